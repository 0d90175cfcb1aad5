"""Angles pinmech writes and reads back: one convention.

A scene's driver angle names the crank's physical angle from world x, so a linkage drawn
with its crank at -179.9 deg is the same pose as a scene asking 180.1 deg (or 540.1 deg):
the drawn pose is taken on the scene's turn, never reached by a whole turn of motion (a
rocker cannot make that turn: it would stop at a fold). Checked for the triple rockers
below, whose crank rocks through 180 deg (O4 to the right) or through 0 deg (O4 to the
left), near the wrap of every convention (+-180, 0/360), against the closed form of the
drawn pose (B where the coupler's and the rocker's circles meet, left of A -> O4).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pinmech import Scene, analyse
from pinmech.io.sweep import Sweep

CRANK, COUPLER, ROCKER, GROUND = 0.040, 0.035, 0.050, 0.030  # a triple rocker: 40 + 50 > 35 + 30
#: The closed pose of the engine against the closed form: Newton's closure tolerance
#: (1e-13 of the loop's size, ~0.1 m) leaves ~1e-14 m; the circle intersection's rounding
#: is eps x size / sin(angle of the circles), ~1e-16 / 0.3. 1e-12 m covers both by 100.
POSE_TOL = 1e-12


def _B(O4x: float, theta: float) -> np.ndarray:
    """B of the drawn four-bar at crank angle theta [rad]: the coupler's circle about A and
    the rocker's about O4 meet left of A -> O4 (the textbook two-circle construction)."""
    A = CRANK * np.array([math.cos(theta), math.sin(theta)])
    O4 = np.array([O4x, 0.0])
    d = O4 - A
    L = float(np.hypot(*d))
    a = (COUPLER**2 - ROCKER**2 + L**2) / (2 * L)
    h = math.sqrt(COUPLER**2 - a**2)
    u = d / L
    return A + a * u + h * np.array([-u[1], u[0]])


def _linkage(tmp_path, O4x: float, drawn_deg: float) -> str:
    t = math.radians(drawn_deg)
    A = (CRANK * math.cos(t) * 1e3, CRANK * math.sin(t) * 1e3)
    (tmp_path / "rocker.toml").write_text(f"""title = "a triple rocker"
ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["{O4x * 1e3!r} mm", "0 mm"]
A = ["{A[0]!r} mm", "{A[1]!r} mm"]
B = {{ from = ["A", "O4"], lengths = ["{COUPLER * 1e3!r} mm", "{ROCKER * 1e3!r} mm"], side = "left" }}
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
""")
    return "rocker.toml"


# (O4's x, the crank's drawn angle [deg]): rocking through 180 deg, then through 0 deg.
DRAWN = [(GROUND, -179.9), (GROUND, 179.9), (GROUND, 180.0), (GROUND, -180.0),
         (-GROUND, -0.1), (-GROUND, 0.1), (-GROUND, 359.9), (-GROUND, 0.0)]


@pytest.mark.parametrize(("O4x", "drawn"), DRAWN)
@pytest.mark.parametrize("turns", [-1, 0, 1, 2])
def test_a_scene_at_the_drawn_angle_on_any_turn_solves_the_drawn_pose(tmp_path, O4x, drawn, turns):
    linkage = _linkage(tmp_path, O4x, drawn)
    asked = drawn + 360 * turns
    scene = tmp_path / "scene.toml"
    scene.write_text(f'linkage = "{linkage}"\n[drivers.O2]\nangle = "{asked!r} deg"\n[report]\npoints = ["B"]\n')
    result = analyse(Scene.load(scene))
    B = np.asarray(result.motion.points["B"].position[:2])
    assert np.max(np.abs(B - _B(O4x, math.radians(drawn)))) <= POSE_TOL


@pytest.mark.parametrize(("O4x", "drawn", "start", "stop"), [
    (-GROUND, -10.69, 349.31, 366.43),   # the crank drawn below x, the scene written in 0..360
    (-GROUND, 350.0, -10.0, 15.0),       # the other way round
    (GROUND, -170.0, 190.0, 170.0),      # through 180 deg, turning clockwise
    (GROUND, 175.0, -185.0, -170.0),
])
def test_a_sweep_across_the_wrap_starts_at_the_drawn_pose_and_follows_the_rocker(tmp_path, O4x, drawn, start, stop):
    linkage = _linkage(tmp_path, O4x, drawn)
    scene = tmp_path / "scene.toml"
    scene.write_text(f'linkage = "{linkage}"\n[drivers.O2]\nangle = "{start!r} deg"\n'
                     f'[report]\npoints = ["B"]\n[sweep]\nfrom = "{start!r} deg"\nto = "{stop!r} deg"\nsteps = 11\n')
    sweep = Sweep.from_scene(Scene.load(scene))
    values = np.radians(np.linspace(start, stop, 11))
    for pose in sweep.poses(values):
        B = np.asarray(pose.motion.points["B"].position[:2])
        assert np.max(np.abs(B - _B(O4x, pose.value))) <= POSE_TOL


