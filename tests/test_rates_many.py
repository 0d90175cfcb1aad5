"""`RateSolver.solve_many`: the rate problem at many poses in one call (the compiled core
for square, regular tasks), against `solve` pose by pose and against the closed form of the
arm of text 17.110 (P2 of issue 13).

Tolerances: against `solve`, 1e-12 of each rate's size (the same rows and the same LU, in
another order of operations, times condition numbers below 1e2 here); against the closed
form, 1e-13 absolute over rates up to 149 rad/s^2, the bar of issue 13 (the two closed
forms of the benchmark differ by 2e-13 there, so 1e-12 is asserted and the error printed
by scripts/benchmark_peers.py)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import pinmech
from pinmech.exceptions import ModelError, SingularPoseError
from tests.tolerance import rounding

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import closed_form  # noqa: E402

R1, R2, R3, TH_CD = 0.3, 0.3, 0.17, -math.pi / 2


def _arm(models_dir):
    mechanism = pinmech.Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    solver = pinmech.RateSolver(mechanism, [
        pinmech.Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)),
        pinmech.Task("CD", ("wz",), np.zeros(1), np.zeros(1))])
    return mechanism, solver


def _poses(mechanism, n=360):
    k = np.arange(n) * (360.0 / n)
    th1 = np.radians(50.0 + k)
    th2 = np.radians(50.0 + k - 65.0 + 40.0 * np.sin(np.radians(k)))
    ja, jb, jc = (mechanism.joint(x) for x in "ABC")
    Q = np.tile(mechanism.neutral(), (n, 1))
    rel = (np.stack([th1, th2 - th1, TH_CD - th2], axis=1) + math.pi) % (2 * math.pi) - math.pi
    Q[:, ja.idx_q], Q[:, jb.idx_q], Q[:, jc.idx_q] = rel.T
    return Q, th1, th2


@pytest.fixture
def models_dir():
    from tests.conftest import MODELS
    return MODELS


def test_arm_rates_meet_the_closed_form(models_dir):
    mechanism, solver = _arm(models_dir)
    Q, th1, th2 = _poses(mechanism)
    batch = solver.solve_many(Q)
    ref = closed_form.planar_arm_rates(th1, th2, TH_CD, R1, R2, R3, np.array([1.0, 0.0]), np.zeros(2))
    ia, ib = mechanism.joint("A").idx_v, mechanism.joint("B").idx_v
    got = np.column_stack([batch.v[:, ia], batch.v[:, ia] + batch.v[:, ib], batch.a[:, ia],
                           batch.a[:, ia] + batch.a[:, ib]])
    want = np.column_stack([ref.omega_AB, ref.omega_BC, ref.alpha_AB, ref.alpha_BC])
    assert np.abs(got - want).max() < rounding(np.abs(want).max(), batch.condition.max())
    assert list(batch.method) == ["exact"] * len(Q)


def test_many_equals_one_by_one(models_dir):
    mechanism, solver = _arm(models_dir)
    Q = _poses(mechanism, 36)[0]
    batch = solver.solve_many(Q)
    for i, q in enumerate(Q):
        r = solver.solve(q)
        for got, want in ((batch.v[i], r.v), (batch.a[i], r.a), (batch.achieved_velocity[i], r.achieved_velocity),
                          (batch.achieved_acceleration[i], r.achieved_acceleration)):
            np.testing.assert_allclose(got, want, rtol=0, atol=rounding(1 + np.abs(want).max(), r.condition))
        assert batch.condition[i] == pytest.approx(r.condition, rel=rounding(1.0, r.condition))
        assert batch.sigma_min[i] == pytest.approx(r.sigma_min, rel=rounding(1.0, r.condition))


def test_closed_loop_task_equals_solve(scenes_dir):
    """The R-RTR task scene: closure rows stacked over D's x row, at poses of a sweep."""
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scenes_dir / "r_rtr.toml"))
    Q = next(sweep.chunks(np.radians(np.arange(5.0, 360.0, 10.0)))).solution.q  # 0 and 180 deg: D moves along y only
    solver = pinmech.RateSolver(sweep.mechanism, [pinmech.Task("D", ("x",), np.array([1.0]), np.zeros(1))])
    batch = solver.solve_many(Q)
    for i, q in enumerate(Q):
        r = solver.solve(q)
        np.testing.assert_allclose(batch.v[i], r.v, rtol=0, atol=rounding(1 + np.abs(r.v).max(), r.condition))
        np.testing.assert_allclose(batch.a[i], r.a, rtol=0, atol=rounding(1 + np.abs(r.a).max(), r.condition))
        assert batch.closure_velocity_residual[i] < rounding(np.abs(r.v).max()) and batch.closure_acceleration_residual[i] < 1e-9


