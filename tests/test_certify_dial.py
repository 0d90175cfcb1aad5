"""The certification dial (`[solver] certify`, `--certify`, `LoopSolver(certify=)`): at each
level a sweep still lands on the closed form, and what it passes (a change point, a fold)
is named as at every pose.

References, each independent of pinmech: the R-RTR's vector-loop solution
(scripts/closed_form.py); a four-bar's rocker angle from Freudenstein's equation
K1 cos(t4) - K2 cos(t2) + K3 = cos(t2 - t4), solved here as a quadratic in tan(t4 / 2);
a non-Grashof four-bar's limit angle from the law of cosines (|A - O4| = b - c); a
parallelogram's change point where its crank lies along the ground (t2 = 0).

What each level keeps: every pose has its closure, velocity and acceleration residuals
and its assembly signature (so every pose meets the same closed form, to the bound of a
closed pose at the cycle's condition number, and every change point is named); certified poses (every pose, every K-th and a range's last, a range's
last) have their condition number, the others NaN. A MUTANT test
shows the due-pose check at work: the same assertion on a pose over max_condition fails when
the due poses are not certified (level "none": every-K with its due checks skipped).
"""

from __future__ import annotations

import csv
import io
import json
import math

import closed_form
import numpy as np
import pytest

from pinmech import LoopSolver, Mechanism, OptionError, Scene
from pinmech.cli import main
from pinmech.exceptions import DriverLimitError, SingularPoseError
from pinmech.io.sweep import Sweep
from pinmech.solve.cycle import solve_range
from tests._mechanisms import four_bar_urdf, write
from tests.tolerance import closure

LEVELS = ("every-pose", "every-10", "every-3", "ends", "none")
OMEGA1 = -50 * np.pi / 30  # the R-RTR scene's crank speed [rad/s]
#: The R-RTR's constraint Jacobian stays under this condition number over a turn
#: (tests/test_r_rtr.py); the bar of a closed pose there is closure(scale, R_RTR_COND, order).
R_RTR_COND = 100.0
#: The bundled crank-rocker: a = 40, b = 120, c = 80, d = 100 mm (Grashof: 40 + 120 < 80 + 100).
CRANK_ROCKER = (0.04, 0.12, 0.08, 0.10)
#: Its condition number stays under this over a turn (transmission angle from 28 to 97 deg:
#: the Jacobian's smallest singular value is about sin(mu) in loop sizes).
CRANK_ROCKER_COND = 50.0


def _freudenstein(theta2: np.ndarray, a: float, b: float, c: float, d: float, branch: int) -> np.ndarray:
    """Rocker angle t4 [rad] of the four-bar O2 = (0, 0), O4 = (d, 0) at crank angle t2, from
    K1 cos t4 - K2 cos t2 + K3 = cos(t2 - t4) with K1 = d/a, K2 = d/c,
    K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c): with u = tan(t4/2), A u^2 + B u + C = 0,
    A = cos t2 - K1 - K2 cos t2 + K3, B = -2 sin t2, C = K1 - (K2 + 1) cos t2 + K3."""
    k1, k2, k3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    A = np.cos(theta2) - k1 - k2 * np.cos(theta2) + k3
    B = -2.0 * np.sin(theta2)
    C = k1 - (k2 + 1.0) * np.cos(theta2) + k3
    return 2.0 * np.arctan2(-B + branch * np.sqrt(B * B - 4 * A * C), 2 * A)


def _wrapped(x: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * x))


def _conditions(chunks) -> np.ndarray:
    return np.concatenate([c.solution.condition for c in chunks])


def _range(solver: LoopSolver, values, **kw) -> list:
    return list(solve_range(solver, solver.drivers[0], values, driver_q=np.zeros(1), driver_v=np.ones(1),
                            driver_a=np.zeros(1), **kw))


