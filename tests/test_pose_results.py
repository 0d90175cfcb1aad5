"""One pose's results, built cheaply (`results.frozen`), are the dataclasses their
__init__ would build, frozen as before, holding the pose they were computed at; and the
one-pass check of a pose's q refuses what it refused.

The numbers are checked against the R-RTR's hand-derived vector-loop solution
(scripts/closed_form.py, no Pinocchio) and the rate rows against Pinocchio's own frame
Jacobian, as tests/test_r_rtr.py and tests/test_solve_rates.py do over whole cycles.
"""

from __future__ import annotations

import dataclasses

import closed_form
import numpy as np
import pinocchio as pin
import pytest

from pinmech import CoincidentPoint, LoopSolver, Mechanism, ModelError, RateSolver, Task, evaluate_motion
from tests.conftest import MODELS
from tests.tolerance import rounding

OMEGA1, ALPHA1 = -50 * np.pi / 30, 3.0  # crank at -50 rpm [rad/s], speeding up at 3 rad/s^2
#: Both sides exact: only rounding amplified by the loop's condition number (< 100 on the
#: R-RTR's cycle) and the Newton tolerance (1e-13) separate them, as in tests/test_r_rtr.py.
RTOL = 1e-10


@pytest.fixture(scope="module")
def r_rtr():
    """The R-RTR at crank 40 deg: mechanism, data, solved (q, v, a), the closed form there."""
    mech = Mechanism.from_urdf(MODELS / "r_rtr.urdf")
    solver = LoopSolver(mech, ["A"])
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", np.radians(20))
    mech.set_coordinate(guess, "B_slider", -0.06)
    phi = np.radians(40)
    sol = solver.solve([phi], [OMEGA1], [ALPHA1], guess=guess)
    return mech, mech.model.createData(), sol, closed_form.r_rtr(np.array([phi]), OMEGA1, ALPHA1)


@pytest.fixture(scope="module")
def motion(r_rtr):
    mech, data, sol, _ = r_rtr
    return evaluate_motion(mech, data, sol.q, sol.v, sol.a, coincident=[CoincidentPoint("B3", "B", "link3")])


@pytest.fixture(scope="module")
def arm_rates():
    """Text 17.110's arm: D at (1, 0) m/s, CD not turning, at A, B, C = 50, -65, -75 deg."""
    arm = Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    solver = RateSolver(arm, [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.array([0.0, 0.0])),
                              Task("CD", ("wz",), np.zeros(1), np.zeros(1))])
    q = arm.neutral()
    for name, angle in zip("ABC", (50, -65, -75)):
        arm.set_coordinate(q, name, np.radians(angle))
    return arm, solver, q, solver.solve(q)


def _one_pose_results(motion, arm_rates):
    return [arm_rates[3], motion.points["D"], motion.points["B3"], motion.links["link3"], motion.joints["A"],
            motion.sliders["B_slider"]]


def test_each_result_holds_exactly_its_dataclass_fields_and_stays_frozen(motion, arm_rates):
    for result in _one_pose_results(motion, arm_rates):
        cls = type(result)
        assert not hasattr(cls, "__post_init__"), cls  # `frozen` skips it: no class may have one
        assert list(vars(result)) == [f.name for f in dataclasses.fields(cls)], cls
        again = cls(**vars(result))  # its own __init__, on the same fields
        assert repr(again) == repr(result) and repr(dataclasses.replace(result)) == repr(result)
        with pytest.raises(dataclasses.FrozenInstanceError):
            result.__setattr__(dataclasses.fields(cls)[0].name, None)


