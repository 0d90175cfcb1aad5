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


def test_summary_json_carries_the_crank_rockers_design_at_full_precision(tmp_path, capsys):
    """The bundled crank-rocker (a 40, b 120, c 80, d 100 mm), one turn: Barker I-2 GCRR
    (s + l = 140 < p + q = 180, the input the shortest); the rocker's extremes where crank
    and coupler are in line, |O2 B| = b + a and b - a, B from the circles (O2, b +- a) and
    (O4, c); Q = alpha / beta of the crank angles between them; mu from the law of cosines
    at theta = 0 and 180 deg (Norton §4.10) — each to 1e-9, from the JSON file."""
    import json

    from pinmech.cli import main

    from .conftest import SCENES

    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    out = tmp_path / "summary.json"
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "37", "--csv", str(tmp_path / "s.csv"),
                 "--summary-json", str(out)]) == 0
    summary = json.loads(out.read_text())
    (loop,) = summary["loops"]
    assert (loop["class"], loop["barker"]) == ("crank-rocker", "I-2 GCRR")
    crank, rocker = [], []
    for reach, flip in ((b + a, 0.0), (b - a, math.pi)):
        x = (reach**2 - c**2 + d**2) / (2 * d)
        B = np.array([x, math.sqrt(reach**2 - x**2)])
        crank.append((math.atan2(B[1], B[0]) + flip) % (2 * math.pi))
        rocker.append(math.atan2(B[1], B[0] - d))
    (output,) = summary["outputs"]
    np.testing.assert_allclose(sorted(x["driver_wrapped"] for x in output["limits"]), sorted(crank), rtol=0, atol=1e-9)
    np.testing.assert_allclose(output["swing"], abs(rocker[1] - rocker[0]), rtol=0, atol=1e-9)
    alpha = (crank[1] - crank[0]) % (2 * math.pi)
    np.testing.assert_allclose(output["time_ratio"], max(alpha, 2 * math.pi - alpha) / min(alpha, 2 * math.pi - alpha),
                               rtol=1e-9)
    (dyad,) = summary["dyads"]
    mu = [math.acos((b * b + c * c - a * a - d * d + 2 * a * d * math.cos(t)) / (2 * b * c)) for t in (0, math.pi)]
    np.testing.assert_allclose([dyad["transmission_angle_least"], dyad["transmission_angle_largest"]], mu,
                               rtol=0, atol=1e-12)  # flat extremes: the value to rounding
    np.testing.assert_allclose(dyad["pressure_angle_largest"], math.pi / 2 - mu[0], rtol=0, atol=1e-12)
    assert "Barker I-2 GCRR (input crank)" in capsys.readouterr().err


def test_json_lines_carry_the_instant_centres(tmp_path):
    """I13 (ground, coupler) of a four-bar is where the lines O2 A and O4 B meet (Kennedy),
    O2, A, B, O4 from the closed form (scripts/closed_form.py) at each pose's crank angle."""
    import json

    from closed_form import four_bar

    from pinmech.cli import main

    from .conftest import SCENES

    lines = tmp_path / "s.jsonl"
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "7", "--json", str(lines)]) == 0
    for row in map(json.loads, lines.read_text().splitlines()):
        fb = four_bar(row["O2"], 1.0, 0.0, 0.04, 0.12, 0.08, 0.10)
        A, B, O4 = np.asarray(fb.A), np.asarray(fb.B), np.array([0.10, 0.0])
        t = np.linalg.solve(np.column_stack([A, -(B - O4)]), O4)  # t A = O4 + s (B - O4)
        centres = {tuple(x["links"]): x for x in row["design"]["instant_centres"]}
        assert len(centres) == 6
        # Kennedy's intersection against the closed form's: rounding over the lines' angle, 1e-9 relative
        np.testing.assert_allclose(centres["ground", "coupler"]["position"][:2], t[0] * A, rtol=1e-9)


def test_a_parallelogram_drawn_crossed_stays_crossed_and_its_branch_watch_sees_no_change(tmp_path):
    """Parallelogram a = c = 50, b = d = 100 mm drawn at 270 deg on its antiparallelogram
    branch (B right of A -> O4), swept a turn, failing poses skipped: every pose solved is
    the antiparallelogram (O2 A != O4 B: the rocker's joint angle not the crank's), so the
    design's branch watch notes no change (it went on as the parallelogram past O2 =
    540 deg; tests/test_change_point_branch.py checks both branches to the closed forms)."""
    scene = four_bar_files(tmp_path, 100, 50, 100, 50, 270, side="left")
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scene))
    design = design_of(sweep)
    solved = 0
    for pose in sweep.poses(np.radians(np.linspace(270, 630, 361)), skip_failures=True):
        design.add(pose)
        if pose.motion is None:
            continue
        joints = pose.motion.joints
        solved += 1
        assert abs(math.remainder(joints["O4"].q - joints["O2"].q, 2 * math.pi)) > 1e-6  # not O2 A = O4 B
    assert solved == 359 and design.branch_notes == []