# ------------------------------------------------------------------ every level against a closed form
@pytest.mark.parametrize("level", LEVELS)
def test_the_r_rtr_over_a_turn_meets_its_closed_form_at_every_level(r_rtr_scene, level):
    """Positions, velocities and accelerations of D at 361 crank angles, each within the bound
    of a pose closed to the tolerance at the cycle's condition number: the residuals hold at
    every pose whatever the level."""
    sweep = Sweep.from_scene(Scene.load(r_rtr_scene, [f'solver.certify="{level}"']))
    values = sweep.default_values(361)
    poses = list(sweep.poses(values))
    cf = closed_form.r_rtr(values, OMEGA1, 0.0)
    points = [p.motion.points["D"] for p in poses]
    for order, ours, theirs in ((0, [p.position[:2] for p in points], cf.D),
                                (1, [p.velocity[:2] for p in points], cf.vD),
                                (2, [p.acceleration[:2] for p in points], cf.aD)):
        np.testing.assert_allclose(np.array(ours), theirs, rtol=0, atol=closure(theirs, R_RTR_COND, order))
    certified = np.array([p.accuracy.certified for p in poses])
    assert certified[-1] == (level != "none")  # a range's last pose is certified at every level but "none"
    if level == "every-pose":
        assert certified.all()
    elif level.startswith("every-"):
        k = int(level.split("-")[1])
        assert len(poses) // k <= certified.sum() <= len(poses) // k + 3  # every K-th, the ends
    else:  # ends, none: the first pose (the scene's, solved on its own) and the last
        assert certified.sum() <= 2
    conditions = np.array([p.accuracy.condition for p in poses])
    assert np.all(conditions[certified] < R_RTR_COND) and np.isnan(conditions[~certified]).all()


@pytest.mark.parametrize("level", LEVELS)
def test_a_crank_rocker_over_a_turn_meets_freudenstein_at_every_level(tmp_path, level):
    """The rocker angle at 720 crank angles against Freudenstein's equation, on the branch
    the reference pose (60 deg) is on."""
    a, b, c, d = CRANK_ROCKER
    mech = Mechanism.from_urdf(write(tmp_path, "fb.urdf", four_bar_urdf(a, b, c, d)))
    t2 = math.radians(60)
    t4 = float(_freudenstein(np.array(t2), a, b, c, d, +1))
    B = np.array([d + c * math.cos(t4), c * math.sin(t4)])
    t3 = math.atan2(B[1] - a * math.sin(t2), B[0] - a * math.cos(t2))
    q = mech.neutral()
    for name, value in (("O2", t2), ("A", t3 - t2), ("O4", t4)):
        mech.set_coordinate(q, name, value)
    solver = LoopSolver(mech, ["O2"], certify=level)
    solver.set_reference([t2], q)
    values = t2 + np.linspace(0.0, 2 * np.pi, 720)
    chunks = _range(solver, values)
    qs = np.concatenate([ch.solution.q for ch in chunks])
    rocker = np.array([mech.coordinate(qi, "O4") for qi in qs])
    expected = _freudenstein(values, a, b, c, d, +1)
    np.testing.assert_allclose(_wrapped(rocker - expected), 0.0, atol=closure(np.pi, CRANK_ROCKER_COND))
    assert not any(ch.errors for ch in chunks) and not any(ch.notes for ch in chunks)
    assert (np.isnan(_conditions(chunks)).any()) == (level != "every-pose")


# ------------------------------------------------------------------ a change point between certified poses
def _parallelogram(tmp_path, level: str, max_condition: float = 1e4) -> LoopSolver:
    """The parallelogram a = c = 50 mm, b = d = 100 mm on its parallelogram branch at crank
    angle 1 rad (rocker = crank, coupler along the ground): its branches cross where the
    crank lies along the ground (t2 = 0, pi)."""
    mech = Mechanism.from_urdf(write(tmp_path, "pg.urdf", four_bar_urdf(0.05, 0.1, 0.05, 0.1)))
    q = mech.neutral()
    for name, value in (("O2", 1.0), ("A", -1.0), ("O4", 1.0)):
        mech.set_coordinate(q, name, value)
    solver = LoopSolver(mech, ["O2"], certify=level, max_condition=max_condition)
    solver.set_reference([1.0], q)
    return solver


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("turn, crossings, located", [(False, [0.0], 1e-6), (True, [np.pi, 2 * np.pi], 1e-3)])
def test_change_points_between_certified_poses_are_named_as_at_every_pose(tmp_path, level, turn, crossings, located):
    """From 1 rad down through 0 (100 crank angles, none on the crossing), or a whole turn
    up (25 angles: two crossings, at pi and 2 pi, the signature back as it was at the end):
    each change point is noted where the closed form puts it (the middle of the continuation
    step that passed it: 1e-6 rad on the fine range, 1e-3 rad on the coarse turn, whose
    steps are 0.26 rad) and the sweep keeps the branch of continuous tangent (rocker =
    crank). Every pose keeps its assembly signature whatever the level: an uncertified step
    that finds another one is refused, and the range followed again with every pose
    certified, so the notes are the ones every pose gives."""
    solver = _parallelogram(tmp_path, level)
    values = np.linspace(1.0, 1.0 + 2 * np.pi, 25) if turn else np.linspace(1.0, -1.0, 100)
    chunks = _range(solver, values)
    notes = {ch.start + j: n for ch in chunks for j, n in ch.notes.items()}
    where = [math.radians(float(n.split("O2 = ")[1].split(" deg")[0])) for n in notes.values()]
    assert len(where) == len(crossings) and np.all(np.abs(np.array(where) - crossings) < located), notes
    for i, at in zip(notes, crossings):  # each note on the first pose past its crossing
        assert values[i - 1] < at < values[i] or values[i] < at < values[i - 1]
    qs = np.concatenate([ch.solution.q for ch in chunks])
    rocker = np.array([solver.mechanism.coordinate(qi, "O4") for qi in qs])
    np.testing.assert_allclose(_wrapped(rocker - values), 0.0, atol=closure(np.pi, 1e3))


