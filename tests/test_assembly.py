"""Assembly modes: every pose on the reference's assembly, or a named error.

References are closed forms derived apart from Pinocchio (scripts/closed_form.py for the
four-bar and the offset slider-crank, scripts/closed_form_six_bar.py for a Stephenson III
six-bar), each with its assemblies chosen by an explicit side of a line, and the limit
angle of a non-Grashof four-bar from the law of cosines. Tolerances: positions to the
solver's bound (tests/tolerance.py closure: it closes to 1e-13 of the size and the poses
here are far from singular, condition numbers below 1e2); fold locations 1e-9 rad as the issue asks
(the locator brackets the fold to 1e-12 in its pivot joint, so the driver is right to
rounding).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import closed_form
import numpy as np
import pytest
from closed_form_six_bar import stephenson_d
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import pinmech
from pinmech import AssemblyError, DriverLimitError, LoopSolver, Mechanism, SingularPoseError
from pinmech.cli import main
from pinmech.solve.cycle import solve_range
from tests._mechanisms import four_bar_urdf, spatial_rsur_urdf, stephenson_six_bar_urdf, write
from tests.tolerance import closure, rounding

# The poses here are far from singular: rate Jacobians' condition numbers below 1e2
# (tests/tolerance.py closure: 4 x 1e2 x the solver's 1e-13 of the size).
COND = 1e2

SIX = {"a": 0.04, "b": 0.12, "c": 0.08, "d": 0.10, "cx": 0.06, "cy": 0.04, "b2": 0.10, "c2": 0.09, "o6": (0.16, 0.10)}


# ---------------------------------------------------------------------- helpers
def _four_bar(tmp_path, a, b, c, d) -> Mechanism:
    return Mechanism.from_urdf(write(tmp_path, "fb.urdf", four_bar_urdf(a, b, c, d)))


def _four_bar_guess(mech: Mechanism, theta: float, a, b, c, d, branch: int) -> np.ndarray:
    ref = closed_form.four_bar(theta, 0.0, 0.0, a, b, c, d, branch)
    q = mech.neutral()
    mech.set_coordinate(q, "O2", theta)
    mech.set_coordinate(q, "A", float(ref.theta3) - theta)
    mech.set_coordinate(q, "O4", float(ref.theta4))
    return q


def _pin(mech: Mechanism, solver: LoopSolver, q: np.ndarray, name: str) -> np.ndarray:
    import pinocchio as pin

    pin.framesForwardKinematics(mech.model, solver.data, q)
    return solver.data.oMf[mech.frame_id(name)].translation[:2].copy()


def _rocker_tip(mech, q, c, d) -> np.ndarray:
    """The four-bar's pin B as the end of the rocker: O4 + c e4 [m]."""
    t4 = mech.coordinate(q, "O4")
    return np.array([d + c * math.cos(t4), c * math.sin(t4)])


def _six_bar(tmp_path) -> Mechanism:
    return Mechanism.from_urdf(write(tmp_path, "six.urdf", stephenson_six_bar_urdf(**SIX)))


def _six_guess(mech: Mechanism, theta: float, branch: int, branch2: int) -> np.ndarray:
    p = SIX
    fb = closed_form.four_bar(theta, 0.0, 0.0, p["a"], p["b"], p["c"], p["d"], branch)
    D = stephenson_d(theta, **p, branch=branch, branch2=branch2)
    e3 = np.array([math.cos(fb.theta3), math.sin(fb.theta3)])
    C = fb.A + p["cx"] * e3 + p["cy"] * np.array([-e3[1], e3[0]])
    q = mech.neutral()
    mech.set_coordinate(q, "O2", theta)
    mech.set_coordinate(q, "A", float(fb.theta3) - theta)
    mech.set_coordinate(q, "O4", float(fb.theta4))
    phi5 = math.atan2(D[1] - C[1], D[0] - C[0])
    mech.set_coordinate(q, "C", phi5 - float(fb.theta3))
    mech.set_coordinate(q, "O6", math.atan2(D[1] - p["o6"][1], D[0] - p["o6"][0]))
    return q


def _sweep(solver: LoopSolver, values, **kw):
    chunks = list(solve_range(solver, solver.drivers[0], values, driver_q=np.zeros(1), driver_v=np.ones(1),
                              driver_a=np.zeros(1), **kw))
    q = np.concatenate([c.solution.q for c in chunks])
    errors = {c.start + j: e for c in chunks for j, e in c.errors.items()}
    return q, errors, [n for c in chunks for n in c.notes.values()]


