"""The task-space rate solver: J q_dot = x_dot and J q_ddot = x_ddot - Jdot q_dot.

Text 17.110's arm against its closed form; minimum-norm and damped answers against numpy's
pseudo-inverse on the same Jacobian; singular poses, over-determined and inconsistent
tasks; a task on the closed R-RTR loop against the R-RTR's closed form.
"""

from __future__ import annotations

import closed_form
import numpy as np
import pinocchio as pin
import pytest

from pinmech import (
    FrameNotFound,
    LoopClosureError,
    LoopSolver,
    Mechanism,
    ModelError,
    OptionError,
    RateSolver,
    SingularPoseError,
    Task,
    TaskError,
)
from pinmech.solve.rates import DAMPING_RANGE
from tests._mechanisms import cut_rows
from tests.conftest import MODELS
from tests.tolerance import closure, residual, rounding

DEG = np.pi / 180
R_ARM = (0.3, 0.3, 0.17)
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@pytest.fixture(scope="module")
def arm():
    return Mechanism.from_urdf(MODELS / "planar_arm.urdf")


def arm_tasks(vD=(1.0, 0.0), aD=(0.0, 0.0)) -> list[Task]:
    """Text 17.110: D moves at vD with classical acceleration aD, CD does not turn."""
    return [Task("D", ("x", "y"), np.array(vD), np.array(aD)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]


def arm_q(arm, angles_deg) -> np.ndarray:
    q = arm.neutral()
    for name, angle in zip("ABC", angles_deg):
        arm.set_coordinate(q, name, angle * DEG)
    return q


def frame_jacobian(mech, q, frame) -> np.ndarray:
    data = mech.model.createData()
    pin.computeJointJacobians(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    return pin.getFrameJacobian(mech.model, data, mech.frame_id(frame), _LWA)


# --------------------------------------------------------------------- text 17.110
def test_text_17_110_against_cramers_rule(arm):
    """The text's two equations solved by Cramer's rule without Pinocchio, 1e-10 relative."""
    sol = RateSolver(arm, arm_tasks()).solve(arm_q(arm, (50, -65, -75)))
    cf = closed_form.planar_arm_rates(50 * DEG, -15 * DEG, -90 * DEG, *R_ARM, np.array([1.0, 0.0]), np.zeros(2))
    assert sol.method == "exact" and sol.nullspace_dim == 0 and sol.rank == 3
    np.testing.assert_allclose(sol.v, cf.q_dot, rtol=1e-10)
    np.testing.assert_allclose(sol.a, cf.q_ddot, rtol=1e-10)
    assert sol.is_exact(rounding(1.0, sol.condition))


def test_any_motion_of_D_against_cramers_rule(arm):
    """Another pose and a non-zero acceleration of D, to 1e-10."""
    sol = RateSolver(arm, arm_tasks((0.3, -0.2), (1.0, 2.0))).solve(arm_q(arm, (20, 40, -150)))
    cf = closed_form.planar_arm_rates(20 * DEG, 60 * DEG, -90 * DEG, *R_ARM, np.array([0.3, -0.2]),
                                      np.array([1.0, 2.0]))
    np.testing.assert_allclose(sol.v, cf.q_dot, rtol=1e-10)
    np.testing.assert_allclose(sol.a, cf.q_ddot, rtol=1e-10)


def test_task_values_can_change_per_call(arm):
    """One solver, new asked values: the same answer as a solver built for them."""
    q = arm_q(arm, (50, -65, -75))
    solver = RateSolver(arm, arm_tasks())
    sol = solver.solve(q, velocity=[0.3, -0.2, 0.0], acceleration=[1.0, 2.0, 0.0])
    ref = RateSolver(arm, arm_tasks((0.3, -0.2), (1.0, 2.0))).solve(q)
    np.testing.assert_allclose(sol.v, ref.v, rtol=rounding(1.0, sol.condition))
    np.testing.assert_allclose(sol.a, ref.a, rtol=rounding(1.0, sol.condition))
    with pytest.raises(TaskError, match=r"velocity needs 3 finite values \(rows D.x, D.y, CD.wz\)"):
        solver.solve(q, velocity=[1.0, 0.0])


def test_local_rows_are_the_world_rows_turned_into_the_frame(arm):
    """CD points straight down: its local x is world -y, local y is world x."""
    q = arm_q(arm, (50, -65, -75))
    world = RateSolver(arm, arm_tasks((0.4, -0.7), (1.5, 0.5))).solve(q)
    local = RateSolver(arm, [Task("D", ("x", "y"), np.array([0.7, 0.4]), np.array([-0.5, 1.5]), "local"),
                             Task("CD", ("wz",), np.zeros(1), np.zeros(1))]).solve(q)
    np.testing.assert_allclose(local.v, world.v, rtol=rounding(1.0, world.condition))
    np.testing.assert_allclose(local.a, world.a, rtol=rounding(1.0, world.condition))


# --------------------------------------------------------------------- redundant and damped
def test_redundant_task_is_numpys_minimum_norm(arm):
    """D's velocity only: 2 rows, 3 joints; the answer is pinv(J) x_dot, null space 1,
    and the accelerations are pinv(J) (x_ddot - Jdot q_dot)."""
    q = arm_q(arm, (50, -65, -75))
    solver = RateSolver(arm, [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.array([0.5, -1.0]))])
    sol = solver.solve(q)
    J = frame_jacobian(arm, q, "D")[:2]
    assert sol.method == "minimum_norm" and sol.nullspace_dim == 1 and sol.rank == 2
    np.testing.assert_allclose(sol.v, np.linalg.pinv(J) @ [1.0, 0.0], rtol=rounding(1.0, sol.condition))
    jdot_v = sol.achieved_acceleration - J @ sol.a  # the drift the solver used
    np.testing.assert_allclose(sol.a, np.linalg.pinv(J) @ ([0.5, -1.0] - jdot_v), rtol=rounding(1.0, sol.condition))
    assert sol.is_exact(rounding(1.0, sol.condition))


def test_damped_least_squares_is_the_regularised_pseudo_inverse(arm):
    """(J^T J + lambda^2 I)^-1 J^T x_dot, on the Jacobian numpy gets from Pinocchio, its
    linear rows divided by the arm's size (lambda is dimensionless: the same at any size)."""
    q = arm_q(arm, (50, -65, -75))
    lam = 0.05
    sol = RateSolver(arm, arm_tasks(), method="damped", damping=lam).solve(q)
    J = np.vstack([frame_jacobian(arm, q, "D")[:2], frame_jacobian(arm, q, "CD")[5:]])
    rows = np.array([1 / arm.length_scale, 1 / arm.length_scale, 1.0])[:, None]
    expected = np.linalg.solve((rows * J).T @ (rows * J) + lam**2 * np.eye(3), (rows * J).T @ (rows[:, 0] * [1.0, 0, 0]))
    np.testing.assert_allclose(sol.v, expected, rtol=rounding(1.0, sol.condition**2))
    assert sol.method == "damped" and not sol.is_exact()
    np.testing.assert_allclose(sol.achieved_velocity, J @ sol.v, rtol=0, atol=rounding(np.abs(J) @ np.abs(sol.v)))  # what it reports achieving
    assert sol.velocity_error == pytest.approx(np.max(np.abs(J @ sol.v - [1.0, 0.0, 0.0])))


# --------------------------------------------------------------------- singular poses
@pytest.mark.parametrize("bend", [0.0, 180.0])
def test_stretched_or_folded_arm_is_singular(arm, bend):
    """B = 0 (stretched) or 180 deg (folded back): D cannot move along the arm's line."""
    with pytest.raises(SingularPoseError, match=r"task Jacobian is singular at A = 28\.64788976 deg, B = .* deg") as info:
        RateSolver(arm, arm_tasks()).solve(arm_q(arm, (0.5 / DEG, bend, -30)))
    assert info.value.sigma_min < 1e-9 and info.value.condition > 1e4
    np.testing.assert_allclose(info.value.partial, arm_q(arm, (0.5 / DEG, bend, -30)))


def test_damped_solution_at_the_singular_pose_reports_its_error(arm):
    """Stretched along x, D can move along x only by turning CD, which the task forbids:
    the damped answer is finite and the report shows it misses most of the 1 m/s asked."""
    sol = RateSolver(arm, arm_tasks(), method="damped", damping=1e-2).solve(arm_q(arm, (0, 0, -90)))
    assert np.all(np.isfinite(sol.v)) and np.all(np.isfinite(sol.a)) and not sol.is_exact()
    assert sol.velocity_error > 0.5
    np.testing.assert_allclose(sol.requested_velocity, [1.0, 0.0, 0.0])


# --------------------------------------------------------------------- tasks that cannot hold
def test_over_determined_task_is_an_error_or_least_squares(arm):
    q = arm_q(arm, (50, -65, -75))
    tasks = [Task("D", ("x", "y", "wz"), np.array([1.0, 0.0, 0.0]), np.zeros(3)),
             Task("C", ("x",), np.array([2.0]), np.zeros(1))]
    with pytest.raises(TaskError, match="4 equations .* for 3 joint freedoms: over-determined"):
        RateSolver(arm, tasks).solve(q)
    sol = RateSolver(arm, tasks, method="least_squares").solve(q)
    J = np.vstack([frame_jacobian(arm, q, "D")[[0, 1, 5]], frame_jacobian(arm, q, "C")[:1]])
    w = np.array([1, 1, arm.length_scale, 1]) / arm.length_scale  # residuals weighed dimensionless
    np.testing.assert_allclose(sol.v, np.linalg.lstsq(w[:, None] * J, w * [1.0, 0.0, 0.0, 2.0], rcond=None)[0],
                               rtol=rounding(1.0, sol.condition**2))
    assert sol.method == "least_squares" and sol.rank == 3 and sol.nullspace_dim == 0
    # what the report shows; atol: a row that cancels to zero keeps rounding of its terms
    # (about 1, eps each), summed in another order by the core than by numpy
    np.testing.assert_allclose(sol.achieved_velocity, J @ sol.v, rtol=0, atol=rounding(np.abs(J) @ np.abs(sol.v)))
    assert sol.velocity_error == pytest.approx(np.max(np.abs(J @ sol.v - [1.0, 0.0, 0.0, 2.0])))
    assert sol.velocity_error > 0.1  # v_D - v_C = omega_CD x CD: 1 m/s apart needs CD to turn, wz = 0 forbids it


def test_a_motion_no_joint_gives_is_an_inconsistent_task(arm):
    """The planar arm cannot move D along z: a TaskError naming the row, not a singular pose."""
    tasks = [Task("D", ("x", "y", "z"), np.array([1.0, 0.0, 0.1]), np.zeros(3))]
    with pytest.raises(TaskError, match=r"no joint of the model gives D\.z at any pose"):
        RateSolver(arm, tasks).solve(arm_q(arm, (50, -65, -75)))
    sol = RateSolver(arm, tasks, method="least_squares").solve(arm_q(arm, (50, -65, -75)))
    assert sol.method == "least_squares" and sol.rank == 2 and sol.nullspace_dim == 1
    np.testing.assert_allclose(sol.achieved_velocity, [1.0, 0.0, 0.0], atol=rounding(1.0, sol.condition))
    assert sol.velocity_error == pytest.approx(0.1)  # the z asked, reported as missed


def test_a_row_prescribed_twice_is_an_inconsistent_task(arm):
    """D is fixed on CD: D's wz and CD's wz are one row. Asking them different is impossible."""
    tasks = [Task("D", ("x", "wz"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.ones(1), np.zeros(1))]
    with pytest.raises(TaskError, match=r"CD\.wz repeats a combination of the rows before at every pose"):
        RateSolver(arm, tasks).solve(arm_q(arm, (50, -65, -75)))
    sol = RateSolver(arm, tasks, method="least_squares").solve(arm_q(arm, (50, -65, -75)))
    np.testing.assert_allclose(sol.achieved_velocity, [1.0, 0.5, 0.5], rtol=rounding(1.0, sol.condition))  # halfway


def test_the_rank_check_does_not_mistake_a_singular_pose_for_the_task(arm):
    """At the stretched pose the rank drops, but not at other poses: a SingularPoseError."""
    solver = RateSolver(arm, arm_tasks())
    with pytest.raises(SingularPoseError):
        solver.solve(arm_q(arm, (0, 0, -90)))
    assert solver.solve(arm_q(arm, (50, -65, -75))).method == "exact"  # same solver, fine pose


# --------------------------------------------------------------------- closed loops
def test_task_on_the_r_rtr_loop_against_its_closed_form(models_dir):
    """No driver speed: D must move at 1 m/s along x with no x acceleration. The closed form
    is linear in the crank's rates, v_D = omega1 dD/dphi, a_D = a_D(omega1, 0) + alpha1 dD/dphi,
    so omega1 = 1 / (dD/dphi)_x and alpha1 = -a_D,x(omega1, 0) / (dD/dphi)_x."""
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", 20 * DEG)
    mech.set_coordinate(guess, "B_slider", -0.06)
    q, _, _ = LoopSolver(mech, ["A"]).close(guess, [30 * DEG])
    sol = RateSolver(mech, [Task("D", ("x",), np.array([1.0]), np.array([0.0]))]).solve(q)

    dD = closed_form.r_rtr(30 * DEG, 1.0, 0.0).vD[0]
    omega1 = 1.0 / dD
    alpha1 = -closed_form.r_rtr(30 * DEG, omega1, 0.0).aD[0] / dD
    A = mech.joint("A").idx_v
    np.testing.assert_allclose([sol.v[A], sol.a[A]], [omega1, alpha1], rtol=1e-10)
    assert sol.method == "exact" and sol.rank == mech.model.nv
    assert sol.closure_velocity_residual < rounding(np.abs(sol.v).max()) and sol.closure_acceleration_residual < rounding(np.abs(sol.a).max() + np.abs(sol.v).max() ** 2)


# --------------------------------------------------------------------- open loops
def four_bar_open() -> tuple[Mechanism, np.ndarray, np.ndarray]:
    """The four-bar, its loop closed at O2 = 0.7 rad, and a q with the same joint angles as
    the probe's (O2 0.7, A 0.4, O4 1.9 rad) whose cut is 58.0 mm apart: 0.32 of the loop's
    0.18 m (the distance checked against Pinocchio's placements of the two cut frames)."""
    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    open_q = mech.neutral()
    for name, x in (("O2", 0.7), ("A", 0.4), ("O4", 1.9)):
        mech.set_coordinate(open_q, name, x)
    closed_q, _, _ = LoopSolver(mech, ["O2"]).close(mech.neutral(), [0.7])
    return mech, closed_q, open_q


def cut_gap(mech, q) -> float:
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    c = mech.closures[0]
    return float(np.linalg.norm(data.oMf[c.child_frame].translation - data.oMf[c.parent_frame].translation))


def test_rates_at_an_open_loop_are_a_named_error_saying_how_far_open():
    """Before: method 'exact' and rates of another mechanism, with no residual stated."""
    mech, _, open_q = four_bar_open()
    assert cut_gap(mech, open_q) == pytest.approx(0.0580, abs=5e-5)
    with pytest.raises(LoopClosureError, match=r"O2 = 40.1\d* deg.*loop B's cut frames are 0.058 m apart "
                                               r"\(0.322 of its size, 0.18 m\).*tolerance 1e-13") as info:
        RateSolver(mech, [Task("P", ("x",), np.array([0.1]), np.zeros(1))]).solve(open_q)
    assert info.value.residual == pytest.approx(0.31, abs=5e-3) and "\n" not in str(info.value)


def test_solve_many_refuses_an_open_pose_among_closed_ones():
    """The compiled core measures no position residual: the poses it solved are checked in
    numpy, and an open one is named by `solve`, as one by one."""
    mech, closed_q, open_q = four_bar_open()
    solver = RateSolver(mech, [Task("P", ("x",), np.array([0.1]), np.zeros(1))])
    batch = solver.solve_many(np.array([closed_q, closed_q]))
    np.testing.assert_array_equal(batch.closure_residual, [solver.solve(closed_q).closure_residual] * 2)
    assert np.all(batch.closure_residual <= residual(1.0))
    with pytest.raises(LoopClosureError, match="0.058 m apart"):
        solver.solve_many(np.array([closed_q, open_q, closed_q]))


def test_a_loop_closed_within_a_looser_tol_states_its_residual():
    """A q closed to 1e-9 of the loop's size: refused at the default tol (1e-13), solved
    with tol = 1e-6, and the residual carried is the one Pinocchio's placements give (not
    0, as LoopSolver.rates wrote before)."""
    mech, closed_q, _ = four_bar_open()
    q = closed_q.copy()
    mech.set_coordinate(q, "O4", mech.coordinate(q, "O4") + 1e-9)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    expected = max(np.abs(cut_rows(mech.model, data, c, selected=True)).max() for c in mech.closures)
    assert 1e-11 < expected < 1e-8
    task = [Task("P", ("x",), np.array([0.1]), np.zeros(1))]
    with pytest.raises(LoopClosureError, match="tolerance 1e-13"):
        RateSolver(mech, task).solve(q)
    with pytest.raises(OptionError, match=r"tol = nan must be a number in \[1e-16, 0.001\]"):
        RateSolver(mech, task, tol=float("nan"))  # as LoopSolver's: NaN would close every loop
    sol = RateSolver(mech, task, tol=1e-6).solve(q)
    assert sol.closure_residual == pytest.approx(expected, rel=1e-6)  # the same rows, to rounding of 1e-15
    assert RateSolver(mech, task, tol=1e-6).solve_many(q[None]).closure_residual[0] == pytest.approx(expected,
                                                                                                     rel=1e-6)
    loop = LoopSolver(mech, ["O2"])
    with pytest.raises(LoopClosureError, match="rates at O2 = 40.1"):
        loop.rates(q, [1.0], [0.0])
    loop.tol = 1e-6
    assert loop.rates(q, [1.0], [0.0])[2].residual == pytest.approx(expected, rel=1e-6)
    assert loop.rates(closed_q, [1.0], [0.0])[2].residual <= residual(1.0)


@pytest.mark.parametrize("build", ["prismatic", "spherical", "fixed", "revolute"])
def test_solve_many_measures_each_cut_type_as_the_closures_do(build, tmp_path):
    """The closure residuals solve_many reads from the compiled core (the rows its rate
    solve already evaluates at each pose) equal the textbook rows on Pinocchio's placements
    (tests/_mechanisms.cut_rows: the independent rows and every selected row) at 20 random
    poses, all open, of a prismatic cut, a spherical one (the RSUR), a weld (MJCF
    ball_loop, its ball's quaternion in q) and the four-bar's revolute cut: to 1e-12 of
    1 + the residual (the same formulas, rounding apart)."""
    from pinmech.model.mjcf import load_mjcf
    from tests import _mechanisms

    if build == "fixed":
        mech = load_mjcf(MODELS / "mjcf" / "ball_loop.xml")
    elif build == "revolute":
        mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    else:
        text = (_mechanisms.slider_crank_prismatic_cut_urdf() if build == "prismatic"
                else _mechanisms.spatial_rsur_urdf())
        mech = Mechanism.from_urdf(_mechanisms.write(tmp_path, f"{build}.urdf", text))
    assert {c.cut_type for c in mech.closures} == {build}
    solver = RateSolver(mech, [Task(next(iter(mech.links)), ("x",), np.array([0.1]), np.zeros(1))])
    rng = np.random.default_rng(7)
    Q = np.array([pin.integrate(mech.model, mech.neutral(), rng.normal(size=mech.model.nv)) for _ in range(20)])
    numbers = solver._rates(Q, solver.x_dot, solver.x_ddot)[:, 2 * mech.model.nv:]  # after v and a
    independent, full = numbers[:, 5], numbers[:, 6]
    data = mech.model.createData()
    for i, q in enumerate(Q):
        pin.framesForwardKinematics(mech.model, data, q)
        want_i = max(np.abs(cut_rows(mech.model, data, c)).max() for c in mech.closures)
        want_f = max(np.abs(cut_rows(mech.model, data, c, selected=True)).max() for c in mech.closures)
        assert want_f > 1e-3  # open: a random pose
        assert independent[i] == pytest.approx(want_i, abs=rounding(1 + want_i))
        assert full[i] == pytest.approx(want_f, abs=rounding(1 + want_f))


# --------------------------------------------------------------------- malformed input
@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"components": ("q",), "velocity": np.zeros(1), "acceleration": np.zeros(1)}, "must be distinct names"),
        ({"components": ("vx",), "velocity": np.zeros(1), "acceleration": np.zeros(1)}, "among x, y, z, wx, wy, wz"),
        ({"components": ("x", "x"), "velocity": np.zeros(2), "acceleration": np.zeros(2)}, "must be distinct"),
        ({"components": (), "velocity": np.zeros(0), "acceleration": np.zeros(0)}, "must be distinct"),
        ({"components": ("x",), "velocity": np.zeros(2), "acceleration": np.zeros(1)}, "velocity needs 1 finite"),
        ({"components": ("x",), "velocity": np.array([np.nan]), "acceleration": np.zeros(1)}, "finite"),
        ({"components": ("x",), "velocity": np.zeros(1), "acceleration": np.array([np.inf])}, "acceleration needs"),
        ({"components": ("x",), "velocity": np.zeros(1), "acceleration": np.zeros(1), "reference": "tool"},
         "reference must be 'world' or 'local'"),
    ],
)
def test_malformed_tasks(kwargs, message):
    with pytest.raises(TaskError, match=message):
        Task("D", **kwargs)