@pytest.mark.parametrize("drawn", [-179.9, 179.9])
@pytest.mark.parametrize("asked", [-180.1, 179.9, 539.9])
def test_the_built_urdf_reads_the_crank_angle_as_the_linkage_does(tmp_path, drawn, asked):
    """`pinmech build`'s URDF: the ground pin's coordinate is the crank's angle from x, as
    the linkage's, so a scene of either file at one angle is one pose (the rocker's angle
    from x, atan2 of B - O4 in the closed form)."""
    from pinmech.model.linkage_model import build_urdf

    linkage = _linkage(tmp_path, GROUND, drawn)
    build_urdf(tmp_path / linkage, tmp_path / "rocker.urdf")
    B = _B(GROUND, math.radians(asked))
    rocker = math.atan2(B[1], B[0] - GROUND)
    A = CRANK * np.array([math.cos(math.radians(asked)), math.sin(math.radians(asked))])
    bend = math.atan2(B[1] - A[1], B[0] - A[0]) - math.radians(asked)  # pin A: the coupler from the crank
    for line in (f'linkage = "{linkage}"', 'urdf = "rocker.urdf"'):
        scene = tmp_path / "scene.toml"
        scene.write_text(f'{line}\n[drivers.O2]\nangle = "{asked!r} deg"\n'
                         f'[guess]\nO4 = "{math.degrees(rocker)!r} deg"\nA = "{math.degrees(bend)!r} deg"\n')
        found = analyse(Scene.load(scene)).motion.links["rocker"].angle
        assert abs(math.remainder(found - rocker, 2 * math.pi)) <= POSE_TOL / ROCKER


def test_limit_positions_of_a_sweep_past_a_turn_are_printed_as_positions_in_0_to_360(capsys):
    """The bundled crank-rocker (ground 100, crank 40, coupler 120, rocker 80 mm) swept from
    300 to 700 deg: its toggles, where B lies on the crank's line at 160 mm (extended) or
    80 mm behind O2 (folded), by the circle about O4 (80 mm), are at
    atan2(sqrt(160^2 - 146^2), 146) = 24.1468 deg and 180 + atan2(sqrt(80^2 - 50^2), 50)
    = 231.318 deg: printed there (6 figures), not at 384.147 and 591.318 deg, and every
    driver position in the summary is in [0, 360)."""
    import re

    from pinmech.cli import main
    from tests.conftest import MODELS

    main(["sweep", str(MODELS / "scenes" / "four_bar_drawn.toml"), "--from", "300 deg", "--to", "700 deg",
          "--steps", "81", "--json", "/dev/null"])
    err = capsys.readouterr().err
    extended = math.degrees(math.atan2(math.sqrt(160**2 - 146**2), 146))
    folded = 180 + math.degrees(math.atan2(math.sqrt(80**2 - 50**2), 50))
    found = {m[0]: float(m[1]) for m in re.findall(r"rocker extreme \((min|max)\) \S+ deg at O2 = (\S+) deg", err)}
    assert found["min"] == pytest.approx(extended, abs=1e-3)  # 6 significant figures printed
    assert found["max"] == pytest.approx(folded, abs=1e-3)
    positions = [float(x) for x in re.findall(r"O2 = (\S+) deg", err)]
    assert positions and all(0.0 <= x < 360.0 for x in positions)


@pytest.mark.parametrize(("angle", "position"), [
    (-10.69, 349.31), (349.31, 349.31), (370.0, 10.0), (-360.0, 0.0), (-0.0, 0.0), (720.0, 0.0),
    (-180.0, 180.0), (180.0, 180.0), (-1e-300, 0.0), (1e6 + 0.5, 280.5)])
def test_a_position_is_the_angle_less_its_whole_turns_in_0_to_360(angle, position):
    from pinmech.angles import position_text, turn_degrees, turn_radians

    # fmod is exact, so the remainder is the exact float (1e6 + 0.5 - 2777 * 360 = 280.5)
    assert turn_degrees(angle) == position and str(turn_degrees(angle)) != "-0.0"
    assert turn_radians(math.radians(angle)) == pytest.approx(math.radians(position), abs=1e-12)
    assert 0.0 <= turn_radians(math.radians(angle)) < 2 * math.pi
    assert position_text(360.0 - 1e-9) == "0" and position_text(angle) == format(position, ".6g")


@pytest.mark.parametrize("asked", [300.0, -60.0, 660.0, -420.0])
def test_a_rocker_drawn_near_its_fold_reaches_the_scene_angle_the_only_way_it_can(tmp_path, asked):
    """The triple rocker through 180 deg (folds at 18.57 and 341.43 deg: |A O4| = 50 - 35,
    law of cosines) drawn at 25 deg, asked for 300 deg however written: the shorter way round
    (back through 0 deg) meets the fold at 18.57 deg, so it is followed forward 275 deg, the
    only way the crank can turn; B where the closed form puts it at 300 deg."""
    linkage = _linkage(tmp_path, GROUND, 25.0)
    scene = tmp_path / "scene.toml"
    scene.write_text(f'linkage = "{linkage}"\n[drivers.O2]\nangle = "{asked!r} deg"\n[report]\npoints = ["B"]\n')
    B = np.asarray(analyse(Scene.load(scene)).motion.points["B"].position[:2])
    assert np.max(np.abs(B - _B(GROUND, math.radians(300.0)))) <= POSE_TOL
