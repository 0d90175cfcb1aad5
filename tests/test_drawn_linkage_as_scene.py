"""A drawn linkage passed where a scene is expected is solved at its drawn pose: its ground
pins drive it (as many as its mobility), each at its drawn value and at a unit rate, every
pin reported, and the scene it stands for printed so the user can copy it.

The bundled four-bar (models/linkages/four_bar.toml: O2 (0, 0), O4 (100, 0), crank 40 mm
drawn along x, coupler 120, rocker 80 mm, B left of A -> O4) is checked against the
two-circle construction of B and Norton's velocity closed form (Design of Machinery,
eq. 6.18): omega4 = omega2 a sin(theta2 - theta3) / (c sin(theta4 - theta3)).
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from pinmech import Scene, analyse
from pinmech.cli import main
from tests.conftest import MODELS

FOUR_BAR = MODELS / "linkages" / "four_bar.toml"
#: Newton closes the drawn pose to 1e-13 of the loop's size (~0.3 m); the closed form's
#: rounding is a few eps x 0.1 m: 1e-12 m and 1e-11 rad/s (rates: condition ~10) cover both.
POSITION_TOL, RATE_TOL = 1e-12, 1e-11


def _four_bar_B() -> np.ndarray:
    A, O4 = np.array([0.04, 0.0]), np.array([0.1, 0.0])
    d = O4 - A
    L = float(np.hypot(*d))
    a = (0.12**2 - 0.08**2 + L**2) / (2 * L)
    u = d / L
    return A + a * u + math.sqrt(0.12**2 - a * a) * np.array([-u[1], u[0]])


def test_the_drawn_four_bar_is_solved_at_its_drawn_pose_with_a_unit_crank_rate():
    result = analyse(Scene.load(FOUR_BAR))
    B = _four_bar_B()
    assert np.max(np.abs(np.asarray(result.motion.points["B"].position[:2]) - B)) <= POSITION_TOL
    theta2, theta3, theta4 = 0.0, math.atan2(B[1], B[0] - 0.04), math.atan2(B[1], B[0] - 0.1)
    omega4 = 1.0 * 0.04 * math.sin(theta2 - theta3) / (0.08 * math.sin(theta4 - theta3))
    assert result.motion.links["rocker"].angular_velocity[2] == pytest.approx(omega4, abs=RATE_TOL)
    assert set(result.motion.points) == {"O2", "O4", "A", "B", "P"}  # every pin reported


def test_the_scene_it_stands_for_is_printed_and_reads_back_to_the_same_pose(tmp_path):
    implied = Scene.load(FOUR_BAR)
    text = implied.implied
    assert tomllib.loads(text)["drivers"] == {"O2": {"angle": "0 deg", "speed": "1 rad/s"}}
    written = tmp_path / "four_bar_scene.toml"
    written.write_text(text.replace('"four_bar.toml"', f'"{FOUR_BAR.as_posix()}"'))
    a, b = analyse(implied), analyse(Scene.load(written))
    assert np.array_equal(a.solution.q, b.solution.q)


@pytest.mark.parametrize("argv", [
    ["solve"], ["sweep", "--steps", "5", "--csv", "{tmp}/s.csv"], ["report", "-o", "{tmp}/r.html"],
    ["polygon", "-o", "{tmp}/p.svg"], ["snapshot", "-o", "{tmp}/s.html"]])
def test_every_scene_command_takes_a_drawn_linkage(tmp_path, capsys, argv):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    code = main([argv[0], str(FOUR_BAR), *argv[1:]])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "is a drawn linkage, not a scene" in err and 'angle = "0 deg"' in err


def test_forces_on_a_drawn_linkage_name_the_missing_masses_not_unknown_keys(capsys):
    code = main(["forces", str(FOUR_BAR)])
    err = capsys.readouterr().err
    assert code == 3 and "unknown key" not in err and "mass" in err


@pytest.mark.parametrize("name", sorted(p.name for p in (MODELS / "linkages").glob("*.toml")))
def test_every_bundled_linkage_solves_at_its_drawn_pose(name):
    result = analyse(Scene.load(MODELS / "linkages" / name))
    assert result.solution.is_closed()
    assert len(result.drivers.names) == result.mechanism.mobility
