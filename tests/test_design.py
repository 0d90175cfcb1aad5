"""Design diagnostics against closed forms derived apart from Pinocchio (Norton, Design of
Machinery, ch. 2, 4, 6): Grashof classes, transmission and pressure angles, limit
positions, stroke, swing and time ratio, instant centres (the point of zero relative
velocity, by finite differences), mechanical advantage, and their CLI exposure."""

from __future__ import annotations

import csv
import json
import math
import re

import numpy as np
import pytest
from closed_form import four_bar

import pinmech
from pinmech.cli import main
from pinmech.solve.diagnostics_sweep import design_of
from pinmech.exceptions import DiagnosticError
from pinmech.solve.grashof import loop_classes
from pinmech.solve.instant_centres import instant_centres
from pinmech.model.planar_linkage import planar_linkage

from .conftest import MODELS, SCENES
from tests.tolerance import REGULAR, closure, rounding

DEG = math.pi / 180
#: Angles from the solved pose against the closed form: both are exact to rounding of
#: the closure (tol 1e-13 of the loop's size), so 1e-9 deg leaves a margin of 1e4.
ANGLE_TOL = 1e-9
#: Limit positions are bisected to 1e-12 rad (BISECTION_TOL); where the output's rate
#: vanishes it varies linearly, so the driver value is found to about the closure
#: tolerance over the slope: 1e-8 rad is a margin of 100 over what was measured (1e-10).
DRIVER_TOL = 1e-8


def _four_bar_files(tmp_path, d, a, b, c, drawn=0.0):
    """A drawn four-bar O2 (0, 0), O4 (d, 0), crank a drawn at `drawn` deg, coupler b,
    rocker c [mm], B left of A -> O4, and a scene driving O2 at 60 rpm."""
    linkage = tmp_path / "four_bar.toml"
    linkage.write_text(f"""title = "four-bar"
ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["{d} mm", "0 mm"]
A = {{ from = "O2", length = "{a} mm", angle = "{drawn} deg" }}
B = {{ from = ["A", "O4"], lengths = ["{b} mm", "{c} mm"], side = "left" }}
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
""")
    scene = tmp_path / "four_bar_scene.toml"
    scene.write_text('title = "four-bar"\nlinkage = "four_bar.toml"\n[drivers.O2]\nangle = "0 deg"\nspeed = "60 rpm"\n')
    return scene


def _solve(scene, angle_deg: float):
    return pinmech.analyse(pinmech.Scene.load(scene, [f'drivers.O2.angle="{angle_deg} deg"']))


def analysis_design(analysis):
    """The design section `pinmech solve` reports (with the mechanical advantage)."""
    from pinmech.io.report import scene_design

    return scene_design(analysis)


# Norton §2.12: s + l vs p + q, and which link is the shortest. (d, a, b, c) [mm], the
# class, the links turning fully, the crank angle drawn and crank angles it reaches [deg].
GRASHOF = [
    ((100, 40, 120, 80), "crank-rocker", ["crank"], 0, (0, 40, 130, 250)),  # shortest next to the ground
    ((40, 90, 110, 100), "double-crank", ["crank", "rocker"], 0, (0, 40, 130, 250)),  # shortest: the ground
    ((100, 80, 40, 90), "double-rocker", [], 60, (55, 60, 70)),  # shortest: the coupler
    ((100, 50, 100, 50), "change point", ["crank", "rocker"], 60, ()),  # a parallelogram: s + l = p + q
    ((100, 45, 50, 55), "triple rocker", [], 0, (-8, 0, 9)),  # s + l = 145 > p + q = 105
]