@pytest.mark.parametrize(
    "bad, message",
    [
        (lambda q: q[:2], r"q must be 3 finite numbers \(SI\), got shape \(2,\)"),
        (lambda q: np.r_[q[:2], np.nan], r"q must be 3 finite numbers \(SI\), got shape \(3,\) with a non-finite"),
        (lambda q: q[None], r"q must be 3 finite numbers \(SI\), got shape \(1, 3\)"),
        (lambda q: ["a", "b", "c"], "q must be real numbers .SI., got text"),  # text is never cast (not even "0")
    ],
)
def test_a_q_that_is_no_configuration_is_a_model_error_naming_q(arm, bad, message):
    """Before: raw Pinocchio or numpy errors (README: a ModelError naming the argument)."""
    with pytest.raises(ModelError, match=message):
        RateSolver(arm, arm_tasks()).solve(bad(arm_q(arm, (50, -65, -75))))


def test_a_q_given_as_a_list_is_the_array():
    q = arm_q(Mechanism.from_urdf(MODELS / "planar_arm.urdf"), (50, -65, -75))
    solver = RateSolver(Mechanism.from_urdf(MODELS / "planar_arm.urdf"), arm_tasks())
    np.testing.assert_array_equal(solver.solve(list(q)).v, solver.solve(q).v)


