"""The coupler's centrodes on the paths figure (`pinmech sweep --paths --centrodes`). The
coupler's instant centre relative to the ground is where the crank line O2-A meets the
rocker line O4-B (Kennedy's theorem, Norton sec. 6.4): the fixed centrode is that point at
every pose, computed here from the four-bar's closed form alone; the moving centrode, drawn
on the coupler at the scene's pose, touches the fixed one there (rolling contact)."""

from __future__ import annotations

import math

import closed_form as cf
import numpy as np
import pytest

from pinmech.cli import main
from tests.conftest import MODELS

pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')

O2, O4 = np.zeros(2), np.array([0.10, 0.0])  # models/linkages/four_bar.toml [m]


def _meet(p, d, q, e):
    """The point where the lines p + s d and q + t e meet."""
    s, _ = np.linalg.solve(np.column_stack([d, -e]), q - p)
    return p + s * d


def _scene(tmp_path, angle="30 deg"):
    path = tmp_path / "scene.toml"
    path.write_text(f'linkage = "{MODELS / "linkages" / "four_bar.toml"}"\n[drivers.O2]\nangle = "{angle}"\n'
                    'speed = "1 rad/s"\n[report]\npoints = ["P"]\n')
    return path


def test_the_fixed_centrode_of_the_coupler_is_where_the_crank_and_rocker_lines_meet(tmp_path, figures):
    assert main(["sweep", str(_scene(tmp_path)), "--steps", "13", "--from", "30 deg", "--to", "390 deg",
                 "--paths", str(tmp_path / "p.png"), "--centrodes", "coupler"]) == 0
    ax = figures[-1].axes[0]
    (fixed,) = [line for line in ax.get_lines() if line.get_gid() == "fixed centrode"]
    scale = 1e-3 if "mm" in ax.get_xlabel() else 1.0
    u, v = (np.asarray(c) * scale for c in fixed.get_data())
    (x0, x1), (y0, y1) = (np.asarray(lim) * scale for lim in (ax.get_xlim(), ax.get_ylim()))
    drawn = 0
    for k, theta in enumerate(np.radians(np.linspace(30.0, 390.0, 13))):
        ref = cf.four_bar(theta, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
        want = _meet(O2, ref.A[:2] - O2, O4, ref.B[:2] - O4)
        if np.isnan(u[k]):  # left out: beyond the figure's window (the centre runs off to infinity)
            assert not (x0 <= want[0] <= x1 and y0 <= want[1] <= y1), (k, want)
            continue
        # the centre moves as 1/sin of the lines' angle: 1e-9 m of a 0.1 m linkage at these poses
        np.testing.assert_allclose([u[k], v[k]], want, atol=1e-9)
        drawn += 1
    assert drawn >= 8


def test_the_moving_centrode_touches_the_fixed_one_at_the_scenes_pose(tmp_path, figures):
    assert main(["sweep", str(_scene(tmp_path, "210 deg")), "--steps", "13", "--from", "0 deg", "--to", "360 deg",
                 "--paths", str(tmp_path / "p.png"), "--centrodes", "coupler"]) == 0
    ax = figures[-1].axes[0]
    (fixed,) = [line for line in ax.get_lines() if line.get_gid() == "fixed centrode"]
    (moving,) = [line for line in ax.get_lines() if line.get_gid() == "moving centrode"]
    k = 7  # the pose at 210 deg, the scene's (its centre lies within the figure's window)
    np.testing.assert_allclose(np.asarray(moving.get_data())[:, k], np.asarray(fixed.get_data())[:, k], atol=1e-9)
    ref = cf.four_bar(math.radians(210.0), 1.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
    scale = 1e-3 if "mm" in ax.get_xlabel() else 1.0
    want = _meet(O2, ref.A[:2] - O2, O4, ref.B[:2] - O4)
    np.testing.assert_allclose(np.asarray(moving.get_data())[:, k] * scale, want, atol=1e-9)


def test_centrodes_of_the_ground_or_of_an_unknown_link_are_refused(tmp_path, capsys):
    scene = str(_scene(tmp_path))
    assert main(["sweep", scene, "--steps", "5", "--paths", str(tmp_path / "p.png"), "--centrodes", "ground"]) == 14
    assert "the ground has no centrode" in capsys.readouterr().err
    assert main(["sweep", scene, "--steps", "5", "--paths", str(tmp_path / "p.png"), "--centrodes", "nope"]) == 4
    assert main(["sweep", scene, "--steps", "5", "--centrodes", "coupler"]) == 2  # no figure to draw them on