@pytest.mark.parametrize("lengths, label, cranks, drawn, angles", GRASHOF, ids=[g[1] for g in GRASHOF])
def test_grashof_class_of_each_four_bar(tmp_path, lengths, label, cranks, drawn, angles):
    d, a, b, c = lengths
    scene = _four_bar_files(tmp_path, d, a, b, c, drawn)
    mech = pinmech.load_linkage(tmp_path / "four_bar.toml")
    (loop,) = loop_classes(planar_linkage(mech))
    assert (loop.kind, loop.label, list(loop.cranks)) == ("four-bar", label, cranks)
    # the lengths read off the model are the drawn ones (1e-12 m: coordinates from mm)
    np.testing.assert_allclose([loop.lengths[n] for n in ("ground", "crank", "coupler", "rocker")],
                               np.array(lengths) / 1000, rtol=0, atol=rounding(0.2))
    assert scene.exists()


@pytest.mark.parametrize("lengths, label, cranks, drawn, angles", [g for g in GRASHOF if g[4]],
                         ids=[g[1] for g in GRASHOF if g[4]])
def test_transmission_angle_is_the_law_of_cosines_angle(tmp_path, lengths, label, cranks, drawn, angles):
    """Norton §4.10: cos mu = (b^2 + c^2 - (a^2 + d^2 - 2 a d cos theta2)) / (2 b c), the
    diagonal O4 A by the law of cosines; pressure angle 90 deg - acute mu."""
    d, a, b, c = (x / 1000 for x in lengths)
    scene = _four_bar_files(tmp_path, *lengths, drawn)
    for theta in angles:
        design = analysis_design(_solve(scene, theta))
        ((dyad, got),) = design.dyads
        diagonal2 = a**2 + d**2 - 2 * a * d * math.cos(theta * DEG)
        mu = math.degrees(math.acos((b**2 + c**2 - diagonal2) / (2 * b * c)))
        np.testing.assert_allclose(got.mu, mu, rtol=0, atol=ANGLE_TOL)
        np.testing.assert_allclose(got.mu_acute, min(mu, 180 - mu), rtol=0, atol=ANGLE_TOL)
        np.testing.assert_allclose(got.pressure, 90 - min(mu, 180 - mu), rtol=0, atol=ANGLE_TOL)


def test_mechanical_advantage_of_a_four_bar_is_omega2_over_omega4():
    """Norton eq. 6.18: omega4 / omega2 = a sin(theta2 - theta3) / (c sin(theta4 - theta3)),
    theta3 and theta4 of the closed form; the torque ratio is its inverse (virtual power)."""
    for theta in (60.0, 150.0, 300.0):
        analysis = _solve(SCENES / "four_bar.toml", theta)
        design = analysis_design(analysis)
        fb = four_bar(theta * DEG, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10)
        expected = 1.0 / float(fb.omega4)
        # rates to the closure's rounding times the condition number: 1e-10 relative
        np.testing.assert_allclose(design.advantage["rocker"][0], expected, rtol=1e-10)
        assert design.advantage["rocker"][1] == "1"


def test_pressure_angle_of_the_offset_slider_crank():
    """sin phi = |r sin theta - e| / l: the rod's angle to the slide (r 50, l 150, e 10 mm)."""
    for theta in (30.0, 100.0, 200.0, 290.0):
        analysis = pinmech.analyse(pinmech.Scene.load(SCENES / "slider_crank.toml",
                                                      [f'drivers.O.angle="{theta} deg"']))
        ((dyad, angles),) = analysis_design(analysis).dyads
        phi = math.degrees(math.asin(abs(0.05 * math.sin(theta * DEG) - 0.01) / 0.15))
        np.testing.assert_allclose(angles.pressure, phi, rtol=0, atol=ANGLE_TOL)
        np.testing.assert_allclose(angles.mu, 90 - phi, rtol=0, atol=ANGLE_TOL)


def _sweep_design(scene, steps=73):
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scene))
    design = design_of(sweep)
    for pose in sweep.poses(sweep.default_values(steps)):
        design.add(pose)
    return sweep, design