# ---------------------------------------------------------------------- one-off solves
@pytest.mark.parametrize("branch", [+1, -1])
def test_one_off_solves_of_a_four_bar_keep_the_reference_assembly(tmp_path, branch):
    """From a reference at 60 deg, 36 crank angles (every 10 deg, and beyond a turn) land
    on the reference's assembly: the closed form of the same side of A -> O4."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10  # the bundled crank-rocker
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    ref = solver.set_reference([math.radians(60)], _four_bar_guess(mech, math.radians(60), a, b, c, d, branch))
    for k in range(36):
        theta = math.radians(60 + 10 * k + (360 if k % 3 == 0 else 0) - (720 if k % 5 == 0 else 0))
        sol = solver.solve([theta])
        expected = closed_form.four_bar(theta, 0.0, 0.0, a, b, c, d, branch)
        assert sol.assembly.signs == ref.signs
        assert np.allclose(_rocker_tip(mech, sol.q, c, d), expected.B, rtol=0, atol=closure(0.16, COND))
        side = "left" if branch > 0 else "right"
        assert sol.assembly.labels == (f"B {side} of A->O4",)


@pytest.mark.parametrize("branch", [+1, -1])
def test_one_off_solves_of_an_offset_slider_crank_keep_their_side(branch):
    """The bundled slider-crank, piston right (+1) or left (-1) of the crank pin: 36 crank
    angles against the closed form."""
    from pathlib import Path

    mech = Mechanism.from_urdf(Path(__file__).parents[1] / "models" / "slider_crank.urdf")
    r, l, e = 0.05, 0.15, 0.01
    theta0 = math.radians(45)
    ref = closed_form.slider_crank(theta0, 0.0, 0.0, r, l, e, branch)
    q = mech.neutral()
    mech.set_coordinate(q, "O", theta0)
    mech.set_coordinate(q, "A", float(ref.beta) - theta0)
    mech.set_coordinate(q, "slide", float(ref.x_B))
    solver = LoopSolver(mech, ["O"])
    reference = solver.set_reference([theta0], q)
    for k in range(36):
        theta = theta0 + math.radians(10 * k)
        sol = solver.solve([theta])
        assert sol.assembly.signs == reference.signs
        assert abs(mech.coordinate(sol.q, "slide") - float(closed_form.slider_crank(theta, 0, 0, r, l, e, branch).x_B)) \
            < closure(0.2, COND)


@pytest.mark.parametrize("branch,branch2", [(1, 1), (1, -1), (-1, 1), (-1, -1)])
def test_one_off_solves_of_a_stephenson_six_bar_keep_each_of_its_four_assemblies(tmp_path, branch, branch2):
    mech = _six_bar(tmp_path)
    solver = LoopSolver(mech, ["O2"])
    theta0 = math.radians(30)
    ref = solver.set_reference([theta0], _six_guess(mech, theta0, branch, branch2))
    assert len(ref.signs) == 2  # one sign per loop: the blocks B and D
    for k in range(36):
        theta = theta0 + math.radians(10 * k)
        sol = solver.solve([theta])
        assert sol.assembly.signs == ref.signs
        D = _pin(mech, solver, sol.q, "D_pin")
        assert np.allclose(D, stephenson_d(theta, **SIX, branch=branch, branch2=branch2), rtol=0, atol=closure(0.2, COND))


# ---------------------------------------------------------------------- sweeps
@pytest.mark.parametrize("spacing", [1, 10, 30, 45])
def test_six_bar_sweeps_at_any_spacing_match_the_closed_form_and_come_back(tmp_path, spacing):
    """A full turn of the Stephenson six-bar at 1, 10, 30 and 45 degree spacing: every row
    on the reference's assembly (the closed form of its two sides), the last pose on the
    first within 1e-12 of the mechanism size."""
    mech = _six_bar(tmp_path)
    solver = LoopSolver(mech, ["O2"])
    theta0 = math.radians(30)
    solver.set_reference([theta0], _six_guess(mech, theta0, 1, -1))
    values = theta0 + np.radians(np.arange(0, 360 + spacing, spacing))
    q, errors, _ = _sweep(solver, values)
    assert not errors
    D = np.array([_pin(mech, solver, qi, "D_pin") for qi in q])
    assert np.allclose(D, stephenson_d(values, **SIX, branch=1, branch2=-1), rtol=0, atol=closure(0.2, COND))
    assert np.max(np.abs(D[-1] - D[0])) < closure(0.2, COND)


@pytest.mark.parametrize("spacing", [1, 10, 30, 45])
def test_four_bar_sweeps_at_any_spacing_give_the_rows_of_a_fine_sweep(tmp_path, spacing):
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    solver.set_reference([0.0], _four_bar_guess(mech, 0.0, a, b, c, d, -1))
    values = np.radians(np.arange(0, 720 + spacing, spacing))  # two turns
    q, errors, _ = _sweep(solver, values)
    assert not errors
    B = np.array([_rocker_tip(mech, qi, c, d) for qi in q])
    assert np.allclose(B, closed_form.four_bar(values, 0, 0, a, b, c, d, -1).B, rtol=0, atol=closure(0.16, COND))


# ---------------------------------------------------------------------- folds
def _non_grashof(tmp_path):
    """A triple rocker: s + l = 0.04 + 0.09 > p + q = 0.07 + 0.05. Its crank swings
    between +-theta_lim where |A - O4| = b - c, by the law of cosines."""
    a, b, c, d = 0.07, 0.09, 0.05, 0.04
    lim = math.acos((a * a + d * d - (b - c) ** 2) / (2 * a * d))
    return _four_bar(tmp_path, a, b, c, d), (a, b, c, d), lim


@pytest.mark.parametrize("branch", [+1, -1])
def test_a_non_grashof_crank_stops_at_its_limit_angle_located_to_1e9(tmp_path, branch):
    mech, dims, lim = _non_grashof(tmp_path)
    solver = LoopSolver(mech, ["O2"])
    solver.set_reference([math.pi], _four_bar_guess(mech, math.pi, *dims, branch))
    for target, limit in ((math.radians(10), lim), (math.radians(350), 2 * math.pi - lim)):
        with pytest.raises(DriverLimitError) as info:
            solver.solve([target])
        assert abs(info.value.limit[0] - limit) < 1e-9
        assert info.value.exit_code == 11
    near = solver.solve([lim + 1e-6])  # just before the limit: still its own assembly
    expected = closed_form.four_bar(lim + 1e-6, 0, 0, *dims, branch)
    assert np.allclose(_rocker_tip(mech, near.q, dims[2], dims[3]), expected.B, atol=closure(0.11, COND))


def test_a_sweep_past_a_limit_stops_there_or_goes_through_onto_the_other_branch(tmp_path):
    mech, dims, lim = _non_grashof(tmp_path)
    solver = LoopSolver(mech, ["O2"])
    solver.set_reference([math.pi], _four_bar_guess(mech, math.pi, *dims, +1))
    values = np.radians(np.arange(180, -1, -5.0))  # down to 0 deg, past the limit at 28.96 deg
    _q, errors, _ = _sweep(solver, values)
    first_bad = min(errors)
    assert math.degrees(values[first_bad - 1]) > math.degrees(lim) > math.degrees(values[first_bad])
    assert all(isinstance(errors[i], DriverLimitError) for i in errors)
    # through the fold: the crank turns back (values mirrored at the limit), the other side
    solver2 = LoopSolver(mech, ["O2"])
    solver2.set_reference([math.pi], _four_bar_guess(mech, math.pi, *dims, +1))
    chunks = list(solve_range(solver2, "O2", values, driver_q=np.zeros(1), driver_v=np.ones(1),
                              driver_a=np.zeros(1), through_folds=True))
    got = np.concatenate([c.values for c in chunks])
    qs = np.concatenate([c.solution.q for c in chunks])
    past = values < lim
    assert np.allclose(got[past], 2 * lim - values[past], atol=1e-9)
    for theta, qi, mirrored in zip(got, qs, past):
        expected = closed_form.four_bar(theta, 0, 0, *dims, -1 if mirrored else +1)
        assert np.allclose(_rocker_tip(mech, qi, dims[2], dims[3]), expected.B, atol=1e-11 * 0.11)
    assert any("fold" in n for c in chunks for n in c.notes.values())


def test_the_rsur_near_its_rocker_limit_keeps_its_root_or_names_the_other(tmp_path):
    """The spatial RSUR driven from its rocker, 1e-6 rad before the rocker's limit: by
    continuation the pose is on the reference's assembly; a guess 1e-3 rad from the other
    root is either the right root or an AssemblyError, never the other root in silence."""
    mech = Mechanism.from_urdf(write(tmp_path, "rsur.urdf", spatial_rsur_urdf()))
    solver = LoopSolver(mech, ["R4"])
    # a reference pose from the crank-driven solver (R1 = 0), read off at its rocker angle
    crank = LoopSolver(mech, ["R1"])
    q_ref = crank.solve([0.0], guess=mech.neutral()).q
    r4 = mech.coordinate(q_ref, "R4")
    ref = solver.set_reference([r4], q_ref)
    with pytest.raises(DriverLimitError) as info:
        solver.solve([r4 - 3.0])  # the rocker's limit lies below r4 (3.8 deg)
    limit = info.value.limit[0]
    before = limit + 1e-6
    sol = solver.solve([before])
    assert sol.assembly.signs == ref.signs
    assert 1e3 < sol.accuracy.condition < 1e4  # as in the issue: near the limit, under max_condition
    # the other root at the same rocker angle: the path through the fold, mirrored back to it
    other = solver.follow(sol.q, np.array([before]), np.array([limit - 1e-6]),
                          pinmech.Route((0.0,)), through_folds=True)
    assert abs(mech.coordinate(other, "R4") - before) < closure(1.0, sol.accuracy.condition)
    assert pinmech.LoopSolver(mech, ["R4"]).solve([before], guess=other).assembly.signs != ref.signs
    bumped = other.copy()
    bumped[mech.joint("R1").idx_q] += 1e-3
    try:
        again = solver.solve([before], guess=bumped)
    except (AssemblyError, SingularPoseError):
        return
    assert again.assembly.signs == ref.signs


# ---------------------------------------------------------------------- bifurcation
def _parallelogram(tmp_path, a: float, b: float) -> tuple[Mechanism, LoopSolver]:
    """A four-bar with a = c, b = d, its reference the parallelogram at O2 = 60 deg."""
    mech = _four_bar(tmp_path, a, b, a, b)
    solver = LoopSolver(mech, ["O2"])
    q = mech.neutral()
    mech.set_coordinate(q, "O2", math.radians(60))
    mech.set_coordinate(q, "A", -math.radians(60))
    mech.set_coordinate(q, "O4", math.radians(60))
    solver.set_reference([math.radians(60)], q)
    return mech, solver


def test_a_parallelogram_keeps_its_branch_through_the_change_points(tmp_path):
    """a = c, b = d: at 0 and 180 deg the parallelogram and the antiparallelogram meet. A
    sweep through both keeps the coupler parallel to the ground (tangent continuous) and
    says it passed the change points."""
    mech, solver = _parallelogram(tmp_path, 0.05, 0.12)
    values = np.radians(np.arange(60.5, 60.5 + 360, 1.0))
    qs, errors, notes = _sweep(solver, values)
    assert not errors
    for theta, qi in zip(values, qs):
        coupler = math.remainder(mech.coordinate(qi, "O2") + mech.coordinate(qi, "A"), 2 * math.pi)
        assert abs(coupler) < closure(1.0, COND)
        assert abs(math.remainder(mech.coordinate(qi, "O4") - theta, 2 * math.pi)) < closure(1.0, COND)
    assert sum("change point" in n for n in notes) == 2


def test_a_parallelogram_swept_onto_its_change_points_keeps_its_branch_after_each(tmp_path):
    """60 deg apart from 60 deg backwards, poses land exactly on the change points (0, -180,
    -360, -540 deg): those fail by name (singular), and every other row is the
    parallelogram (rocker parallel to the crank) after a note. A failed singular pose used
    to become the sweep's reference, and the next pose, followed from a point where both
    branches meet, came out on the antiparallelogram in silence (from -600 deg on)."""
    mech, solver = _parallelogram(tmp_path, 0.04, 0.10)
    values = np.radians(60 - 60.0 * np.arange(1, 14))
    qs, errors, notes = _sweep(solver, values)
    for i, (theta, qi) in enumerate(zip(values, qs)):
        if i in errors:
            assert isinstance(errors[i], (SingularPoseError, AssemblyError)), errors[i]
            assert abs(math.remainder(theta, math.pi)) < 1e-9  # only at the change points
            continue
        assert abs(math.remainder(mech.coordinate(qi, "O4") - theta, 2 * math.pi)) < closure(1.0, COND), math.degrees(theta)
    assert sum("change point" in n for n in notes) >= 3


# ---------------------------------------------------------------------- hypothesis
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(a=st.floats(0.02, 0.1), b=st.floats(0.05, 0.15), c=st.floats(0.03, 0.12), d=st.floats(0.05, 0.12),
       start=st.floats(0, 2 * math.pi), step=st.floats(3, 50), branch=st.sampled_from([1, -1]))
def test_random_four_bar_sweeps_never_change_assembly_in_silence(tmp_path_factory, a, b, c, d, start, step, branch):
    """Random dimensions (Grashof or not), start angles and spacings: every row is on the
    reference's side (the closed form of that branch) or a named error. Change-point
    linkages (s + l = p + q, within 1e-3 of the size), where branches cross and the closed
    form's side of A -> O4 is not a branch any more, are the parallelogram test's."""
    lengths = sorted((a, b, c, d))
    assume(abs(lengths[0] + lengths[3] - lengths[1] - lengths[2]) > 1e-3 * lengths[3])
    try:
        closed_form.four_bar(start, 0, 0, a, b, c, d, branch)
    except ValueError:
        return  # the start does not close: nothing to follow
    tmp = tmp_path_factory.mktemp("fb")
    mech = _four_bar(tmp, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    try:
        solver.set_reference([start], _four_bar_guess(mech, start, a, b, c, d, branch))
    except (SingularPoseError, pinmech.LoopClosureError):
        return
    values = start + np.radians(np.arange(0, 370, step))
    qs, errors, _ = _sweep(solver, values)
    size = max(a, b, c, d)
    for i, (theta, qi) in enumerate(zip(values, qs)):
        if i in errors:
            assert isinstance(errors[i], (DriverLimitError, SingularPoseError, AssemblyError))
            continue
        expected = closed_form.four_bar(theta, 0, 0, a, b, c, d, branch)
        assert np.allclose(_rocker_tip(mech, qi, c, d), expected.B, rtol=0, atol=1e-9 * size), (i, theta)


# ---------------------------------------------------------------------- API and CLI
def test_a_guess_on_the_other_assembly_is_an_assembly_error_unless_any(tmp_path):
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    solver.set_reference([1.0], _four_bar_guess(mech, 1.0, a, b, c, d, +1))
    other = _four_bar_guess(mech, 2.0, a, b, c, d, -1)
    with pytest.raises(AssemblyError) as info:
        solver.solve([2.0], guess=other)
    assert info.value.exit_code == 10 and info.value.expected != info.value.found
    solver.set_reference([1.0], _four_bar_guess(mech, 1.0, a, b, c, d, +1), assembly="any")
    assert solver.solve([2.0], guess=other).assembly.labels == ("B right of A->O4",)


def test_bundled_four_bar_keeps_its_open_assembly_at_every_angle(models_dir, capsys):
    """The issue's cases: 120 and 150 deg used to fail, 180-240 deg gave the crossed
    assembly. From the scene's 60 deg, every angle is the scene's assembly."""
    import json

    for angle in (120, 150, 180, 200, 240, -100, 420):
        assert main(["solve", str(models_dir / "scenes" / "four_bar.toml"), "--angle", f"{angle} deg", "--json"]) == 0
        out = json.loads(capsys.readouterr().out)
        theta = math.radians(angle)
        expected = closed_form.four_bar(theta, 0, 0, 0.04, 0.12, 0.08, 0.10, +1)
        assert abs(math.remainder(out["joints"]["O4"]["q"] - float(expected.theta4), 2 * math.pi)) < closure(1.0, COND)
        assert out["assembly"]["B"]["label"] == "B left of A->O4"
        assert out["route"]["from"] == {"O2": pytest.approx(math.radians(60), abs=rounding(math.pi))}


def test_a_scene_without_guess_says_which_assembly_and_how_to_pin_it(tmp_path, models_dir, capsys):
    scene = tmp_path / "s.toml"
    body = '[drivers.O2]\nangle = "60 deg"\n'
    scene.write_text(f'urdf = "{models_dir / "four_bar.urdf"}"\n{body}')
    assert main(["solve", str(scene)]) == 0
    out = capsys.readouterr().out
    assert "no [guess]" in out and 'assembly = { "B" = ' in out and "neutral configuration" in out
    assert main(["solve", str(models_dir / "scenes" / "four_bar_drawn.toml")]) == 0  # a drawing is its own guess
    drawn = capsys.readouterr().out
    assert "the one the model is drawn in" in drawn and "neutral" not in drawn
    wrong = "+" if '"B" = "-"' in out else "-"
    top = f'urdf = "{models_dir / "four_bar.urdf"}"\n'
    scene.write_text(top + f'assembly = {{ B = "{wrong}" }}\n' + body)
    assert main(["solve", str(scene)]) == 10
    assert "change [guess]" in capsys.readouterr().err
    scene.write_text(top + 'assembly = { Q = "+" }\n' + body)
    assert main(["solve", str(scene)]) == 4
    scene.write_text(top + 'assembly = "any"\n' + body)
    assert main(["solve", str(scene)]) == 0


def test_cli_sweep_says_it_came_back_after_a_turn(models_dir, capsys):
    assert main(["sweep", str(models_dir / "scenes" / "four_bar.toml"), "--steps", "9"]) == 0
    assert "back where it began" in capsys.readouterr().err


def test_a_slider_crank_driven_at_its_piston_stops_at_the_end_of_its_stroke(models_dir):
    """Driven from the piston, the offset slider-crank's outer dead centre is a fold: the
    stroke ends at x = sqrt((r + l)^2 - e^2), located to 1e-9 of the size."""
    mech = Mechanism.from_urdf(models_dir / "slider_crank.urdf")
    r, l, e = 0.05, 0.15, 0.01
    theta = math.radians(100)
    ref = closed_form.slider_crank(theta, 0, 0, r, l, e, +1)
    q = mech.neutral()
    mech.set_coordinate(q, "O", theta)
    mech.set_coordinate(q, "A", float(ref.beta) - theta)
    mech.set_coordinate(q, "slide", float(ref.x_B))
    solver = LoopSolver(mech, ["slide"])
    solver.set_reference([float(ref.x_B)], q)
    with pytest.raises(DriverLimitError) as info:
        solver.solve([0.25])
    assert abs(info.value.limit[0] - math.sqrt((r + l) ** 2 - e**2)) < 1e-9 * 0.2
    assert "slide = 0.1997" in str(info.value)


def test_sweep_json_lines_say_where_a_fold_was_crossed(tmp_path, models_dir, capsys):
    import json

    text = four_bar_urdf(0.07, 0.09, 0.05, 0.04)  # the triple rocker of the fold tests
    urdf = write(tmp_path, "ng.urdf", text)
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{urdf}"\n[drivers.O2]\nangle = "180 deg"\nspeed = "1 rad/s"\n'
                     '[guess]\nA = "-150 deg"\nO4 = "100 deg"\n')
    out = tmp_path / "rows.jsonl"
    assert main(["sweep", str(scene), "--from", "180 deg", "--to", "0 deg", "--steps", "19",
                 "--through-folds", "--json", str(out)]) == 0
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert sum("fold" in r.get("note", "") for r in rows) == 1
    assert "crossed a fold at O2 = 28.955" in capsys.readouterr().err
    # without --through-folds the crank's range of motion ends at the fold: the sweep ends
    # there, says so, and summarises (a rocker's toggle is its normal range, not an error)
    assert main(["sweep", str(scene), "--from", "180 deg", "--to", "0 deg", "--steps", "19"]) == 0
    assert "O2 cannot go past 28.955" in capsys.readouterr().err


def test_a_solver_without_reference_takes_its_first_pose_as_one(tmp_path):
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    first = solver.solve([1.0], guess=_four_bar_guess(mech, 1.0, a, b, c, d, -1))
    assert solver.reference is not None and solver.reference.signs == first.assembly.signs
    later = solver.solve([4.0])  # by continuation from the first pose
    assert np.allclose(_rocker_tip(mech, later.q, c, d), closed_form.four_bar(4.0, 0, 0, a, b, c, d, -1).B,
                       atol=closure(0.16, COND))
    with pytest.raises(AssemblyError):
        solver.solve([4.0], guess=_four_bar_guess(mech, 4.0, a, b, c, d, +1))


def test_the_batch_mode_hands_back_poses_of_another_assembly(tmp_path):
    """BatchSolver from guesses on the other side: None (the pose-by-pose solver then
    names the pose), never those poses."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    solver.set_reference([1.0], _four_bar_guess(mech, 1.0, a, b, c, d, +1))
    thetas = np.linspace(1.0, 1.1, 5)
    batch = pinmech.BatchSolver(solver)
    same = np.array([_four_bar_guess(mech, t, a, b, c, d, +1) for t in thetas])
    other = np.array([_four_bar_guess(mech, t, a, b, c, d, -1) for t in thetas])
    zeros = np.zeros((5, 1))
    assert batch.try_solve(same, thetas[:, None], zeros, zeros) is not None
    assert batch.try_solve(other, thetas[:, None], zeros, zeros) is None


