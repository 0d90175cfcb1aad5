"""Scene points given by coordinates on a link: `[points.Q] link = "coupler", at = [x, y, z]`.

The bundled four-bar's URDF hangs its point P at (60, 30, 0) mm on the coupler, so a scene
point Q written with the same coordinates must move exactly as P (same frame arithmetic
in Pinocchio, so equal to rounding: atol 1e-15 m, 1e-13 m/s, 1e-12 m/s^2).
"""

from __future__ import annotations

import numpy as np
import pytest

from pinmech import Scene, analyse
from pinmech.cli import main
from pinmech.exceptions import FrameNotFound, SceneError, UnitError
from tests.tolerance import rounding


def _scene(tmp_path, scenes_dir, points: str):
    text = (scenes_dir / "four_bar.toml").read_text().replace('urdf = "../four_bar.urdf"',
                                                             f'urdf = "{scenes_dir.parent / "four_bar.urdf"}"')
    text = text.replace('points = ["A_pin", "B_pin", "P"]', 'points = ["P", "Q"]')
    path = tmp_path / "s.toml"
    path.write_text(text + "\n" + points)
    return path


def test_point_by_coordinates_moves_as_the_urdf_point(tmp_path, scenes_dir):
    path = _scene(tmp_path, scenes_dir, '[points.Q]\nlink = "coupler"\nat = ["60 mm", "30 mm", "0 mm"]\n')
    motion = analyse(Scene.load(path)).motion
    P, Q = motion.points["P"], motion.points["Q"]
    np.testing.assert_allclose(Q.position, P.position, atol=rounding(0.2))
    np.testing.assert_allclose(Q.velocity, P.velocity, atol=rounding(np.abs(P.velocity).max()))
    np.testing.assert_allclose(Q.acceleration, P.acceleration, atol=rounding(np.abs(P.acceleration).max()))
    assert Q.link == "coupler"


def test_point_on_a_drawn_linkage(tmp_path, scenes_dir):
    """On a drawn linkage the link frame sits on its parent joint, x along its first bar."""
    text = (scenes_dir / "four_bar_drawn.toml").read_text().replace(
        'linkage = "../linkages/four_bar.toml"', f'linkage = "{scenes_dir.parent / "linkages" / "four_bar.toml"}"')
    path = tmp_path / "d.toml"
    path.write_text(text.replace('points = ["P"]', 'points = ["Q", "P"]')
                    + '\n[points.Q]\nlink = "coupler"\nat = ["120 mm", "0 mm", "0 mm"]\n')
    analysis = analyse(Scene.load(path))
    # Q is B, the far end of the coupler: |Q - O4| is the rocker's 80 mm at every pose
    O4 = np.array([0.1, 0.0, 0.0])
    assert np.linalg.norm(analysis.motion.points["Q"].position - O4) == pytest.approx(0.08, abs=rounding(0.2))


@pytest.mark.parametrize("points, error, words", [
    ('[points.Q]\nlink = "coupler"\nat = ["60", "30 mm", "0 mm"]\n', UnitError, ["points.Q.at", "no unit"]),
    ('[points.Q]\nlink = "couplr"\nat = ["60 mm", "30 mm", "0 mm"]\n', FrameNotFound, ["couplr", "coupler"]),
    ('[points.Q]\nlink = "coupler"\nat = ["60 mm", "30 mm"]\n', SceneError, ["points.Q", "three"]),
    ('[points.P]\nlink = "coupler"\nat = ["60 mm", "30 mm", "0 mm"]\n', SceneError, ["points.P", "already"]),
])
def test_bad_points_are_one_line(tmp_path, scenes_dir, capsys, points, error, words):
    path = _scene(tmp_path, scenes_dir, points)
    with pytest.raises(error) as err:
        analyse(Scene.load(path))
    for word in words:
        assert word in str(err.value)
    assert main(["solve", str(path)]) == error.exit_code
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