def test_dead_centres_stroke_and_time_ratio_of_the_offset_slider_crank():
    """Extended (TDC): |OB| = l + r; folded (BDC): |OB| = l - r, B on the line y = e, so
    theta_TDC = atan2(e, x_TDC), theta_BDC = atan2(-e, -x_BDC); stroke x_TDC - x_BDC;
    Q the ratio of the crank angles between them (Norton §4.10)."""
    r, l, e = 0.05, 0.15, 0.01
    x_tdc, x_bdc = math.sqrt((l + r) ** 2 - e**2), math.sqrt((l - r) ** 2 - e**2)
    th_tdc, th_bdc = math.atan2(e, x_tdc) % (2 * math.pi), math.atan2(-e, -x_bdc) % (2 * math.pi)
    sweep, design = _sweep_design(SCENES / "slider_crank.toml")
    (found,) = design.limits()
    by_label = {x.label.split()[0]: x for x in found}
    np.testing.assert_allclose(by_label["max"].driver % (2 * math.pi), th_tdc, rtol=0, atol=DRIVER_TOL)
    np.testing.assert_allclose(by_label["min"].driver % (2 * math.pi), th_bdc, rtol=0, atol=DRIVER_TOL)
    np.testing.assert_allclose([by_label["max"].value, by_label["min"].value], [x_tdc, x_bdc], rtol=0, atol=closure(0.2, REGULAR))
    assert (by_label["max"].toggle, by_label["min"].toggle) == ("extended", "folded")
    summary = "\n".join(design.summary(2 * math.pi))
    beta = th_bdc - th_tdc
    q = max(beta, 2 * math.pi - beta) / min(beta, 2 * math.pi - beta)
    assert f"stroke {x_tdc - x_bdc:.6g} m" in summary and f"Q = {q:.6g}" in summary


def test_crank_shaper_time_ratio_is_two():
    """Crank r = 50 mm, lever pivot d = 100 mm below: the lever's extremes are where it is
    tangent to the crank circle, the crank at -90 deg +- acos(r/d); swing 2 asin(r/d),
    Q = (180 + 2 asin(r/d)) / (180 - 2 asin(r/d)) = 2 (the figure a user had computed
    by hand from the JSON)."""
    r, d = 0.05, 0.10
    sweep, design = _sweep_design(SCENES / "crank_shaper.toml")
    (found,) = design.limits()
    crank = sorted(x.driver % (2 * math.pi) for x in found)
    expected = sorted(((-90 + s * math.degrees(math.acos(r / d))) % 360) * DEG for s in (-1, 1))
    np.testing.assert_allclose(crank, expected, rtol=0, atol=DRIVER_TOL)
    from pinmech.solve.limit_positions import travel

    t = travel(found, 2 * math.pi)
    np.testing.assert_allclose(t.travel, 2 * math.asin(r / d), rtol=0, atol=1e-10)
    half = math.degrees(2 * math.asin(r / d))
    np.testing.assert_allclose(t.ratio, (180 + half) / (180 - half), rtol=1e-10)