def test_a_driver_value_with_its_unit_is_a_named_error_in_the_api(models_dir):
    """Issue 11 item 19: a string driver value is a UnitError naming SI and to_si, not numpy's ValueError."""
    solver = LoopSolver(Mechanism.from_urdf(models_dir / "r_rtr.urdf"), ["A"])
    with pytest.raises(pinmech.UnitError, match="to_si"):
        solver.solve(["30 deg"])


# ---------------------------------------------------------------------- near change points, folds at any size
@pytest.mark.parametrize("eps", [1e-4, 1e-6, 1e-8, 1e-10])
@pytest.mark.parametrize("step", [30.0, -45.0, 90.0])
@pytest.mark.parametrize("branch", [+1, -1])
def test_four_bars_a_hair_from_a_parallelogram_keep_their_branch_or_say_so(tmp_path, eps, step, branch):
    """Crank 40, coupler 100, ground 100 mm, rocker 40 (1 + eps) mm: Grashof, so each
    branch is regular all the way round and its closed form holds, but near O2 = 180 deg
    the two branches pass within about eps of the size of each other. Swept over two
    turns at coarse spacing, every row is on the reference's branch (1e-9 of the size),
    or a named error: the pivot-parametrized continuation used to cross onto the other
    branch there in silence (53 mm off at eps = 1e-8)."""
    a, b, c, d = 0.04, 0.10, 0.04 * (1 + eps), 0.10
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    start = math.radians(60.0)
    solver.set_reference([start], _four_bar_guess(mech, start, a, b, c, d, branch))
    values = start + np.radians(step * np.arange(1, int(720 / abs(step)) + 1))
    qs, errors, _ = _sweep(solver, values)
    for i, (theta, qi) in enumerate(zip(values, qs)):
        if i in errors:
            assert isinstance(errors[i], (AssemblyError, SingularPoseError)), errors[i]
            continue
        expected = closed_form.four_bar(theta, 0, 0, a, b, c, d, branch)
        assert np.allclose(_rocker_tip(mech, qi, c, d), expected.B, rtol=0, atol=1e-9 * d), (i, math.degrees(theta))