def test_the_motion_read_equals_the_vector_loop_solution(motion, r_rtr):
    """Link 3's angle, omega3 and alpha3; D's and B3's velocity and acceleration; the slider's
    s_dot, s_ddot and Coriolis term 2 w3 x v_rel, as the textbook's vector loop gives them."""
    cf = r_rtr[3]
    link3, d, b3, slider = motion.links["link3"], motion.points["D"], motion.points["B3"], motion.sliders["B_slider"]

    def close(ours, theirs):
        theirs = np.ravel(theirs)
        np.testing.assert_allclose(np.ravel(ours)[:theirs.size], theirs, rtol=0,
                                   atol=RTOL * max(1.0, np.max(np.abs(theirs))))

    close(np.unwrap([cf.phi3[0], link3.angle])[1], cf.phi3)
    close([link3.angular_velocity[2], link3.angular_acceleration[2]], [cf.omega3[0], cf.alpha3[0]])
    close(d.velocity, cf.vD), close(d.acceleration, cf.aD), close(b3.velocity, cf.vB3), close(b3.acceleration, cf.aB3)
    close(abs(slider.s_dot), abs(cf.s_dot)), close(abs(slider.s_ddot), abs(cf.s_ddot))
    close(slider.coriolis_acceleration, cf.coriolis)


def test_a_motion_keeps_the_pose_it_was_evaluated_at(r_rtr):
    """The joints are read on first access, from the pose as it was given: a q changed in
    place afterwards (a caller's reused buffer) does not change them."""
    mech, data, sol, _ = r_rtr
    q, v = sol.q.copy(), sol.v.copy()
    m = evaluate_motion(mech, data, q, v, sol.a)
    crank = mech.joint("A")
    angle = np.arctan2(q[crank.idx_q + 1], q[crank.idx_q])  # the continuous joint's (cos, sin) pair
    q[:], v[:] = 0.0, 0.0
    assert (m.joints["A"].q, m.joints["A"].v) == (angle, sol.v[crank.idx_v])


def test_rate_rows_are_the_frame_jacobian_times_the_rates_and_own_their_request(arm_rates):
    """achieved = J v on the task rows, J from Pinocchio's LOCAL_WORLD_ALIGNED frame
    Jacobian (independent of the compiled core); the asked rows are the result's own copy."""
    arm, solver, q, r = arm_rates
    data = arm.model.createData()
    pin.computeJointJacobians(arm.model, data, q)
    pin.updateFramePlacements(arm.model, data)
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    J = np.vstack([pin.getFrameJacobian(arm.model, data, arm.frame_id("D"), lwa)[:2],
                   pin.getFrameJacobian(arm.model, data, arm.frame_id("CD"), lwa)[5:]])
    np.testing.assert_allclose(r.achieved_velocity, J @ r.v, rtol=0, atol=rounding(np.abs(J) @ np.abs(r.v)))  # unit-size rows: rounding
    np.testing.assert_allclose(r.achieved_velocity, [1.0, 0.0, 0.0], rtol=0, atol=rounding(1.0, r.condition))
    r.requested_velocity[:] = 7.0
    assert solver.x_dot.tolist() == [1.0, 0.0, 0.0] and solver.solve(q).requested_velocity.tolist() == [1.0, 0.0, 0.0]


@pytest.mark.parametrize("where", [0, 2, 4])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_coordinate_is_refused_wherever_it_sits(r_rtr, where, bad):
    mech = r_rtr[0]
    q = r_rtr[2].q.copy()
    q[where] = bad
    with pytest.raises(ModelError, match="q must be 5 finite numbers"):
        mech.checked_q(q)


def test_finite_coordinates_whose_sum_overflows_are_accepted():
    """The one-pass check adds the coordinates: 1e308 + 1e308 overflows, yet each is finite."""
    arm = Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    q = np.full(arm.model.nq, 1e308)
    assert arm.checked_q(q) is q


def test_a_cos_sin_pair_off_the_unit_circle_is_refused_with_its_norm(r_rtr):
    mech, _, sol, _ = r_rtr
    q = sol.q.copy()
    crank = mech.joint("A")
    q[crank.idx_q:crank.idx_q + 2] *= 1.0 + 1e-9
    with pytest.raises(ModelError, match=r"joint 'A' has a \(cos, sin\) pair of norm 1\.000000001"):
        mech.checked_q(q)