def test_rocker_extremes_swing_and_time_ratio_of_the_crank_rocker():
    """Rocker extremes where crank and coupler are in line: |O2 B| = b + a (extended) and
    b - a (folded); B from the circles (O2, b +- a) and (O4, c), above the ground line (the
    drawn assembly). Norton §4.10: Q = alpha / beta of the crank angles between them."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    angles, crank = [], []
    for reach, flip in ((b + a, 0.0), (b - a, math.pi)):
        x = (reach**2 - c**2 + d**2) / (2 * d)
        B = np.array([x, math.sqrt(reach**2 - x**2)])
        crank.append((math.atan2(B[1], B[0]) + flip) % (2 * math.pi))
        angles.append(math.atan2(B[1], B[0] - d))
    sweep, design = _sweep_design(SCENES / "four_bar.toml")
    (found,) = design.limits()
    np.testing.assert_allclose(sorted(x.driver % (2 * math.pi) for x in found), sorted(crank), rtol=0, atol=DRIVER_TOL)
    from pinmech.solve.limit_positions import travel

    t = travel(found, 2 * math.pi)
    np.testing.assert_allclose(t.travel, abs(angles[1] - angles[0]), rtol=0, atol=1e-10)
    alpha = (crank[1] - crank[0]) % (2 * math.pi)
    np.testing.assert_allclose(t.ratio, max(alpha, 2 * math.pi - alpha) / min(alpha, 2 * math.pi - alpha), rtol=1e-10)


MECHANISMS = ["four_bar.toml", "slider_crank.toml", "r_rtr.toml", "crank_shaper.toml", "jansen.toml"]


@pytest.mark.parametrize("scene", MECHANISMS + ["watt", "stephenson"])
def test_each_instant_centre_is_the_point_of_zero_relative_velocity(tmp_path, scene):
    """Central differences of the two links' points at the centre, each fixed in its link:
    their velocities agree (h = 1e-6 rad: truncation h^2 ~ 1e-12 of the link speeds,
    rounding eps / h ~ 1e-10: atol 1e-8 m/rad). Centres at infinity: no relative turning."""
    if scene in ("watt", "stephenson"):
        path = tmp_path / f"{scene}.toml"
        path.write_text(f'title = "{scene}"\nlinkage = "{MODELS / "linkages" / scene}.toml"\n'
                        '[drivers.O2]\nangle = "30 deg"\nspeed = "1 rad/s"\n')
    else:
        path = SCENES / scene
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(path))
    linkage = planar_linkage(sweep.mechanism)
    x0, h = sweep.start, 1e-6
    (q0,) = [p.motion for p in sweep.poses([x0])]
    q = design_of(sweep)._q(q0)
    poses = {s: sweep.solver.follow(q, np.array([x0]), np.array([x0 + s * h]), pinmech.Route((x0,))) for s in (-1, 1)}
    linkage.place(q)
    centres = instant_centres(linkage)
    n = len({x for p in linkage.pairs for x in p.links})
    assert len(centres) == n * (n - 1) // 2  # Kennedy's theorem reached every centre
    for (i, j), centre in centres.items():
        linkage.place(q)
        if centre.point is None:
            turn = {s: _angle(linkage, poses[s], i) - _angle(linkage, poses[s], j) for s in (-1, 1)}
            np.testing.assert_allclose((turn[1] - turn[-1]) / (2 * h), 0.0, atol=1e-8)
            continue
        on_i, on_j = linkage.to_link(i, centre.point), linkage.to_link(j, centre.point)
        moved = {}
        for s in (-1, 1):
            linkage.place(poses[s])
            moved[s] = linkage.point(i, on_i) - linkage.point(j, on_j)
        np.testing.assert_allclose((moved[1] - moved[-1]) / (2 * h), 0.0, atol=1e-8, err_msg=str(centre.links))


def _angle(linkage, q, link):
    linkage.place(q)
    d = linkage.direction(link, np.array([1.0, 0.0, 0.0]))
    return math.atan2(d[1], d[0])


def test_coupler_centre_of_a_four_bar_is_where_crank_and_rocker_lines_meet():
    """I13 (ground, coupler) is the meeting point of the lines O2A and O4B (Kennedy);
    O2, A, B, O4 from the closed form."""
    for theta in (60.0, 200.0):
        design = analysis_design(_solve(SCENES / "four_bar.toml", theta))
        fb = four_bar(theta * DEG, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10)
        A, B, O4 = np.asarray(fb.A), np.asarray(fb.B), np.array([0.10, 0.0])
        t = np.linalg.solve(np.column_stack([A, -(B - O4)]), O4)  # t A = O4 + s (B - O4)
        (centre,) = [c for c in design.centres if c.links == ("ground", "coupler")]
        np.testing.assert_allclose(centre.point, t[0] * A, rtol=1e-9)


def test_spatial_mechanism_is_refused_by_name_and_said_in_the_report(capsys):
    with pytest.raises(DiagnosticError, match="planar diagnostics need a planar mechanism"):
        planar_linkage(pinmech.load_linkage(MODELS / "linkages" / "rsur.toml"))
    assert main(["solve", str(SCENES / "rsur_drawn.toml")]) == 0
    assert "planar diagnostics: not applicable" in capsys.readouterr().out
    assert main(["sweep", str(SCENES / "rsur_drawn.toml"), "--steps", "5", "--skip-failures"]) == 0
    out, err = capsys.readouterr()
    assert "design: planar diagnostics: not applicable" in err and "transmission_angle" not in out


def test_cli_solve_json_and_sweep_columns_carry_the_diagnostics(tmp_path, capsys):
    assert main(["solve", str(SCENES / "four_bar.toml"), "--json"]) == 0
    design = json.loads(capsys.readouterr().out)["design"]
    assert design["planar"] and design["loops"][0]["class"] == "crank-rocker"
    assert {"transmission_angle", "transmission_angle_acute", "pressure_angle"} <= set(design["dyads"][0])
    assert len(design["instant_centres"]) == 6 and design["mechanical_advantage"]["rocker"]["unit"] == "1"
    out, lines = tmp_path / "s.csv", tmp_path / "s.jsonl"
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "37", "--csv", str(out), "--json", str(lines)]) == 0
    err = capsys.readouterr().err
    assert "design: rocker: time ratio Q = 1.35557" in err and "swing" in err and "transmission angle" in err
    rows = list(csv.DictReader(out.open()))
    assert {"B.transmission_angle [deg]", "B.pressure_angle [deg]", "rocker.mechanical_advantage [1]"} <= set(rows[0])
    first = json.loads(lines.read_text().splitlines()[0])
    mu = math.radians(float(rows[0]["B.transmission_angle [deg]"]))
    np.testing.assert_allclose(first["design"]["dyads"]["B"]["transmission_angle"], mu, rtol=1e-11)


def test_fixed_centrode_of_the_coupler_is_the_meeting_point_of_crank_and_rocker_lines():
    """The fixed centrode of the coupler traces I13 (lines O2A and O4B meet), the moving
    centrode is that point in the coupler's frame: mapped back, it is the same point."""
    from pinmech.solve.instant_centres import centrodes

    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(SCENES / "four_bar.toml"))
    thetas = np.radians([60.0, 100.0, 200.0])
    qs = [design_of(sweep)._q(p.motion) for p in sweep.poses(thetas)]
    linkage = planar_linkage(sweep.mechanism)
    coupler = next(i for i, n in linkage.names.items() if n == "coupler")
    fixed, moving = centrodes(linkage, coupler, np.array(qs))
    for theta, q, f, m in zip(thetas, qs, fixed, moving):
        fb = four_bar(theta, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10)
        A, B, O4 = np.asarray(fb.A), np.asarray(fb.B), np.array([0.10, 0.0])
        t = np.linalg.solve(np.column_stack([A, -(B - O4)]), O4)
        np.testing.assert_allclose(f, t[0] * A, rtol=1e-9)  # closed form vs Kennedy: rounding x 1e6
        linkage.place(q)
        np.testing.assert_allclose(linkage.point(coupler, m), f, rtol=0, atol=closure(0.2, REGULAR))