TRAMMEL = """title = "elliptic trammel"
ground = ["O"]
[joints]
O = ["0 mm", "0 mm"]
P1 = ["{x0} mm", "0 mm"]
P2 = ["0 mm", "{y0} mm"]
Q1 = ["{x0} mm", "0 mm"]
[links]
b1 = ["P1", "Q1"]
b2 = ["P2"]
bar = ["P1", "P2"]
[sliders]
S1 = {{ block = "b1", on = "ground", at = "P1", along = "0 deg" }}
S2 = {{ block = "b2", on = "ground", at = "P2", along = "90 deg" }}
"""


@pytest.mark.parametrize("size", [1e-4, 0.1, 100.0])
def test_a_trammel_reaches_its_fold_at_any_size(tmp_path, size):
    """An elliptic trammel (bar L between a block on x, drawn at x0 = 0.3 L, and one on y),
    driven by the x block: the fold is at x = L, S1 = 0.7 L. Just before it the y block
    is at sqrt(L^2 - x^2) (1e-9 of L: the pose is 0.1% of L from the fold, condition ~1e2);
    past it the drivers stop there, named (DriverLimitError, located to 1e-9 of L). The
    continuation's turn check read prismatic joints' tangents in metres, so below about
    1 m every step was refused and reachable poses were AssemblyErrors."""
    L = size
    x0 = 0.3 * L
    path = tmp_path / "trammel.toml"
    path.write_text(TRAMMEL.format(x0=repr(x0 * 1e3), y0=repr(math.sqrt(L * L - x0 * x0) * 1e3)))
    mech = pinmech.load_linkage(path)
    solver = LoopSolver(mech, ["S1"])
    solver.set_reference([0.0], mech.reference)
    x = 0.999 * L
    sol = solver.solve([x - x0])
    y0 = math.sqrt(L * L - x0 * x0)
    assert y0 + mech.coordinate(sol.q, "S2") == pytest.approx(math.sqrt(L * L - x * x), abs=1e-9 * L)
    with pytest.raises(DriverLimitError) as err:
        solver.solve([0.75 * L])
    assert err.value.limit[0] == pytest.approx(0.7 * L, abs=1e-9 * L)


