"""Errors speak the user's units (issue 11, item 23): driver values in degrees for angles
and metres for slides, in every message that names a pose, the singular-pose one included.
Before, "cannot be closed at A = 3.14159" followed a scene written in degrees, and a
SweepError read "stopped at O6 = 167.122 deg ... at O6 = 2.91684"."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from pinmech import LoopClosureError, LoopSolver, Mechanism, Scene, SingularPoseError, SweepError
from pinmech.cli import main
from pinmech.io.sweep import Sweep
from tests._mechanisms import four_bar_urdf, write

#: A number followed by neither a unit nor more digits: a value in bare radians.
_BARE = re.compile(r"(?:O2|O4|A|slide) = (-?[0-9.]+(?:e[-+]?\d+)?)(?! ?(?:deg|m\b|[0-9.]))")


def _no_bare_values(message: str) -> None:
    assert not _BARE.findall(message), message


@pytest.fixture
def rocking_four_bar(tmp_path):
    """Non-Grashof (a = 0.08, b = 0.05, c = 0.06, d = 0.10): the crank rocks within about +-81 deg."""
    return Mechanism.from_urdf(write(tmp_path, "fb.urdf", four_bar_urdf(0.08, 0.05, 0.06, 0.10)))


def test_a_loop_that_cannot_close_names_the_angle_in_degrees(rocking_four_bar):
    with pytest.raises(LoopClosureError, match=r"cannot be closed at O2 = 180 deg") as info:
        LoopSolver(rocking_four_bar, ["O2"]).solve([math.pi])
    _no_bare_values(str(info.value))


def test_a_singular_pose_names_the_driver(rocking_four_bar):
    """The crank exactly at its limit angle, from a guess on the assembly: the message
    names the driver's value (in degrees), the condition number and the limit."""
    a, b, c, d = 0.08, 0.05, 0.06, 0.10
    limit = math.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d))
    solver = LoopSolver(rocking_four_bar, ["O2"], max_condition=10.0)
    guess = rocking_four_bar.neutral()
    rocking_four_bar.set_coordinate(guess, "A", -1.0)
    rocking_four_bar.set_coordinate(guess, "O4", 2.0)
    with pytest.raises(SingularPoseError) as info:
        solver.solve([limit - 1e-3], guess=guess)
    assert f"O2 = {math.degrees(limit - 1e-3):.10g} deg" in str(info.value)
    _no_bare_values(str(info.value))


def test_a_sweep_that_stops_names_its_pose_in_degrees_twice(rocking_four_bar, tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{rocking_four_bar.source}"\n[drivers.O2]\nangle = "0 deg"\nspeed = "1 rad/s"\n'
                     '[guess]\nA = "110 deg"\nO4 = "129 deg"\n', encoding="utf-8")
    sweep = Sweep.from_scene(Scene.load(scene))
    with pytest.raises(SweepError) as info:
        list(sweep.poses(np.radians(np.arange(0.0, 120.0, 10.0)), start="warm"))
    message = str(info.value)
    assert re.search(r"stopped at O2 = 80 deg: .* at O2 = 80 deg", message), message  # past the limit, 74.5 deg
    _no_bare_values(message)


def test_the_command_line_speaks_degrees(rocking_four_bar, tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{rocking_four_bar.source}"\n[drivers.O2]\nangle = "180 deg"\nspeed = "1 rad/s"\n',
                     encoding="utf-8")
    assert main(["solve", str(scene)]) == 6
    err = capsys.readouterr().err
    assert "O2 = 180 deg" in err and err.count("\n") == 1
    _no_bare_values(err)


def test_a_slide_driver_is_named_in_metres(tmp_path, models_dir):
    mech = Mechanism.from_urdf(models_dir / "slider_crank.urdf")
    with pytest.raises(LoopClosureError, match=r"cannot be closed at slide = 0\.5 m") as info:
        LoopSolver(mech, ["slide"]).solve([0.5])
    _no_bare_values(str(info.value))