@pytest.mark.parametrize("first, last", [("0 deg", "360 deg"), ("420 deg", "60 deg")], ids=["forward", "backward"])
def test_rocker_extremes_are_named_by_the_rocker_not_by_the_sweeps_direction(tmp_path, first, last):
    """The crank-rocker swept either way: the rocker's largest angle is at the folded toggle
    and its least at the extended one (angles of B from the circles (O2, b -+ a) and (O4, c)),
    and the swing is their difference (swept backwards it was named the other way round and
    the swing given as 286 deg)."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    theta4 = {}
    for reach, lay in ((b + a, "extended"), (b - a, "folded")):
        x = (reach**2 - c**2 + d**2) / (2 * d)
        theta4[lay] = math.atan2(math.sqrt(reach**2 - x**2), x - d)
    scene = pinmech.Scene.load(SCENES / "four_bar.toml", [f'sweep.from="{first}"', f'sweep.to="{last}"'])
    sweep = pinmech.Sweep.from_scene(scene)
    design = design_of(sweep)
    start, stop = (scene.quantity(v, "angle") for v in (first, last))
    for pose in sweep.poses(np.linspace(start, stop, 73)):
        design.add(pose)
    (found,) = design.limits()
    labels = {x.toggle: x.label for x in found}
    assert labels == {"folded": "max", "extended": "min"}
    np.testing.assert_allclose(sorted(x.value for x in found), sorted(theta4.values()), rtol=0, atol=1e-10)
    from pinmech.solve.limit_positions import travel

    np.testing.assert_allclose(travel(found, None).travel, theta4["folded"] - theta4["extended"], rtol=0, atol=1e-10)


def test_least_and_largest_transmission_angle_are_located_between_the_poses():
    """Crank-rocker a = 40, coupler b = 120, rocker c = 80, ground d = 100 mm (Norton §4.10):
    cos mu = (b^2 + c^2 - a^2 - d^2 + 2 a d cos theta) / (2 b c) is extreme where cos theta
    is, so the least mu is at theta = 0 and the largest at theta = 180 deg. The sweep's poses
    (every 30 deg from 7 deg) miss both; the summary locates them between the poses."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10

    def mu(theta):
        return math.degrees(math.acos((b**2 + c**2 - a**2 - d**2 + 2 * a * d * math.cos(theta)) / (2 * b * c)))

    scene = pinmech.Scene.load(SCENES / "four_bar.toml", ['sweep.from="7 deg"', 'sweep.to="367 deg"'])
    sweep = pinmech.Sweep.from_scene(scene)
    design = design_of(sweep)
    for pose in sweep.poses(sweep.default_values(13)):
        design.add(pose)
    ((low, low_at, high, high_at),) = [(x.low, x.low_at, x.high, x.high_at) for x in design.angle_extremes()]
    # The driver value is refined to 1e-10 rad where mu is flat (a minimum): mu is then
    # exact to ~(1e-10)^2, the angle to the closure's rounding; 1e-8 rad and 1e-9 deg margins.
    np.testing.assert_allclose(low_at % (2 * math.pi), 2 * math.pi, rtol=0, atol=DRIVER_TOL)
    np.testing.assert_allclose(high_at, math.pi, rtol=0, atol=DRIVER_TOL)
    np.testing.assert_allclose([low, high], [mu(0.0), mu(math.pi)], rtol=0, atol=ANGLE_TOL)
    summary = "\n".join(design.summary(2 * math.pi))
    # a position is printed in [0, 360) deg: 2 pi less 1e-10 rad is "0 deg", not "360 deg"
    assert f"from {mu(0.0):.6g} deg at O2 = 0 deg to {mu(math.pi):.6g} deg at O2 = 180 deg" in summary