# ------------------------------------------------------------------ a pose over max_condition at a due pose
def _assert_the_ill_conditioned_pose_is_named(tmp_path, level: str) -> None:
    """The parallelogram driven from 1 rad toward its crossing (100 angles down to 1 mrad)
    with max_condition = 100: its condition number grows about as 1/t2 (from the closed
    form: the coupler and the crank become collinear), so the poses from t2 = 1.2 deg on
    are singular poses, named as such (SingularPoseError) by a sweep at every pose; the
    range's last pose is a due pose at every-K and ends."""
    solver = _parallelogram(tmp_path, level, max_condition=100.0)
    values = np.linspace(1.0, 0.001, 100)
    chunks = _range(solver, values)
    errors = {ch.start + j: e for ch in chunks for j, e in ch.errors.items()}
    assert sorted(errors) == [97, 98, 99], sorted(errors)
    assert all(isinstance(e, SingularPoseError) and e.condition > 100.0 for e in errors.values())


@pytest.mark.parametrize("level", ["every-pose", "every-10", "every-3", "ends"])
def test_a_due_pose_over_max_condition_names_the_first_singular_pose_as_at_every_pose(tmp_path, level):
    """The poses before the range's last are left uncertified at every-10, every-3 and ends:
    the last, certified, is over max_condition, the core goes back to the last certified
    pose and certifies every pose up to it, and the first singular pose is named as at
    every pose."""
    _assert_the_ill_conditioned_pose_is_named(tmp_path, level)


def test_mutant_the_check_fails_without_the_due_pose_certification(tmp_path):
    """The MUTANT: every-K with its due-pose certification skipped is level "none" (no
    condition number anywhere): nothing compares a condition number with max_condition, the
    singular poses come back as answers (flagged "not certified") and the same assertion
    fails. This is what the due-pose check of every-K catches (the test above). A core built
    with the due landing left uncertified (pivot.cpp: certify_now_ = certify_all_) fails the
    test above the same way, at every-10, every-3 and ends."""
    with pytest.raises(AssertionError):
        _assert_the_ill_conditioned_pose_is_named(tmp_path, "none")


# ------------------------------------------------------------------ a fold
@pytest.mark.parametrize("level", LEVELS)
def test_a_fold_stops_the_sweep_at_its_law_of_cosines_angle_at_every_level(tmp_path, level):
    """A triple rocker (a, b, c, d = 70, 90, 50, 40 mm: 40 + 90 > 70 + 50) driven from 180 deg
    down by 5 deg: its crank cannot pass theta_lim = acos((a^2 + d^2 - (b - c)^2) / (2 a d))
    (law of cosines, |A - O4| = b - c). Every pose past it fails with DriverLimitError locating
    the limit to 1e-9 rad; every pose before it is on the closed form. Through the fold, the
    values past it are mirrored at the limit onto the other branch."""
    a, b, c, d = 0.07, 0.09, 0.05, 0.04
    lim = math.acos((a * a + d * d - (b - c) ** 2) / (2 * a * d))
    mech = Mechanism.from_urdf(write(tmp_path, "ng.urdf", four_bar_urdf(a, b, c, d)))

    def reference() -> LoopSolver:
        ref = closed_form.four_bar(math.pi, 0.0, 0.0, a, b, c, d, +1)
        q = mech.neutral()
        for name, value in (("O2", math.pi), ("A", float(ref.theta3) - math.pi), ("O4", float(ref.theta4))):
            mech.set_coordinate(q, name, value)
        solver = LoopSolver(mech, ["O2"], certify=level)
        solver.set_reference([math.pi], q)
        return solver

    values = np.radians(np.arange(180, -1, -5.0))
    chunks = _range(reference(), values)
    errors = {ch.start + j: e for ch in chunks for j, e in ch.errors.items()}
    past = values < lim
    assert sorted(errors) == list(np.flatnonzero(past))
    assert all(isinstance(e, DriverLimitError) and abs(e.limit[0] - lim) < 1e-9 for e in errors.values())
    chunks = _range(reference(), values, through_folds=True)
    got = np.concatenate([ch.values for ch in chunks])
    np.testing.assert_allclose(got[past], 2 * lim - values[past], rtol=0, atol=1e-9)
    qs = np.concatenate([ch.solution.q for ch in chunks])
    for theta, qi, mirrored in zip(got, qs, past):
        expected = closed_form.four_bar(theta, 0.0, 0.0, a, b, c, d, -1 if mirrored else +1)
        np.testing.assert_allclose(mech.coordinate(qi, "O4"), expected.theta4, rtol=0,
                                   atol=closure(np.pi, 1e4))  # condition grows toward the fold
    assert any("fold" in n for ch in chunks for n in ch.notes.values())