def test_a_quaternion_or_cos_sin_pair_whose_norm_is_not_one_is_refused_with_its_norm():
    """Pinocchio reads a quaternion of norm n as a rotation scaled by n^2: before, a floating
    base's (or a ball joint's) rates came out different, silently. A norm within 1e-12 of 1
    (Pinocchio's isNormalized) is taken as it is."""
    floating = Mechanism.from_urdf(MODELS / "planar_arm.urdf", root_joint="free_flyer")
    solver = RateSolver(floating, arm_tasks())
    q = floating.neutral()
    q[3:7] = [0.2, 0.1, 0.0, 2.0]  # norm 2.0125
    with pytest.raises(ModelError, match=r"joint 'root_joint' has a quaternion of norm 2.01246117974981\d*, not 1"):
        solver.solve(q)
    with pytest.raises(ModelError, match=r"q \(row 1\): joint 'root_joint' has a quaternion of norm 2.0124"):
        solver.solve_many(np.array([floating.neutral(), q]))
    q[3:7] /= np.linalg.norm(q[3:7])
    solver.solve(q)
    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    q = mech.neutral()
    j = mech.joint("O2").idx_q  # a continuous joint: (cos, sin)
    q[j : j + 2] *= 1.5
    with pytest.raises(ModelError, match=r"joint 'O2' has a \(cos, sin\) pair of norm 1.5, not 1"):
        RateSolver(mech, [Task("P", ("x",), np.array([0.1]), np.zeros(1))]).solve(q)