def test_a_singular_pose_is_named_as_by_solve(models_dir):
    mechanism, solver = _arm(models_dir)
    Q = _poses(mechanism, 4)[0]
    Q[2, mechanism.joint("B").idx_q] = 0.0  # AB and BC aligned: the arm is stretched out
    with pytest.raises(SingularPoseError):
        solver.solve(Q[2])
    with pytest.raises(SingularPoseError):
        solver.solve_many(Q)


def test_bad_shapes_are_named(models_dir):
    """A q that is no (N, nq) array of configurations is a ModelError naming q, as for
    `solve` and `evaluate_motion` (README, "Python API")."""
    mechanism, solver = _arm(models_dir)
    with pytest.raises(ModelError, match=r"q must be an \(N, 3\) array of finite numbers \(SI\), got shape \(3, 4\)"):
        solver.solve_many(np.zeros((3, mechanism.model.nq + 1)))
    with pytest.raises(ModelError, match=r"got shape \(3,\)"):
        solver.solve_many(np.zeros(3))


def test_local_axes_and_a_six_dof_arm_equal_solve(scenes_dir):
    """A task in the frame's own axes on the arm, and a 6-row task on the UR5 (6 joints,
    SVD above 3x3): `solve_many` equals `solve` pose by pose."""
    from tests.conftest import MODELS

    mechanism = pinmech.Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    solver = pinmech.RateSolver(mechanism, [
        pinmech.Task("D", ("x", "y"), np.array([1.0, 0.0]), np.array([0.5, -0.2]), reference="local"),
        pinmech.Task("CD", ("wz",), np.array([0.3]), np.zeros(1))])
    Q = _poses(mechanism, 24)[0]
    batch = solver.solve_many(Q)
    for i, q in enumerate(Q):
        r = solver.solve(q)
        np.testing.assert_allclose(batch.v[i], r.v, rtol=0, atol=rounding(1 + np.abs(r.v).max(), r.condition))
        np.testing.assert_allclose(batch.a[i], r.a, rtol=0, atol=rounding(1 + np.abs(r.a).max(), r.condition))
    analysis = pinmech.analyse(pinmech.Scene.load(scenes_dir / "ur5.toml"))
    mech = analysis.mechanism
    tasks = [pinmech.Task(analysis.scene.file.task[0].frame, ("x", "y", "z", "wx", "wy", "wz"),
                          np.array([0.1, -0.2, 0.05, 0.3, 0.0, -0.1]), np.array([0.0, 0.1, 0.0, 0.0, 0.2, 0.0]))]
    arm = pinmech.RateSolver(mech, tasks)
    rng = np.random.default_rng(3)
    Q = np.array([mech.neutral() + rng.uniform(-1, 1, mech.model.nq) for _ in range(12)])
    batch = arm.solve_many(Q)  # seeded poses, all regular
    for i, q in enumerate(Q):
        r = arm.solve(q)
        np.testing.assert_allclose(batch.v[i], r.v, rtol=0, atol=1e-10 * (1 + np.abs(r.v).max()))
        np.testing.assert_allclose(batch.a[i], r.a, rtol=0, atol=1e-10 * (1 + np.abs(r.a).max()))


def _arm_jacobian(th1, th2, th3):
    """The 3R arm's task Jacobian in closed form (rows: D's x, y [m per rad], CD's wz; columns:
    the joints A, B, C): joint k turns D about its own axis, d D / d q_k = z x (D - P_k)."""
    dc = R3 * np.array([math.cos(th3), math.sin(th3)])
    db = dc + R2 * np.array([math.cos(th2), math.sin(th2)])
    da = db + R1 * np.array([math.cos(th1), math.sin(th1)])
    return np.array([[-da[1], -db[1], -dc[1]], [da[0], db[0], dc[0]], [1.0, 1.0, 1.0]])