@pytest.mark.parametrize("through_folds", [False, True], ids=["stops at the fold", "through the folds"])
def test_folds_of_a_non_grashof_crank_are_listed_with_the_limit_positions(tmp_path, through_folds):
    """Triple rocker d = 100, a = 45, b = 50, c = 55 mm: the crank stops where coupler and
    rocker are in line, |O4 A| = b + c; by the law of cosines
    cos theta = (a^2 + d^2 - (b + c)^2) / (2 a d), theta = +-83.62 deg (Norton §2.12)."""
    a, b, c, d = 45, 50, 55, 100
    fold = math.degrees(math.acos((a**2 + d**2 - (b + c) ** 2) / (2 * a * d)))
    scene = _four_bar_files(tmp_path, d, a, b, c)
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scene))
    design = design_of(sweep)
    for pose in sweep.poses(sweep.default_values(13), skip_failures=True, through_folds=through_folds):
        design.add(pose)
    found = sorted(math.degrees(x) for x in design.folds())
    # The engine locates a fold to rounding (DriverLimitError); through the folds the fold is
    # halfway between the poses' mirrored values, exact to rounding too: 1e-8 deg margin.
    expected = [fold] if not through_folds else [-fold, fold]
    np.testing.assert_allclose(found, expected, rtol=0, atol=1e-8)
    summary = "\n".join(design.summary(2 * math.pi))
    assert f"design: O2: fold (limit position of the driver) at O2 = {fold:.6g} deg" in summary


