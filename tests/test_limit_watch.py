"""Limit positions and extremes where a sweep begins, ends or stops: at its first pose,
at a toggle of the driver, at a change point; checked against closed forms derived
from the link lengths (Norton, Design of Machinery, §2.12, §4.10)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pinmech
from pinmech.solve.diagnostics_sweep import design_of
from pinmech.solve.limit_positions import travel

#: Limit positions at a pose of the sweep carry the pose's driver value: exact where the
#: rate's zero is the pose (an inline slider-crank at theta = 0, 180 deg, from sin).
#: Bisected ones are found to 1e-12 rad; 1e-9 rad leaves a margin of 1e3.
DRIVER_TOL = 1e-9
#: Piston places from the closed pose: rounding of the closure (1e-13 of the size).
PLACE_TOL = 1e-12


def slider_crank_files(tmp_path, r: float, l: float, e: float, drawn: float = 0.0):
    """A drawn slider-crank: crank r about O (0, 0) drawn at `drawn` deg, rod l, piston on
    y = e [mm], to the right; a scene driving O."""
    t = math.radians(drawn)
    ax, ay = r * math.cos(t), r * math.sin(t)
    bx = ax + math.sqrt(l * l - (e - ay) ** 2)
    (tmp_path / "sc.toml").write_text(f"""title = "slider-crank"