@pytest.mark.parametrize("damping", [DAMPING_RANGE[0], 1.0, DAMPING_RANGE[1]])
def test_damping_at_its_bounds_gives_normal_numbers(arm, damping):
    """At 1e50 the rates are about 1e-100 of the motion asked: small, not denormal (before,
    1e154 gave 1e-309 and 1e155 an OverflowError)."""
    sol = RateSolver(arm, arm_tasks(), method="damped", damping=damping).solve(arm_q(arm, (0, 0, -90)))
    assert np.all(np.isfinite(sol.v)) and np.abs(sol.v).max() > 1e-120


@pytest.mark.parametrize(
    "options, message",
    [
        ({"method": "pinv"}, "method must be one of exact, least_squares, damped"),
        ({"method": "damped", "damping": -1.0}, "damping must be a positive number"),
        ({"method": "damped", "damping": float("nan")}, "damping must be a positive number"),
        ({"method": "damped", "damping": 1e155}, r"damping must be a positive number in \[1e-05, 1e\+50\].*got 1e\+155"),
        ({"method": "damped", "damping": float("inf")}, r"in \[1e-05, 1e\+50\].*got inf"),
        ({"method": "damped", "damping": 1e-9}, r"in \[1e-05, 1e\+50\].*drowns in rounding.*got 1e-09"),
        ({"method": "damped", "damping": "0.1"}, r"got '0.1'"),
    ],
)
def test_bad_solver_options(arm, options, message):
    with pytest.raises(TaskError, match=message):
        RateSolver(arm, arm_tasks(), **options)


def test_no_task_and_unknown_frame(arm):
    with pytest.raises(TaskError, match=r"no task given"):
        RateSolver(arm, [])
    with pytest.raises(FrameNotFound, match="unknown point or frame 'E'"):
        RateSolver(arm, [Task("E", ("x",), np.zeros(1), np.zeros(1))])


def test_r_rtr_task_scene(scenes_dir):
    """models/scenes/r_rtr_task.toml: the pose sets only the crank; the loop is closed, then
    D's one task row gives the crank rate of the closed form (-53.4307 rpm)."""
    from pinmech import Scene, analyse

    analysis = analyse(Scene.load(scenes_dir / "r_rtr_task.toml"))
    dD = closed_form.r_rtr(30 * DEG, 1.0, 0.0).vD[0]
    np.testing.assert_allclose(analysis.drivers.v, [1.0 / dD], rtol=1e-10)
    assert analysis.drivers.v[0] * 30 / np.pi == pytest.approx(-53.4307, abs=5e-5)
    np.testing.assert_allclose(analysis.motion.points["D"].velocity[0], 1.0, rtol=closure(1.0, analysis.solution.accuracy.condition))
    assert analysis.solution.accuracy.residual <= residual(1.0) and analysis.extra["task"]["method"] == "exact"