def test_the_return_message_speaks_only_of_whole_turns_it_saw(tmp_path, capsys):
    """'after 1 turn(s) the mechanism is NOT back where it began' was said of a non-Grashof
    crank whose rows past its limit failed (--skip-failures: the last solved row is not the
    turn's end), of a sweep through folds (the driver never turns) and of a Grashof four-bar
    closed to a loose tol (its gap is that tol). Now: nothing, nothing, and back."""
    from pinmech.cli import main

    a, b, c, d = 0.08, 0.05, 0.06, 0.10  # non-Grashof: the crank is limited to +-74.41 deg
    write(tmp_path, "ng.urdf", four_bar_urdf(a, b, c, d))
    scene = tmp_path / "ng.toml"
    ref = closed_form.four_bar(0.0, 0, 0, a, b, c, d, 1)
    scene.write_text(f'urdf = "ng.urdf"\n[drivers.O2]\nangle = "0 deg"\n[guess]\n'
                     f'A = "{math.degrees(float(ref.theta3)):.6f} deg"\nO4 = "{math.degrees(float(ref.theta4)):.6f} deg"\n')
    for extra in (["--skip-failures"], ["--through-folds"]):
        assert main(["sweep", str(scene), "--from", "0 deg", "--to", "360 deg", "--steps", "9", "--csv",
                     str(tmp_path / "s.csv"), *extra]) == 0
        assert "back where it began" not in capsys.readouterr().err, extra
    write(tmp_path, "g.urdf", four_bar_urdf(0.04, 0.12, 0.08, 0.10))
    scene.write_text('urdf = "g.urdf"\n[drivers.O2]\nangle = "60 deg"\n[solver]\ntol = 1e-3\n')
    assert main(["sweep", str(scene), "--steps", "9", "--csv", str(tmp_path / "s.csv")]) == 0
    assert "the mechanism is back where it began" in capsys.readouterr().err


