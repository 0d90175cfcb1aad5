"""Scene files: values as written, overrides from the command line, and clear errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pinmech import FrameNotFound, ModelError, Scene, SceneError, UnitError, analyse
from pinmech.io.scene_model import load_mechanism, scene_drivers
from tests.tolerance import REGULAR, closure, rounding


def _scene(tmp_path, body: str, name: str = "s.toml"):
    path = tmp_path / name
    path.write_text(body, encoding="utf-8")
    return path


def test_r_rtr_scene_drivers_in_si(r_rtr_scene):
    scene = Scene.load(r_rtr_scene)
    drivers = scene_drivers(scene, load_mechanism(scene))
    assert drivers.names == ("A",)
    np.testing.assert_allclose([drivers.q[0], drivers.v[0], drivers.a[0]], [math.pi / 6, -50 * math.pi / 30, 0.0])


def test_override_changes_the_crank_angle_without_editing_the_file(r_rtr_scene):
    scene = Scene.load(r_rtr_scene, ['drivers.A.angle="90 deg"'])
    analysis = analyse(scene)
    np.testing.assert_allclose(analysis.motion.points["B"].position, [0.0, 0.1, 0.0], atol=rounding(0.1))


def test_the_branch_is_chosen_by_the_guess(r_rtr_scene):
    """The other assembly branch puts D on the far side of C (link 3 turned by 180 deg)."""
    main = analyse(Scene.load(r_rtr_scene))
    other = analyse(Scene.load(r_rtr_scene, ['guess.B="200 deg"', 'guess.B_slider="60 mm"']))
    phi3 = main.motion.links["link3"].angle
    assert other.motion.links["link3"].angle == pytest.approx(phi3 - math.pi, abs=closure(np.pi, REGULAR))


@pytest.mark.parametrize(
    "body, error, message",
    [
        ('urdf = "../r_rtr.urdf"\n[drivers.A]\nangle = "30"\n', UnitError, r"drivers\.A\.angle: '30' has no unit"),
        ('urdf = "../r_rtr.urdf"\n[drivers.A]\nangle = "30 deg"\nspeed = "5 m/s"\n', UnitError, "no angle unit"),
        ('urdf = "../r_rtr.urdf"\n[drivers.crank]\nangle = "30 deg"\n', FrameNotFound, r"unknown joint \(in \[drivers\]\) 'crank'"),
        ('urdf = "../r_rtr.urdf"\n[drivers.A]\nspeed = "1 rpm"\n', SceneError, "missing its angle"),
        ('urdf = "../r_rtr.urdf"\n[drivers.A]\nangle = "1 deg"\nturbo = 1\n', SceneError, "unknown key"),
        ('urdf = "../r_rtr.urdf"\ncolour = "red"\n', SceneError, r"unknown key\(s\) colour"),
        ('[drivers.A]\nangle = "1 deg"\n', SceneError, "give exactly one of urdf"),
        ('urdf = "../r_rtr.urdf"\n[drivers.A\n', SceneError, "malformed TOML"),
        ('urdf = "../missing.urdf"\n[drivers.A]\nangle = "1 deg"\n', ModelError, "is not a file"),
        ('urdf = "../r_rtr.urdf"\n[solver]\ntol = -1\n', SceneError, "positive number"),
    ],
)
def test_bad_scenes_name_the_file_and_the_key(tmp_path, models_dir, body, error, message):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (tmp_path / "r_rtr.urdf").write_text((models_dir / "r_rtr.urdf").read_text())
    path = _scene(scenes, body)
    with pytest.raises(error, match=message) as info:
        analyse(Scene.load(path))
    assert "s.toml" in str(info.value)


def test_a_malformed_override_is_refused(r_rtr_scene):
    with pytest.raises(SceneError, match="is not KEY=VALUE"):
        Scene.load(r_rtr_scene, ["drivers.A.angle"])