ground = ["O"]
[joints]
O = ["0 mm", "0 mm"]
A = {{ from = "O", length = "{r} mm", angle = "{drawn} deg" }}
B = ["{bx!r} mm", "{e} mm"]
[links]
crank = ["O", "A"]
rod = ["A", "B"]
piston = ["B"]
[sliders]
slide = {{ block = "piston", on = "ground", at = "B", along = "0 deg" }}
""")
    scene = tmp_path / "sc_scene.toml"
    scene.write_text(f'title = "sc"\nlinkage = "sc.toml"\n[drivers.O]\nangle = "{drawn} deg"\nspeed = "60 rpm"\n')
    return scene


def swept(scene, first_deg: float, last_deg: float, steps: int, **options):
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scene))
    design = design_of(sweep)
    for pose in sweep.poses(np.radians(np.linspace(first_deg, last_deg, steps)), **options):
        design.add(pose)
    return sweep, design


@pytest.mark.parametrize("first", [0.0, 180.0, -180.0], ids=["from TDC", "from BDC", "from BDC backwards"])
def test_inline_slider_crank_swept_from_a_dead_centre_names_both(tmp_path, first):
    """Inline (e = 0): TDC at theta = 0 (crank and rod extended, x = l + r), BDC at 180 deg
    (folded, x = l - r); stroke 2 r; Q = 1. A sweep of one turn that begins on a dead
    centre names it once, with the other, the stroke and Q."""
    r, l = 0.05, 0.15
    scene = slider_crank_files(tmp_path, 50, 150, 0)
    last = first + (360.0 if first >= 0 else -360.0)
    _, design = swept(scene, first, last, 361)
    (found,) = design.limits()
    t = travel(found, 2 * math.pi)
    by_label = {x.label: x for x in t.limits}
    assert set(by_label) == {"max TDC", "min BDC"}, [x.label for x in found]
    np.testing.assert_allclose(math.remainder(by_label["max TDC"].driver, 2 * math.pi), 0.0, atol=DRIVER_TOL)
    np.testing.assert_allclose(abs(math.remainder(by_label["min BDC"].driver, 2 * math.pi)), math.pi, atol=DRIVER_TOL)
    np.testing.assert_allclose([by_label["max TDC"].value, by_label["min BDC"].value], [l + r, l - r],
                               rtol=0, atol=PLACE_TOL)
    np.testing.assert_allclose(t.travel, 2 * r, rtol=0, atol=PLACE_TOL)
    np.testing.assert_allclose(t.ratio, 1.0, rtol=0, atol=1e-9)


def four_bar_files(tmp_path, d, a, b, c, drawn=0.0, side="left"):
    """A drawn four-bar O2 (0, 0), O4 (d, 0), crank a drawn at `drawn` deg, coupler b,
    rocker c [mm], B on `side` of A -> O4; a scene driving O2 from `drawn`."""
    (tmp_path / "fb.toml").write_text(f"""title = "four-bar"
ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["{d} mm", "0 mm"]
A = {{ from = "O2", length = "{a} mm", angle = "{drawn} deg" }}
B = {{ from = ["A", "O4"], lengths = ["{b} mm", "{c} mm"], side = "{side}" }}
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
""")
    scene = tmp_path / "fb_scene.toml"
    scene.write_text(f'title = "fb"\nlinkage = "fb.toml"\n[drivers.O2]\nangle = "{drawn} deg"\nspeed = "60 rpm"\n')
    return scene


def toggle_angle(a, d, reach):
    """The crank angle [deg] where |O4 A| = reach (coupler and rocker in line), by the law
    of cosines in the triangle O2 A O4: reach^2 = a^2 + d^2 - 2 a d cos theta."""
    return math.degrees(math.acos((a * a + d * d - reach * reach) / (2 * a * d)))


#: The fold is located to rounding (Newton on dx/ds = 0 with a dependent joint as the
#: parameter): 1e-9 deg of the driver is a margin of 1e4 over what was measured; the
#: angle there is 0 to rounding of atan2 (1e-12 deg).
FOLD_TOL_DEG = 1e-9


@pytest.mark.parametrize("steps", [13, 37, 361])
@pytest.mark.parametrize("lengths, drawn, reach", [
    ((100, 80, 40, 90), 60, "b + c"),  # Grashof double-rocker (coupler shortest): the crank rocks
    ((100, 45, 50, 55), 0, "b + c"),  # triple rocker: s + l = 145 > p + q = 105
], ids=["double-rocker", "triple rocker"])
def test_least_transmission_angle_is_zero_at_the_toggle_where_the_driver_stops(tmp_path, lengths, drawn, reach,
                                                                              steps):
    """A crank that rocks stops where coupler and rocker fall in line, extended (|O4 A| =
    b + c): the transmission angle ABO is 180 deg there (acute 0) and the pressure angle
    90 deg, whatever the step count (it was the value at the nearest pose: 21.5 deg,
    7.96 or 10.11 deg by steps)."""
    d, a, b, c = lengths
    fold = toggle_angle(a, d, b + c)
    scene = four_bar_files(tmp_path, d, a, b, c, drawn)
    _, design = swept(scene, drawn, drawn + 360, steps, skip_failures=True)
    ((x),) = design.angle_extremes()
    np.testing.assert_allclose([x.high, x.acute_low, x.pressure], [180.0, 0.0, 90.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose([math.degrees(x.high_at), math.degrees(x.pressure_at)], [fold, fold], rtol=0,
                               atol=FOLD_TOL_DEG)
    np.testing.assert_allclose(math.degrees(design.folds()[0]), fold, rtol=0, atol=FOLD_TOL_DEG)


#: Where coupler and output fall in line at a change point the pose itself is singular:
#: bisection on their side of the line stops where trial poses stop closing (condition
#: number 1e10: within ~1e-10 rad of it), so the driver value is good to 1e-9 rad.
CHANGE_TOL = 1e-9


def test_parallelogram_transmission_angle_reaches_0_and_180_at_its_change_points(tmp_path):
    """Parallelogram a = c = 50, b = d = 100 mm: the coupler stays parallel to the ground,
    the rocker to the crank, so the angle ABO is the crank angle theta folded on [0, 180]:
    0 at theta = 0, 180 deg at theta = 180 deg, the change points where all four pins fall in
    line (it was 1 deg at the pose beside the change point, 'located between the poses')."""
    scene = four_bar_files(tmp_path, 100, 50, 100, 50, 270, side="right")
    _, design = swept(scene, 270, 630, 361, skip_failures=True)
    (x,) = design.angle_extremes()
    np.testing.assert_allclose([x.low, x.high, x.pressure], [0.0, 180.0, 90.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose([x.low_at, x.high_at], [2 * math.pi, 3 * math.pi], rtol=0, atol=CHANGE_TOL)
    np.testing.assert_allclose(x.in_line, [2 * math.pi, 3 * math.pi], rtol=0, atol=CHANGE_TOL)