# ---------------------------------------------------------------------- a block of two loops: four assemblies
#: The bundled Stephenson six-bar (models/linkages/stephenson.toml) in the closed form's
#: terms: four-bar O2-A-B-O4, coupler point C (AC = BC = 70 mm, left of A->B), dyad C-D-O6.
FAR = {"a": 0.04, "b": 0.12, "c": 0.08, "d": 0.10, "cx": 0.06, "cy": math.sqrt(0.07**2 - 0.06**2),
       "b2": 0.08, "c2": 0.06, "o6": (0.16, 0.11)}
_PIVOTS = {"O2": np.zeros(2), "O4": np.array([0.10, 0.0]), "O6": np.array([0.16, 0.11])}
#: Each joint's link, as the direction between two pins, and the joint it hangs from.
_LINK_OF = {"O2": ("O2", "A", None), "A": ("A", "B", "O2"), "O4": ("O4", "B", None), "O6": ("O6", "D", None),
            "D": ("D", "C", "O6")}


def _far_pins(mech: Mechanism, q: np.ndarray) -> dict[str, np.ndarray]:
    import pinocchio as pin

    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    frame = {"A": "A", "B": "B__parent", "C": "C__parent", "D": "D"}
    return {k: data.oMf[mech.model.getFrameId(f)].translation[:2].copy() for k, f in frame.items()} | _PIVOTS


