"""The "Given" of the report page, against the problem statements the bundled scenes come
from: the R-RTR of Problem Chapter I.9 (AB = 100 mm, AC = 50 mm, CD = 150 mm, the crank at
30 deg turning at 50 rpm clockwise), the four-bar's URDF lengths (Norton's crank-rocker:
ground 100, crank 40, coupler 120, rocker 80 mm; P at (60, 30) mm on the coupler) and the
slider-crank with masses (gravity 9.81 m/s^2 down, a 200 N gas force on the piston).
Numbers are printed to 6 significant digits, so an exact length prints exactly.
"""

from __future__ import annotations

import math

import pytest

from pinmech import Scene, analyse
from pinmech.io.report_given import given
from tests.conftest import SCENES


def _given(name: str, *overrides: str) -> dict[str, str]:
    return {h: "\n".join(lines) for h, lines in given(analyse(Scene.load(SCENES / f"{name}.toml", list(overrides))))}


def test_the_r_rtr_as_problem_chapter_i9_states_it():
    g = _given("r_rtr")
    for length in ("AC = 50 mm", "AB = 100 mm", "CD = 150 mm"):
        assert length in g["Dimensions"]
    assert "angle 30 deg" in g["Driver"] and "(-50 rpm)" in g["Driver"]
    assert f"speed {-50 * math.pi / 30:.6g} rad/s" in g["Driver"]
    assert "clockwise seen from (0, 0, 1)" in g["Driver"] and "counter-clockwise" not in g["Driver"]
    assert g["Gravity and loads"].startswith("none: a kinematic analysis")
    assert "planar" in g["Mechanism"] and "3 moving links" in g["Mechanism"]


@pytest.mark.parametrize(("speed", "sense"), [("120 rpm", "counter-clockwise"), ("-30 rpm", "clockwise")])
def test_the_four_bar_dimensions_and_the_drivers_sense(speed, sense):
    """P at (60, 30) mm: AP = hypot(60, 30), BP = hypot(60, 30) mm (B at 120 mm on the x axis)."""
    g = _given("four_bar", f'drivers.O2.speed="{speed}"')
    hyp = f"{math.hypot(60, 30):.6g} mm"
    for length in ("O2O4 = 100 mm", "O2A = 40 mm", "AB = 120 mm", f"AP = {hyp}", f"BP = {hyp}", "O4B = 80 mm"):
        assert length in g["Dimensions"]
    assert g["Driver"].split("rpm)")[1].startswith(f", {sense} seen from")


def test_gravity_and_loads_of_the_slider_crank_with_masses():
    g = _given("slider_crank_dynamic")
    assert "gravity 9.81 m/s² along (0, -1, 0)" in g["Gravity and loads"]
    assert "load gas at B_pin: force (-200, 0, 0) N" in g["Gravity and loads"]
    assert "masses and inertias from the model" in g["Assumptions"]
    assert "(3000 rpm)" in g["Driver"]
