"""A parallelogram four-bar (two equal pairs: ground d = coupler b, crank a = rocker c)
swept through its change points keeps the branch it was drawn on, checked against the
closed forms of both branches over two full turns (Norton, Design of Machinery, §2.12):
the parallelogram, B = A + O4 (the rocker turns with the crank, at its angle), and the
antiparallelogram, B the other meeting point of the circles (A, b) and (O4, c): the
parallelogram's B reflected in the line A O4."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import pinmech
from pinmech.cli import main

D, A = 100.0, 40.0  # mm: ground = coupler, crank = rocker
DRAWN = 270.0  # deg: the crank drawn straight down, away from both change points (0 and 180 deg)

#: The rocker's angle from the closed pose: closure to 1e-13 of the loop's size times the
#: condition number, up to about 1e3 at the poses nearest a change point (half a degree of
#: crank away) — 1e-10 rad is a margin of 1e3 over that product.
ANGLE_TOL = 1e-10


def rocker_angles(theta: float) -> dict[str, float]:
    """The rocker's angle O4 -> B [rad] on each branch at crank angle theta [rad]."""
    a_pin = np.array([A * math.cos(theta), A * math.sin(theta)])
    o4 = np.array([D, 0.0])
    parallel = a_pin + o4  # O2 A = O4 B
    u = (o4 - a_pin) / np.linalg.norm(o4 - a_pin)
    v = parallel - a_pin
    crossed = a_pin + 2.0 * np.dot(v, u) * u - v  # reflected in the line A O4
    return {branch: math.atan2(b[1], b[0] - D) for branch, b in
            (("parallelogram", parallel), ("antiparallelogram", crossed))}


def scene_files(tmp_path, branch: str):
    """The four-bar drawn at DRAWN on `branch` (B on the right of A -> O4: the parallelogram,
    here), and a scene driving O2."""
    side = "right" if branch == "parallelogram" else "left"
    (tmp_path / "fb.toml").write_text(f"""title = "parallelogram four-bar"
ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["{D} mm", "0 mm"]
A = {{ from = "O2", length = "{A} mm", angle = "{DRAWN} deg" }}
B = {{ from = ["A", "O4"], lengths = ["{D} mm", "{A} mm"], side = "{side}" }}
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
""")
    scene = tmp_path / "scene.toml"
    scene.write_text(f'title = "fb"\nlinkage = "fb.toml"\n[drivers.O2]\nangle = "{DRAWN} deg"\nspeed = "60 rpm"\n')
    return scene


def off_branch(branch: str, theta: float, rocker: float) -> float:
    """How far the rocker is from its drawn branch's closed form [rad]."""
    return abs(math.remainder(rocker - rocker_angles(theta)[branch], 2 * math.pi))


def test_the_two_branches_differ_away_from_the_change_points():
    """The closed forms tell the branches apart (else the tests below check nothing): at
    90 deg the rockers are 2 atan(...) apart, far more than ANGLE_TOL."""
    angles = rocker_angles(math.pi / 2)
    assert abs(math.remainder(angles["parallelogram"] - angles["antiparallelogram"], 2 * math.pi)) > 1.0


@pytest.mark.parametrize("branch", ["antiparallelogram", "parallelogram"])
@pytest.mark.parametrize("first, steps", [(270.0, 361), (270.0, 100), (90.5, 361), (-45.25, 37)],
                         ids=["on the grid", "100 steps", "off the grid", "37 steps off the grid"])
@pytest.mark.parametrize("sense", [1, -1], ids=["forwards", "backwards"])
@pytest.mark.parametrize("options", [{"skip_failures": True}, {"past_change_points": True}],
                         ids=["skip failures", "past change points"])
def test_a_sweep_through_change_points_keeps_its_drawn_branch(tmp_path, branch, first, steps, sense, options):
    """Two full turns of the crank pass four change points (theta = 0 and 180 deg, all pins
    in line). Every pose solved is on the branch drawn, to the closed form (it went on as
    the parallelogram past 180 deg, the rocker's rate jumping from -(d - a)/(d + a) to 1);
    a pose exactly on a change point is a failed row, and each change point passed is
    noted."""
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scene_files(tmp_path, branch)))
    values = np.radians(np.linspace(first, first + sense * 720.0, steps))
    solved, passed = 0, 0
    for pose in sweep.poses(values, **options):
        passed += "passed a change point" in pose.note
        if pose.motion is None:
            assert math.remainder(math.degrees(pose.value), 180.0) == pytest.approx(0.0, abs=1e-9)
            continue
        solved += 1
        rocker = pose.motion.links["rocker"].angle
        assert off_branch(branch, pose.value, rocker) <= ANGLE_TOL, (math.degrees(pose.value), branch)
    assert solved >= steps - 5
    assert passed == 4


def test_pinmech_sweep_of_the_antiparallelogram_names_no_change_of_branch(tmp_path, capsys):
    """`pinmech sweep` of the antiparallelogram over two turns, failing poses skipped: the
    JSON lines' rocker angles are the antiparallelogram's; the notes say where each change
    point was passed and that the branch kept is the antiparallelogram; the sweep ends
    back where it began."""
    scene = scene_files(tmp_path, "antiparallelogram")
    lines = tmp_path / "s.jsonl"
    assert main(["sweep", str(scene), "--from", "270 deg", "--to", "990 deg", "--steps", "361", "--skip-failures",
                 "--csv", str(tmp_path / "s.csv"), "--json", str(lines)]) == 0
    err = capsys.readouterr().err
    for row in map(json.loads, lines.read_text().splitlines()):
        if row["pose"] == "solved":
            assert off_branch("antiparallelogram", row["O2"], row["links"]["rocker"]["angle"]) <= ANGLE_TOL
    for where in (360, 540, 720, 900):
        assert f"passed a change point near O2 = {where} deg" in err
    assert "now on its parallelogram branch" not in err
    assert err.count("after the change point: on its antiparallelogram branch") == 4
    assert "back where it began" in err