def _far_q(mech: Mechanism, pins: dict[str, np.ndarray]) -> np.ndarray:
    """The joint coordinates of a pose given by its pins: each joint turns its link by the
    change of the link's direction since the drawing, less its parent link's."""
    q0 = mech.neutral()
    drawn, pins = _far_pins(mech, q0), pins | _PIVOTS

    def turned(joint):
        tail, head, _ = _LINK_OF[joint]
        now, then = pins[head] - pins[tail], drawn[head] - drawn[tail]
        return math.atan2(now[1], now[0]) - math.atan2(then[1], then[0])

    q = q0.copy()
    for joint, (_, _, parent) in _LINK_OF.items():
        mech.set_coordinate(q, joint, mech.coordinate(q0, joint) + turned(joint) - (turned(parent) if parent else 0.0))
    return q


@functools.lru_cache(maxsize=1)
def _far_track(phi0: float) -> dict[int, dict]:
    """The closed form's root reached from the drawn pose (four-bar branch +1, crank at 0)
    at the drawn far-crank angle phi0, moving the far crank up in steps to each whole
    degree up to 245: at each step the root of the same four-bar branch nearest the last
    crank angle (the roots at one angle are at least 0.1 rad apart here)."""
    from closed_form_six_bar import stephenson_far_crank

    theta, out = 0.0, {}
    for degrees in range(math.ceil(math.degrees(phi0)), 246):
        roots = [r for r in stephenson_far_crank(math.radians(degrees), **FAR, samples=2000) if r["branch"] == 1]
        out[degrees] = min(roots, key=lambda r: abs(math.remainder(r["theta2"] - theta, 2 * math.pi)))
        theta = out[degrees]["theta2"]
    return out


def _continued_far_assembly(phi0: float, degrees: float) -> dict:
    """The pins of the continued root at a whole number of degrees of the far crank."""
    return _far_track(phi0)[round(degrees)]