# ------------------------------------------------------------------ the levels as users write them
@pytest.mark.parametrize("value", ["every-0", "every-1.5", "every-", "sometimes", 10, None, "every-10000001"])
def test_an_unknown_level_is_an_option_error_naming_the_levels(value):
    mech = Mechanism.from_urdf(write_r_rtr())
    with pytest.raises(OptionError, match="certify = .* must be one of every-pose, every-K, ends, none"):
        LoopSolver(mech, ["A"], certify=value)


def write_r_rtr():
    from tests.conftest import MODELS

    return MODELS / "r_rtr.urdf"


def test_every_1_is_every_pose_and_a_level_is_checked_when_set_later():
    solver = LoopSolver(Mechanism.from_urdf(write_r_rtr()), ["A"], certify="every-1")
    assert solver.certify == "every-pose"
    with pytest.raises(OptionError):
        solver.certify = "every-0"
    assert solver.certify == "every-pose"


def test_the_scene_and_the_command_line_refuse_a_bad_level_in_one_line(r_rtr_scene, capsys):
    assert main(["sweep", str(r_rtr_scene), "--steps", "5", "--set", 'solver.certify="often"']) == 4
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "solver.certify" in err and "every-K" in err and "Traceback" not in err
    for level in ("every-0", "every-1.5", "every-99999999999999999999", ""):  # an empty one is not "not given"
        assert main(["sweep", str(r_rtr_scene), "--steps", "5", "--certify", level]) == 2, level
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "--certify" in err and (repr(level) if level else "is empty") in err


# ------------------------------------------------------------------ every output says so
def test_a_sweep_certified_every_10_poses_says_so_in_csv_json_and_text(r_rtr_scene, tmp_path, capsys):
    csv_path, json_path = tmp_path / "s.csv", tmp_path / "s.jsonl"
    assert main(["sweep", str(r_rtr_scene), "--steps", "25", "--certify", "every-10", "--csv", str(csv_path),
                 "--json", str(json_path)]) == 0
    assert "certified at every 10 poses" in capsys.readouterr().err
    text = csv_path.read_text()
    assert text.startswith("# condition number (and the error bounds it gives) certified at every 10 poses")
    rows = list(csv.DictReader(io.StringIO(text.split("\n", 1)[1])))
    cells = [r["condition_number [1]"] for r in rows]
    assert "nan" not in (c.lower() for c in cells)
    assert cells.count("not certified") == len(rows) - sum(1 for c in cells if c != "not certified") > 0
    assert all(float(c) >= 1.0 for c in cells if c != "not certified")

    def no_nan(word: str):
        raise AssertionError(f"{word} in the JSON lines")

    entries = [json.loads(line, parse_constant=no_nan) for line in json_path.read_text().splitlines()]
    assert all(e["certified"] == "every 10 poses" for e in entries)
    flags = [e["accuracy"]["certified"] for e in entries]
    assert flags == [c != "not certified" for c in cells]
    assert all(e["accuracy"]["condition_number"] is None for e in entries if not e["accuracy"]["certified"])


def test_a_sweep_at_every_pose_writes_what_it_wrote_before(r_rtr_scene, tmp_path, capsys):
    csv_path = tmp_path / "s.csv"
    assert main(["sweep", str(r_rtr_scene), "--steps", "5", "--csv", str(csv_path)]) == 0
    assert "certified" not in capsys.readouterr().err
    assert csv_path.read_text().startswith("A.q [deg],")