def test_mechanical_advantage_at_a_dead_centre_is_infinite_not_rounding_noise(tmp_path):
    """Inline slider-crank r 50, l 150 mm: x = r cos theta + sqrt(l^2 - r^2 sin^2 theta), so
    dx/dtheta = -r sin theta (1 + r cos theta / sqrt(l^2 - r^2 sin^2 theta)): zero at theta =
    0 and 180 deg (the advantage infinite: it was 2.4e17 at 180 deg, 1 / rounding), -r at
    90 deg (advantage -1/r = -20 1/m)."""
    r, l = 0.05, 0.15
    scene = slider_crank_files(tmp_path, 50, 150, 0)
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scene))
    design = design_of(sweep)
    found = {}
    for pose in sweep.poses(np.radians([0.0, 90.0, 180.0, 360.0])):
        design.add(pose)
        found[round(math.degrees(pose.value))] = design.evaluate(pose)["advantage"][0]
    assert found[0] == found[180] == found[360] == math.inf
    slope = -r * (1 + 0.0)  # at 90 deg, cos theta = 0
    np.testing.assert_allclose(found[90], 1 / slope, rtol=1e-12)  # rates to rounding x condition (~10)
    assert l > r


@pytest.mark.parametrize("e, label", [(99.0, "crank"), (100.0, "change point"), (101.0, "rocker")])
def test_slider_crank_class_at_the_edge_r_plus_e_equals_l(e, label):
    """r 50, l 150 mm: the rod reaches the slide's line from every crank pin iff r + |e| <= l;
    at r + |e| = l it is normal to the slide at theta = -90 deg, a singular pose the crank
    cannot be driven through: a change point, not a crank (it was called 'crank')."""
    from pinmech.solve.grashof import slider_crank_class

    assert slider_crank_class(0.05, 0.15, e / 1000)[0] == label


def test_a_pose_exactly_on_a_change_point_does_not_stop_the_sweep(tmp_path):
    """The parallelogram a = c = 50, b = d = 100 mm on its parallelogram branch, swept a turn
    from 270 deg in 1 deg steps, has poses exactly on its change points, theta = 360 and
    540 deg (all pins in line: the crossing of the two branches, its rates undefined). They
    are failed rows, named, and the sweep goes on (it stopped there, exit 7); every other
    pose is the parallelogram, O2 A = O4 B: the rocker's joint angle equal to the crank's."""
    scene = four_bar_files(tmp_path, 100, 50, 100, 50, 270, side="right")
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scene))
    poses = list(sweep.poses(np.radians(np.linspace(270, 630, 361)), past_change_points=True))  # as `pinmech sweep`
    failed = [round(math.degrees(p.value)) for p in poses if p.motion is None]
    assert failed == [360, 540]
    assert all("change point" in p.note for p in poses if p.motion is None)
    for p in poses:
        if p.motion is not None:
            gap = math.remainder(p.motion.joints["O4"].q - p.motion.joints["O2"].q, 2 * math.pi)
            assert abs(gap) <= 1e-9, (math.degrees(p.value), gap)  # closure to 1e-13, conditioned ~1e3 near


# Barker's table (Norton table 2-4) read off the lengths (d ground, a input, b coupler, c output):
# Grashof (s + l < p + q) by the shortest link, non-Grashof by the longest, special Grashof
# (s + l = p + q) by the shortest, or two equal pairs (S2X).
BARKER = [
    ((40, 90, 110, 100), "O2", "I-1 GCCC"),  # 40 + 110 < 190, the ground shortest
    ((100, 40, 120, 80), "O2", "I-2 GCRR"),  # 40 + 120 < 180, the input shortest
    ((100, 80, 40, 90), "O2", "I-3 GRCR"),  # 40 + 100 < 170, the coupler shortest
    ((100, 40, 120, 80), "O4", "I-4 GRRC"),  # the crank-rocker driven at its rocker: the output shortest
    ((100, 45, 50, 55), "O2", "II-1 RRR1"),  # 45 + 100 > 105, the ground longest
    ((100, 40, 120, 60), "O2", "III-2 SCRR"),  # 40 + 120 = 160 = 100 + 60, the input shortest
    ((100, 50, 100, 50), "O2", "III-5 S2X"),  # two equal pairs
]


@pytest.mark.parametrize("lengths, driver, code", BARKER, ids=[b[2] for b in BARKER])
def test_barker_type_from_the_link_lengths_with_the_driver_as_link_2(tmp_path, lengths, driver, code):
    from pinmech.solve.grashof import loop_classes
    from pinmech.model.planar_linkage import planar_linkage

    four_bar_files(tmp_path, *lengths, 60)
    (loop,) = loop_classes(planar_linkage(pinmech.load_linkage(tmp_path / "fb.toml")))
    assert loop.barker({"O2": "crank", "O4": "rocker"}[driver]) == code