def test_condition_numbers_meet_the_closed_form_jacobians_svd(models_dir):
    """The condition number and smallest singular value of the dimensionless task Jacobian,
    from a generic pose to BC bent 1e-7 rad from AB (kappa ~ 1/delta up to ~1e7), against
    LAPACK's SVD (numpy) of the closed-form Jacobian scaled by the solver's own row and column
    factors. Any backward-stable SVD gets sigma_min within ~eps sigma_max, so the two agree
    to ~kappa eps relative: rel 1e-14 kappa + 1e-14 holds with a margin of ~10 for rounding
    in the Jacobians themselves (closed form vs Pinocchio, each ~eps)."""
    mechanism, _ = _arm(models_dir)
    solver = pinmech.RateSolver(mechanism, _arm(models_dir)[1].tasks, max_condition=1e12)
    ja, jb, jc = (mechanism.joint(x) for x in "ABC")
    angles = [(0.7, 0.7 - 1.1), (0.2, 1.9)] + [(0.4, 0.4 + d) for d in (1e-1, 1e-3, 1e-5, 1e-7)]
    Q = np.tile(mechanism.neutral(), (len(angles), 1))
    for k, (th1, th2) in enumerate(angles):
        Q[k, [ja.idx_q, jb.idx_q, jc.idx_q]] = th1, th2 - th1, TH_CD - th2
    batch = solver.solve_many(Q)
    rows, columns = solver._scales(0)
    cols = columns[[ja.idx_v, jb.idx_v, jc.idx_v]]
    for k, (th1, th2) in enumerate(angles):
        sigma = np.linalg.svd(rows[:, None] * _arm_jacobian(th1, th2, TH_CD) * cols[None, :], compute_uv=False)
        kappa = sigma[0] / sigma[-1]
        assert batch.condition[k] == pytest.approx(kappa, rel=rounding(1.0, kappa))
        assert batch.sigma_min[k] == pytest.approx(sigma[-1], rel=rounding(1.0, kappa))
    assert batch.condition[-1] > 1e6  # the stretched arm was reached


def test_six_by_six_condition_numbers_meet_lapack(scenes_dir):
    """UR5's full-pose task (6 x 6): the condition number and smallest singular value at seeded
    poses and near the wrist singularity (wrist 2 at 1e-3 rad: wrist 1 and 3 axes nearly
    aligned, kappa ~ 1e3), against LAPACK's SVD (numpy) of tool0's frame Jacobian from
    Pinocchio's Python bindings (world-aligned axes), scaled by the solver's row and column
    factors. Both are backward-stable SVDs: rel 1e-14 kappa + 1e-14, as for the arm above."""
    import pinocchio as pin

    analysis = pinmech.analyse(pinmech.Scene.load(scenes_dir / "ur5.toml"))
    mech = analysis.mechanism
    frame = analysis.scene.file.task[0].frame
    arm = pinmech.RateSolver(mech, [pinmech.Task(frame, ("x", "y", "z", "wx", "wy", "wz"), np.zeros(6), np.zeros(6))],
                             max_condition=1e12)
    rng = np.random.default_rng(5)
    Q = np.array([mech.neutral() + rng.uniform(-1, 1, mech.model.nq) for _ in range(6)])
    wrist = mech.joint("wrist_2_joint").idx_q
    Q[-1, wrist] = 1e-3
    batch = arm.solve_many(Q)
    rows, columns = arm._scales(0)
    model = mech.model
    data = model.createData()
    fid = model.getFrameId(frame)
    for k, q in enumerate(Q):
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        sigma = np.linalg.svd(rows[:, None] * J * columns[None, :], compute_uv=False)
        kappa = sigma[0] / sigma[-1]
        assert batch.condition[k] == pytest.approx(kappa, rel=rounding(1.0, kappa))
        assert batch.sigma_min[k] == pytest.approx(sigma[-1], rel=rounding(1.0, kappa))
    assert batch.condition[-1] > 1e2  # the wrist singularity was approached