def _shaper_files(tmp_path, along: str):
    """The crank-shaper of models/linkages/crank_shaper.toml (crank r = 50 mm about A,
    lever pivot C 100 mm below A) with its slot drawn through B along `along`."""
    text = (MODELS / "linkages" / "crank_shaper.toml").read_text()
    (tmp_path / "shaper.toml").write_text(text.replace('along = ["C", "B"]', f"along = {along}"))
    scene = tmp_path / "shaper_scene.toml"
    scene.write_text('title = "shaper"\nlinkage = "shaper.toml"\n[drivers.A]\nangle = "90 deg"\nspeed = "60 rpm"\n')
    return scene


@pytest.mark.parametrize("along, offset", [('["C", "B"]', 0.0), ('"80 deg"', 0.15 * math.cos(80 * DEG))])
def test_pressure_angle_of_the_inverted_slider_crank_is_set_by_the_slots_offset(tmp_path, along, offset):
    """Inverted slider-crank (Norton §4.7): the block on the crank pin P pushes the lever,
    without friction, normal to the slot; the lever's point at P moves normal to C P. The
    pressure angle is the angle between the two, i.e. between the slot and C P: sin phi =
    e / |C P|, e the slot's offset from the pivot C (drawn through B = (0, 50) mm at 80 deg:
    e = 150 mm cos 80 deg = 26.05 mm, less than |C P| >= d - r = 50 mm), P = r (cos theta, sin theta), C = (0, -d). A slot
    through the pivot (the crank-shaper) transmits at mu = 90 deg in every pose."""
    r, d = 0.05, 0.10
    scene = _shaper_files(tmp_path, along)
    for theta in (0.0, 75.0, 160.0, 230.0, 300.0):
        ((dyad, angles),) = analysis_design(pinmech.analyse(pinmech.Scene.load(
            scene, [f'drivers.A.angle="{theta} deg"']))).dyads
        cp = math.hypot(r * math.cos(theta * DEG), r * math.sin(theta * DEG) + d)
        phi = math.degrees(math.asin(offset / cp))
        assert dyad.kind == "slot"
        np.testing.assert_allclose(angles.pressure, phi, rtol=0, atol=ANGLE_TOL)
        np.testing.assert_allclose(angles.mu, 90 - phi, rtol=0, atol=ANGLE_TOL)


def test_sweep_of_the_inverted_slider_crank_reports_its_transmission_angle(tmp_path, capsys):
    """mu = 90 deg - asin(e / |C P|) is least where |C P| is least, the crank pointing at C
    (theta = 270 deg, |C P| = d - r = 50 mm), and largest pointing away (90 deg, d + r);
    the slot along 80 deg: e = 150 mm cos 80 deg = 26.05 mm."""
    scene = _shaper_files(tmp_path, '"80 deg"')
    out = tmp_path / "sweep.csv"
    assert main(["sweep", str(scene), "--csv", str(out)]) == 0
    e = 0.15 * math.cos(80 * DEG)
    low, high = 90 - math.degrees(math.asin(e / 0.05)), 90 - math.degrees(math.asin(e / 0.15))
    line = next(x for x in capsys.readouterr().err.splitlines() if "B_slide: transmission angle" in x)
    found = re.search(r"from (\S+) deg at A = (\S+) deg to (\S+) deg at A = (\S+) deg", line).groups()
    got = [float(x) for x in found]
    got[1::2] = [x % 360 for x in got[1::2]]
    # the extremes are located by golden-section search to 1e-10 rad of the driver; the
    # report prints 6 significant digits: rtol 1e-5
    np.testing.assert_allclose(got, [low, 270, high, 90], rtol=1e-5)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    assert any("transmission_angle" in k for k in rows[0])