def test_a_crank_rocker_driven_at_its_rocker_stops_where_crank_and_coupler_fold(tmp_path):
    """The crank-rocker a 40, b 120, c 80, d 100 mm driven at its rocker (Barker GRRC): the
    rocker cannot pass the toggle where crank and coupler fold, |O2 B| = b - a; its angle
    there from the triangle O2 O4 B, 180 deg - acos((c^2 + d^2 - (b - a)^2) / (2 c d)) =
    128.682 deg. The dyad coupler-crank at A has mu = 0 there (folded), pressure angle 90."""
    a, b, c, d = 40, 120, 80, 100
    fold = 180 - math.degrees(math.acos((c * c + d * d - (b - a) ** 2) / (2 * c * d)))
    four_bar_files(tmp_path, d, a, b, c, 0)
    scene = tmp_path / "rocker_scene.toml"
    scene.write_text('title = "fb"\nlinkage = "fb.toml"\n[drivers.O4]\nangle = "97 deg"\nspeed = "60 rpm"\n')
    _, design = swept(scene, 97, 457, 73, skip_failures=True)
    (x,) = design.angle_extremes()
    np.testing.assert_allclose([x.low, x.pressure], [0.0, 90.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(math.degrees(x.low_at), fold, rtol=0, atol=FOLD_TOL_DEG)


def test_an_inverted_slider_cranks_block_square_to_its_rod_reports_one_constant_angle(capsys):
    """The R-RTR of Problem Chapter I.9 (Marghitu, Mechanisms and Robots Analysis with
    MATLAB): the block on link 2 slides along link 3, pinned to it at the slide, so the
    angle between them is 90 deg at every pose by construction. The summary says so once
    ("= 90 deg at every pose"), not "from 90 deg at one pose to 90 deg at another" with the
    pressure angle's rounding (~1e-14 deg) as its largest value."""
    from pinmech.cli import main

    from .conftest import SCENES

    assert main(["sweep", str(SCENES / "r_rtr.toml")]) == 0
    said = capsys.readouterr().err
    line = next(x for x in said.splitlines() if "transmission angle" in x)
    assert line.endswith("transmission angle mu = 90 deg at every pose, pressure angle |90 deg - mu| = 0 deg "
                         "(constant to 1e-09 deg over the 361 poses)")
    assert " from " not in line and "e-1" not in line


def test_a_constant_transmission_angle_is_one_value_in_the_json_and_the_report_table(tmp_path):
    """The same R-RTR: the summary's JSON says mu is constant (pi/2 to rounding), the
    report's design table prints it once; a four-bar's mu is not constant."""
    from pinmech.draw.report_design import design_rows
    from pinmech.solve.design_summary import design_summary

    from .conftest import SCENES

    for scene, constant in (("r_rtr.toml", True), ("four_bar.toml", False)):
        sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(SCENES / scene))
        design = design_of(sweep)
        for pose in sweep.poses(np.linspace(0.0, 2 * np.pi, 73)):
            design.add(pose)
        (dyad,) = design_summary(sweep)["dyads"]
        assert dyad["transmission_angle_constant"] is constant, scene
        if constant:
            assert abs(dyad["transmission_angle_least"] - math.pi / 2) < 1e-12  # rounding of unit vectors
            rows = [cell for head, cell in design_rows(design_summary(sweep)) if head.startswith("μ at")]
            assert rows == ['<span data-key="dyads.0.transmission_angle_least">90</span>° at every pose (constant)']


@pytest.mark.parametrize("side, constant", [("left", True), ("right", False)],
                         ids=["parallelogram", "antiparallelogram"])
def test_a_parallelograms_mechanical_advantage_is_one_value_not_a_least_at_a_pose(tmp_path, side, constant):
    """A four-bar of two equal pairs (ground = coupler 100 mm, crank = rocker 40 mm) drawn
    at 30 deg on its parallelogram branch: the rocker stays parallel to the crank, so it
    turns with it, omega4 = omega2 at every pose, through both change points, and the
    mechanical advantage |omega2 / omega4| is 1 (the summary said "least 1 at O2 = 110.282
    deg", a pose rounding chose). On the antiparallelogram branch it varies."""
    from pinmech.solve.design_summary import design_summary

    scene = four_bar_files(tmp_path, 100, 40, 100, 40, drawn=30, side=side)
    sweep, design = swept(scene, 30, 390 - 1, 73)  # no pose exactly on a change point (180, 360 deg)
    (stat,) = design.advantages
    (entry,) = design_summary(sweep)["outputs"]
    line = next(x for x in design.summary() if "mechanical advantage" in x)
    assert entry["mechanical_advantage_constant"] is constant and stat.constant is constant
    if constant:
        assert abs(stat.low - 1) < 1e-12 and abs(stat.high - 1) < 1e-12  # rates solved to ~1e-15 relative
        assert line.endswith("mechanical advantage |driver rate / rocker's rate| 1 [1] at every pose "
                             "(constant to 1e-09 of it over the 73 poses)")
    else:
        assert stat.high - stat.low > 0.1 and " least " in line
    assert "limit positions" not in line  # neither rocker has one: it never stops
