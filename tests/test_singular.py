"""Singular and near-singular poses, approached on purpose.

Each approach checks three things: the condition number pinmech reports grows as the
singularity nears; the answers it still gives are right to the stated law (relative
error of accelerations <= eps x condition^3, the `Accuracy.error_estimate`), against a
closed form evaluated in extended precision (np.longdouble, eps 1e-19) so that the
reference is not itself the victim of the cancellation; and past the default limit
(condition 1e5) or at the singularity it stops with SingularPoseError or LoopClosureError.
"""

from __future__ import annotations

import numpy as np
import pytest

import closed_form
from pinmech import LoopClosureError, LoopSolver, Mechanism, SingularPoseError, evaluate_motion
from pinmech.solve_rates import RateSolver, Task
from tests._mechanisms import four_bar_urdf, write

L = np.longdouble


@pytest.fixture(scope="module")
def ab_equals_ac(tmp_path_factory):
    """R-RTR with AB = AC = 0.1 m: at phi = 0 the block B sits on the pivot C."""
    from tests.conftest import MODELS

    text = (MODELS / "r_rtr.urdf").read_text().replace('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="0.10 0 0"')
    return Mechanism.from_urdf(write(tmp_path_factory.mktemp("r"), "r_rtr_ab_ac.urdf", text))


def _r_rtr_at(mech, phi, **options):
    solver = LoopSolver(mech, ["A"], **options)
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", np.pi / 2 - phi / 2)  # link 3 at 90 + phi/2 deg
    mech.set_coordinate(guess, "B_slider", -0.2 * np.sin(phi / 2))
    sol = solver.solve([phi], [1.0], [0.0], guess=guess)
    return sol, evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"])


@pytest.mark.parametrize("delta", [1e-1, 1e-2, 1e-3])
def test_r_rtr_guide_through_its_pivot_approached(ab_equals_ac, delta):
    sol, motion = _r_rtr_at(ab_equals_ac, delta)
    ref = closed_form.r_rtr(L(delta), L(1), L(0), AB=L("0.1"), AC=L("0.1"))
    a_ref = np.array(ref.aD, dtype=float)
    error = np.max(np.abs(motion.points["D"].acceleration[:2] - a_ref)) / np.max(np.abs(a_ref))
    assert sol.accuracy.condition == pytest.approx(2.5 / delta, rel=0.05)  # grows like 1/delta
    assert error <= sol.accuracy.error_estimate


def test_r_rtr_too_close_to_its_singularity_is_refused(ab_equals_ac):
    with pytest.raises(SingularPoseError, match=r"condition number 2\.5\d*e\+04 > 1e\+04"):
        _r_rtr_at(ab_equals_ac, 1e-4)


def test_r_rtr_at_its_singularity(ab_equals_ac):
    with pytest.raises(SingularPoseError):
        _r_rtr_at(ab_equals_ac, 0.0)


# Non-Grashof four-bar: the crank rocks between +-theta_limit, where coupler and rocker align.
A_, B_, C_, D_ = 0.08, 0.05, 0.06, 0.10
THETA_LIMIT = np.arccos((A_**2 + D_**2 - (B_ + C_) ** 2) / (2 * A_ * D_))


@pytest.fixture(scope="module")
def toggle_four_bar(tmp_path_factory):
    return Mechanism.from_urdf(write(tmp_path_factory.mktemp("f"), "fb.urdf", four_bar_urdf(A_, B_, C_, D_)))


def _four_bar_at(mech, theta):
    ref = closed_form.four_bar(L(theta), L(1), L(0), L(A_), L(B_), L(C_), L(D_), branch=1)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(ref.theta3) - theta)
    mech.set_coordinate(guess, "O4", float(ref.theta4))
    solver = LoopSolver(mech, ["O2"])
    sol = solver.solve([theta], [1.0], [0.0], guess=guess)
    return sol, evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["rocker"], points=[]), ref


@pytest.mark.parametrize("delta", [1e-2, 1e-4, 1e-6, 1e-8])
def test_four_bar_toggle_approached(toggle_four_bar, delta):
    sol, motion, ref = _four_bar_at(toggle_four_bar, THETA_LIMIT - delta)
    rocker = motion.links["rocker"]
    for ours, theirs in ((rocker.angular_velocity[2], ref.omega4), (rocker.angular_acceleration[2], ref.alpha4)):
        assert abs(ours - float(theirs)) <= sol.accuracy.error_estimate * abs(float(theirs))
    assert sol.accuracy.condition > 1 / np.sqrt(delta) / 10  # rates blow up like 1/sqrt(delta)


def test_four_bar_past_its_toggle_cannot_close(toggle_four_bar):
    with pytest.raises(LoopClosureError, match="cannot be closed at O2 = 1.2997"):
        LoopSolver(toggle_four_bar, ["O2"]).solve([THETA_LIMIT + 1e-3])


def _arm(models_dir):
    return Mechanism.from_urdf(models_dir / "planar_arm.urdf")


@pytest.mark.parametrize("bend_deg", [10.0, 1.0, 0.1, 179.9])
def test_planar_arm_near_stretched_and_folded(models_dir, bend_deg):
    """D's velocity (1, 0) and CD fixed, arm AB at 0.5 rad, BC bent by a small angle."""
    arm = _arm(models_dir)
    q = arm.neutral()
    angles = (0.5, np.radians(bend_deg), -np.pi / 2 - 0.5 - np.radians(bend_deg))
    for name, angle in zip("ABC", angles):
        arm.set_coordinate(q, name, angle)
    tasks = [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    sol = RateSolver(arm, tasks).solve(q)
    th1, th_bc = L(angles[0]), L(angles[0]) + L(angles[1])
    ref = closed_form.planar_arm_rates(th1, th_bc, L(-np.pi / 2), L("0.3"), L("0.3"), L("0.17"),
                                       np.array([L(1), L(0)]), np.array([L(0), L(0)]))
    bound = 2.2e-16 * sol.condition**3
    np.testing.assert_allclose(sol.v, np.array(ref.q_dot, dtype=float), rtol=bound)
    np.testing.assert_allclose(sol.a, np.array(ref.q_ddot, dtype=float), rtol=bound)


def test_planar_arm_stretched_is_refused(models_dir):
    arm = _arm(models_dir)
    q = arm.neutral()
    arm.set_coordinate(q, "C", -np.pi / 2)
    tasks = [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    with pytest.raises(SingularPoseError, match="A = 0, B = 0, C = -1.5708"):
        RateSolver(arm, tasks).solve(q)