def scrr_scene(tmp_path):
    """Barker III-2 SCRR: ground 100, crank 40, coupler 120, rocker 60 mm (s + l = 160 =
    p + q): a change point at theta = 0, where |O4 A| = d - a = 60 = b - c puts B, O4 and A
    in line. Drawn at 90 deg."""
    (tmp_path / "scrr.toml").write_text("""title = "SCRR four-bar"
ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["100 mm", "0 mm"]
A = { from = "O2", length = "40 mm", angle = "90 deg" }
B = { from = ["A", "O4"], lengths = ["120 mm", "60 mm"], side = "left" }
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
""")
    scene = tmp_path / "scrr_scene.toml"
    scene.write_text('title = "scrr"\nlinkage = "scrr.toml"\n[drivers.O2]\nangle = "90 deg"\nspeed = "60 rpm"\n')
    return scene


ENDS = [(0.0, 360.0), (360.0, 0.0), (90.0, 360.0), (-90.0, 0.0), (0.0, -360.0), (360.0, 720.0)]


@pytest.mark.parametrize("first, last", ENDS, ids=[f"{a:g} to {b:g}" for a, b in ENDS])
@pytest.mark.parametrize("steps", [361, 37])
def test_a_change_point_at_a_sweeps_first_or_last_pose_is_a_row_not_a_failure(tmp_path, capsys, first, last, steps):
    """The SCRR's change point at theta = 0 (mod 360) as the first or the last pose of a
    sweep, either way round: `pinmech sweep` writes it as a failed row saying so and exits
    0 (it stopped there with exit 7, or 10); every other pose is solved."""
    lines = tmp_path / "s.jsonl"
    assert main(["sweep", str(scrr_scene(tmp_path)), "--from", f"{first} deg", "--to", f"{last} deg", "--steps",
                 str(steps), "--csv", str(tmp_path / "s.csv"), "--json", str(lines)]) == 0
    err = capsys.readouterr().err
    rows = [json.loads(line) for line in lines.read_text().splitlines()]
    assert len(rows) == steps
    on_change_point = [i for i, value in enumerate((first, last)) if math.remainder(value, 360.0) == 0.0]
    failed = [row["index"] for row in rows if row["pose"] != "solved"]
    assert failed == [(0, steps - 1)[i] for i in on_change_point]
    for which in ("first", "last"):
        assert (f"the sweep's {which} pose is a change point" in err) == ((0 if which == "first" else 1) in on_change_point)


@pytest.mark.parametrize("last", [360.0, -360.0])
def test_a_change_point_a_turn_on_is_named_at_its_angle_not_rounding(tmp_path, capsys, last):
    """The SCRR's change point a turn (or two) from 0, the sweep's last pose: the failed
    row's error names O2 = 0 deg (its position a turn on), as the driver read back from its
    cos and sin, not "-1.4e-14 deg" (the noise of that reading)."""
    lines = tmp_path / "s.jsonl"
    assert main(["sweep", str(scrr_scene(tmp_path)), "--from", "90 deg", "--to", f"{last} deg", "--steps", "37",
                 "--csv", str(tmp_path / "s.csv"), "--json", str(lines)]) == 0
    capsys.readouterr()
    (row,) = [json.loads(x) for x in lines.read_text().splitlines() if '"solved"' not in x]
    assert "singular at O2 = 0 deg (" in row["error"] and "e-1" not in row["error"].split("(")[0], row["error"]


@pytest.mark.parametrize("last", [450.5, -269.5], ids=["forwards", "backwards"])
@pytest.mark.parametrize("steps", [361, 100, 37])
def test_an_scrr_swept_off_the_grid_passes_its_change_point_either_way(tmp_path, capsys, last, steps):
    """From 90.5 deg a turn either way: no pose on the change point; every pose solved, the
    change point passed named once (it failed one way round)."""
    assert main(["sweep", str(scrr_scene(tmp_path)), "--from", "90.5 deg", "--to", f"{last} deg", "--steps",
                 str(steps), "--csv", str(tmp_path / "s.csv")]) == 0
    assert capsys.readouterr().err.count("passed a change point near O2 = ") == 1


@pytest.mark.parametrize("branch", ["antiparallelogram", "parallelogram"])
@pytest.mark.parametrize("first, last", [(0.0, 720.0), (720.0, 0.0), (180.0, 540.0), (90.5, 540.0)],
                         ids=["0 to 720", "720 to 0", "180 to 540", "90.5 to 540"])
def test_a_parallelogram_swept_between_change_points_names_its_branch_at_both_ends(tmp_path, capsys, branch,
                                                                                    first, last):
    """Two turns between change points: the end poses on them are rows, the branch named
    there (the one drawn), every pose solved on it to the closed form."""
    lines = tmp_path / "s.jsonl"
    assert main(["sweep", str(scene_files(tmp_path, branch)), "--from", f"{first} deg", "--to", f"{last} deg",
                 "--steps", "361", "--csv", str(tmp_path / "s.csv"), "--json", str(lines)]) == 0
    err = capsys.readouterr().err
    for row in map(json.loads, lines.read_text().splitlines()):
        if row["pose"] == "solved":
            assert off_branch(branch, row["O2"], row["links"]["rocker"]["angle"]) <= ANGLE_TOL
    assert f"ends on its change point, arriving on its {branch} branch" in err
    other = "parallelogram" if branch == "antiparallelogram" else "antiparallelogram"
    assert f"on its {other} branch" not in err.replace(f"on its {branch} branch", "")