def test_a_guess_on_another_assembly_of_a_two_loop_block_is_refused_though_its_sign_is_the_same():
    """Issue 22 item 11: the Stephenson six-bar driven at its far crank O6 has one block of
    two loops (B+C) and, at O6 = 240 deg, four assemblies (the closed form: the coupler curve
    of C meets the circle about D four times). From the drawn pose, continuation reaches one
    of them; a guess on each of the four is accepted on that one only (AssemblyError on the
    three others, two of which share its determinant's sign). Positions to the solver's
    bound on the 0.2 m size: closed to 1e-13, condition numbers below 1e2 at these poses."""
    from closed_form_six_bar import stephenson_far_crank

    mech = pinmech.load_linkage(Path(__file__).parents[1] / "models" / "linkages" / "stephenson.toml")
    solver = LoopSolver(mech, ["O6"])
    q0 = mech.neutral()
    phi0, phi = mech.coordinate(q0, "O6"), math.radians(240)
    ref = solver.set_reference([phi0], q0)
    assert solver.structure.names == ("B+C",)
    drawn = min((r for r in stephenson_far_crank(phi0, **FAR) if r["branch"] == 1), key=lambda r: abs(r["theta2"]))
    np.testing.assert_allclose(drawn["C"], _far_pins(mech, ref.q)["C"], rtol=0, atol=closure(0.2, COND))
    expected = _continued_far_assembly(phi0, 240)
    continued = solver.solve([phi])
    for pin_name in "ABCD":
        np.testing.assert_allclose(_far_pins(mech, continued.q)[pin_name], expected[pin_name], rtol=0, atol=closure(0.2, COND))
    assemblies = stephenson_far_crank(phi, **FAR)
    assert len(assemblies) == 4
    same_sign = 0
    for other in assemblies:
        guess = _far_q(mech, other)
        np.testing.assert_allclose(_far_pins(mech, guess)["C"], other["C"], rtol=0, atol=rounding(0.2))
        is_it = np.allclose(other["C"], expected["C"], rtol=0, atol=1e-9)
        sign = LoopSolver(mech, ["O6"]).solve([phi], guess=guess).assembly.signs
        same_sign += sign == continued.assembly.signs and not is_it
        if is_it:
            sol = solver.solve([phi], guess=guess)
            np.testing.assert_allclose(_far_pins(mech, sol.q)["C"], expected["C"], rtol=0, atol=closure(0.2, COND))
        else:
            with pytest.raises(AssemblyError, match="O6 = (240|-120) deg"):
                solver.solve([phi], guess=guess)
    assert same_sign >= 1  # the case the sign alone let through


@pytest.mark.parametrize("start", ["cold", "warm"])
def test_a_cold_or_warm_sweep_of_a_two_loop_block_never_lands_on_another_assembly_of_its_sign(start):
    """The same six-bar swept at 236..244 deg from the guess of an assembly that has the
    continued one's sign but is another (closed form, as above): each row is the closed
    form's continued assembly (to 1e-12 of the size) or an AssemblyError, never the other."""
    from closed_form_six_bar import stephenson_far_crank

    mech = pinmech.load_linkage(Path(__file__).parents[1] / "models" / "linkages" / "stephenson.toml")
    solver = LoopSolver(mech, ["O6"])
    q0 = mech.neutral()
    phi0, phi = mech.coordinate(q0, "O6"), math.radians(240)
    solver.set_reference([phi0], q0)
    signs = solver.solve([phi]).assembly.signs
    expected = _continued_far_assembly(phi0, 240)
    others = [r for r in stephenson_far_crank(phi, **FAR) if not np.allclose(r["C"], expected["C"], atol=1e-9)]
    twin = next(r for r in others if LoopSolver(mech, ["O6"]).solve([phi], guess=_far_q(mech, r)).assembly.signs
                == signs)
    values = np.radians([240.0, 242.0, 244.0])
    chunks = list(solve_range(solver, "O6", values, driver_q=np.zeros(1), driver_v=np.ones(1), driver_a=np.zeros(1),
                              guess=_far_q(mech, twin), start=start))
    q = np.concatenate([c.solution.q for c in chunks])
    errors = {c.start + j: e for c in chunks for j, e in c.errors.items()}
    for i, value in enumerate(values):
        if i in errors:
            assert isinstance(errors[i], AssemblyError)
            continue
        right = _continued_far_assembly(phi0, math.degrees(value))
        np.testing.assert_allclose(_far_pins(mech, q[i])["C"], right["C"], rtol=0, atol=closure(0.2, COND))


def test_the_batch_solver_never_takes_a_guess_on_another_assembly_of_a_two_loop_block():
    """BatchSolver.try_solve from the guess of the same-sign twin assembly (closed form, as
    above): None (the pose-by-pose solver decides), never that pose; a four-bar's dyad,
    whose sign names both of its assemblies, is still batched."""
    from closed_form_six_bar import stephenson_far_crank

    mech = pinmech.load_linkage(Path(__file__).parents[1] / "models" / "linkages" / "stephenson.toml")
    solver = LoopSolver(mech, ["O6"])
    q0 = mech.neutral()
    phi0, phi = mech.coordinate(q0, "O6"), math.radians(240)
    solver.set_reference([phi0], q0)
    signs = solver.solve([phi]).assembly.signs
    expected = _continued_far_assembly(phi0, 240)
    twin = next(r for r in stephenson_far_crank(phi, **FAR) if not np.allclose(r["C"], expected["C"], atol=1e-9)
                and LoopSolver(mech, ["O6"]).solve([phi], guess=_far_q(mech, r)).assembly.signs == signs)
    zeros = np.zeros((1, 1))
    assert pinmech.BatchSolver(solver).try_solve(_far_q(mech, twin)[None], np.array([[phi]]), zeros, zeros) is None