# ------------------------------------------------------------------ the rate solver (P2, the arm of 17.110)
@pytest.mark.parametrize("level", LEVELS)
def test_the_arms_rates_meet_the_closed_form_at_every_level(level):
    """RateSolver.solve_many at 360 poses of the planar arm of text 17.110 against its
    closed form (closed_form.planar_arm_rates): the rates are exact at every level; the
    condition number is NaN at the poses left uncertified, the ones certified keep it. The
    bar: rounding of rates up to 149 rad/s^2 at the arm's condition number (under 50 on these
    poses: 26 at most at every pose)."""
    from tests.conftest import MODELS
    from tests.test_rates_many import R1, R2, R3, TH_CD, _poses
    import pinmech

    mechanism = pinmech.Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    solver = pinmech.RateSolver(mechanism, [
        pinmech.Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)),
        pinmech.Task("CD", ("wz",), np.zeros(1), np.zeros(1))], certify=level)
    Q, th1, th2 = _poses(mechanism)
    batch = solver.solve_many(Q)
    ref = closed_form.planar_arm_rates(th1, th2, TH_CD, R1, R2, R3, np.array([1.0, 0.0]), np.zeros(2))
    ia, ib = mechanism.joint("A").idx_v, mechanism.joint("B").idx_v
    got = np.column_stack([batch.v[:, ia], batch.v[:, ia] + batch.v[:, ib], batch.a[:, ia],
                           batch.a[:, ia] + batch.a[:, ib]])
    want = np.column_stack([ref.omega_AB, ref.omega_BC, ref.alpha_AB, ref.alpha_BC])
    from tests.tolerance import rounding

    assert np.abs(got - want).max() < rounding(np.abs(want).max(), 50.0)
    certified = ~np.isnan(batch.condition)
    expected = {"every-pose": 360, "every-10": 36, "every-3": 120, "ends": 1, "none": 0}[level]
    assert certified.sum() == expected and np.all(batch.condition[certified] < 50.0)


def test_a_study_run_every_10_poses_says_so_and_a_workspace_study_refuses_it(tmp_path, capsys):
    """The study's JSON summary, text and CSV comment name the level; a workspace study
    (each grid point solved on its own, certified) refuses a level it cannot honour."""
    from tests.conftest import MODELS

    studies = MODELS / "studies"
    out = tmp_path / "st"
    assert main(["study", str(studies / "four_bar_sensitivity.toml"), "--workers", "0", "--certify", "every-10",
                 "--out", str(out)]) == 0
    assert "each variant's cycle: condition number (and the error bounds it gives) certified at every 10 poses" \
        in capsys.readouterr().out
    assert json.loads((tmp_path / "st.json").read_text())["certified"] == "every 10 poses"
    assert (tmp_path / "st.csv").read_text().startswith("# condition number (and the error bounds it gives) certified at")
    assert main(["study", str(studies / "five_bar_workspace.toml"), "--workers", "0", "--certify", "ends"]) == 2
    assert "workspace study solves each grid point on its own" in capsys.readouterr().err


@pytest.mark.parametrize("level", ["every-10", "none"])
def test_a_single_pose_is_certified_at_every_level(level):
    """`RateSolver.solve` (one pose) and `LoopSolver.solve` give the condition number at
    every level: the dial skips it between the poses of a range only."""
    from tests.conftest import MODELS
    import pinmech

    arm = pinmech.Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    rates = pinmech.RateSolver(arm, [pinmech.Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)),
                                     pinmech.Task("CD", ("wz",), np.zeros(1), np.zeros(1))], certify=level)
    q = arm.neutral()
    q[arm.joint("B").idx_q] = 0.5
    assert 1.0 <= rates.solve(q).condition < 50.0
    solver = LoopSolver(Mechanism.from_urdf(write_r_rtr()), ["A"], certify=level)
    sol = solver.solve([0.5], guess=solver.mechanism.neutral())
    assert sol.accuracy.certified and 1.0 <= sol.accuracy.condition < R_RTR_COND


def test_the_dial_benchmark_runs_and_every_level_meets_the_references(tmp_path, capsys):
    """scripts/benchmark_dial.py at small counts: its exit code is 0 when every level's
    largest error on P1, P2, the chain and the study's variants is within 1e-9 of the closed
    forms, and the five-bar grid's motors within 1e-8 rad of the law-of-cosines elbows."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    import benchmark_dial

    out = tmp_path / "dial.md"
    assert benchmark_dial.main(["--poses", "36", "--rounds", "1", "--samples", "4", "--grid", "7", "9",
                                "--out", str(out)]) == 0
    text = out.read_text()
    assert text.count("| P1 R-RTR") == 6 and text.count("| five-bar workspace grid, 7 x 9 points |") == 2
