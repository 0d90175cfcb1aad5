"""Angles: near +-pi, after many whole turns, in degrees and radians, and continuous joints.

Pinocchio stores a continuous joint as (cos q, sin q), so any angle gives the pose of the
angle modulo 2 pi, and reading it back (`Mechanism.coordinate`) gives that angle in
(-pi, pi]. What can be lost is only what float64 itself loses: an angle of 1e6 rad is a
float64 with a spacing of 1.2e-10 rad, so "1e6 rad" means that float64, and the pose is
that float64's angle modulo 2 pi (computed exactly by cos and sin), which the references
below use too.
"""

from __future__ import annotations

from decimal import Decimal, localcontext

import numpy as np
import pytest

import closed_form
from pinmech import LoopSolver, Mechanism, Scene, analyse, evaluate_motion
from pinmech.solve.rates import RateSolver, Task
from pinmech.io.sweep import Sweep
from tests.tolerance import closure, rounding, stated

ANGLES = [np.pi, -np.pi, np.nextafter(np.pi, 0), -np.nextafter(np.pi, 0), np.pi - 1e-12, 1e6, -1e6,
          2 * np.pi * 1e5 + 0.5, 1e15 + 0.25, 7 * np.pi]
PI = Decimal("3.14159265358979323846264338327950288419716939937510582097494459230781640628620899")


def _wrapped(angle: float) -> float:
    """The float64 angle modulo 2 pi, in (-pi, pi], in 80-digit decimal arithmetic (float64
    would lose 1e-10 on 1e6 rad, and even np.longdouble 1e-4 on 1e15 rad)."""
    with localcontext() as context:
        context.prec = 80
        x = Decimal(angle) % (2 * PI)  # exact float64 value, sign of the angle
        x = x - 2 * PI if x > PI else x + 2 * PI if x <= -PI else x
        return float(x)


@pytest.fixture(scope="module")
def r_rtr():
    from tests.conftest import MODELS

    return Mechanism.from_urdf(MODELS / "r_rtr.urdf")


@pytest.mark.parametrize("angle", ANGLES)
def test_a_continuous_joint_round_trips(r_rtr, angle):
    """set_coordinate then coordinate: the angle modulo 2 pi, to a unit in the last place of pi."""
    q = r_rtr.neutral()
    r_rtr.set_coordinate(q, "A", angle)
    assert np.hypot(*q[r_rtr.joint("A").idx_q:][:2]) == pytest.approx(1.0, abs=rounding(1.0))
    back = r_rtr.coordinate(q, "A")
    assert -np.pi <= back <= np.pi
    assert abs(back - _wrapped(angle)) <= rounding(np.pi) or abs(abs(back - _wrapped(angle)) - 2 * np.pi) <= rounding(np.pi)


@pytest.mark.parametrize("angle", ANGLES)
def test_crank_angles_at_the_wrap_and_after_many_turns(r_rtr, angle):
    """The R-RTR at any crank angle gives the pose, rates and accelerations of the closed form."""
    guess = r_rtr.neutral()
    r_rtr.set_coordinate(guess, "B_slider", -0.06)
    solver = LoopSolver(r_rtr, ["A"])
    sol = solver.solve([angle], [1.0], [0.5], guess=guess)
    m = evaluate_motion(r_rtr, solver.data, sol.q, sol.v, sol.a, points=["D"])
    cf = closed_form.r_rtr(angle, 1.0, 0.5)
    np.testing.assert_allclose(m.points["D"].position[:2], cf.D, atol=stated(sol.accuracy.residual, sol.accuracy.condition, np.abs(cf.D).max()))
    np.testing.assert_allclose(m.points["D"].velocity[:2], cf.vD, atol=stated(sol.accuracy.residual, sol.accuracy.condition, np.abs(cf.vD).max(), 1))
    np.testing.assert_allclose(m.points["D"].acceleration[:2], cf.aD, atol=stated(sol.accuracy.residual, sol.accuracy.condition, np.abs(cf.aD).max(), 2))
    assert r_rtr.coordinate(sol.q, "A") == pytest.approx(_wrapped(angle), abs=rounding(np.pi)) or abs(angle) == np.pi


@pytest.mark.parametrize("angle", [1e6, -1e6, 1e12, 1e15 + 0.25, -1e15])
def test_far_crank_angles_reached_from_the_reference_close_the_loop(r_rtr, angle):
    """The same angles reached by continuation from a reference at 30 deg (as --angle and
    every solve without a guess do): the turns repeat, so the rest of the way is followed.
    It was x1 - x0 less its turns, and x1 - x0 rounded to the spacing of 1e15 (0.125 rad)
    left the loop open by 0.03 of its size with exit 0; now the pose is the closed form's
    (1e-13 m) and the loop closed to the solver's tolerance."""
    guess = r_rtr.neutral()
    r_rtr.set_coordinate(guess, "B_slider", -0.06)
    solver = LoopSolver(r_rtr, ["A"])
    solver.set_reference([np.radians(30)], guess)
    sol = solver.solve([angle], [1.0], [0.5])
    assert sol.accuracy.residual <= solver.tol
    m = evaluate_motion(r_rtr, solver.data, sol.q, sol.v, sol.a, points=["D"])
    cf = closed_form.r_rtr(_wrapped(angle), 1.0, 0.5)
    np.testing.assert_allclose(m.points["D"].position[:2], cf.D, atol=stated(sol.accuracy.residual, sol.accuracy.condition, np.abs(cf.D).max()))
    np.testing.assert_allclose(m.points["D"].velocity[:2], cf.vD, atol=stated(sol.accuracy.residual, sol.accuracy.condition, np.abs(cf.vD).max(), 1))


@pytest.mark.parametrize("turns", [0, 1, -3, 1000, 10**6])
def test_a_revolute_arm_joint_after_whole_turns(models_dir, turns):
    """A revolute joint (not continuous) keeps its angle as written; its pose and rates after
    whole turns are those of the angle itself, to the float64 spacing of the angle written."""
    arm = Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    tasks = [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    angles = np.radians([50.0, -65.0, -75.0])
    q = arm.neutral()
    for name, angle in zip("ABC", angles):
        arm.set_coordinate(q, name, angle + 2 * np.pi * turns)
    sol = RateSolver(arm, tasks).solve(q)
    th = np.cumsum(angles)
    ref = closed_form.planar_arm_rates(th[0], th[1], th[2], 0.3, 0.3, 0.17, [1.0, 0.0], [0.0, 0.0])
    spacing = np.spacing(2 * np.pi * max(abs(turns), 1))  # what writing the angle rounds off
    np.testing.assert_allclose(sol.v, ref.q_dot, atol=rounding(np.abs(ref.q_dot).max(), sol.condition) + 100 * spacing)
    np.testing.assert_allclose(sol.a, ref.q_ddot, atol=1e-11 + 1000 * spacing)


@pytest.mark.parametrize("degrees, radians", [("30 deg", np.pi / 6), ("180 deg", np.pi), ("-180 deg", -np.pi),
                                              ("540 deg", 3 * np.pi), ("0.25 turn", np.pi / 2),
                                              ("1e6 deg", float(np.radians(1e6)))])
def test_degrees_turns_and_radians_give_the_same_pose(r_rtr_scene, degrees, radians):
    deg = analyse(Scene.load(r_rtr_scene, [f'drivers.A.angle="{degrees}"']))
    rad = analyse(Scene.load(r_rtr_scene, [f'drivers.A.angle="{radians!r} rad"']))
    np.testing.assert_allclose(deg.solution.q, rad.solution.q, rtol=0, atol=closure(np.pi, rad.solution.accuracy.condition))
    np.testing.assert_allclose(deg.motion.points["D"].acceleration, rad.motion.points["D"].acceleration, atol=1e-11)


def test_speeds_in_rpm_rev_per_second_and_radians_agree(r_rtr_scene):
    a = analyse(Scene.load(r_rtr_scene, ['drivers.A.speed="-50 rpm"']))
    b = analyse(Scene.load(r_rtr_scene, [f'drivers.A.speed="{-50 / 60!r} rev/s"']))
    c = analyse(Scene.load(r_rtr_scene, [f'drivers.A.speed="{-50 * np.pi / 30!r} rad/s"']))
    for other in (b, c):
        np.testing.assert_allclose(other.solution.v, a.solution.v, rtol=rounding(1.0))


def test_a_hundred_turns_stay_on_the_branch(r_rtr_scene):
    """3600 poses over 100 crank turns, as `pinmech sweep` solves them (each from the previous
    one): every pose on the scene's branch (D beyond B seen from C), every pose within
    1e-13 of the closed form (no drift), and the last equal to the first."""
    sweep = Sweep.from_scene(Scene.load(r_rtr_scene))
    values = sweep.start + np.linspace(0, 200 * np.pi, 3601)
    d = np.array([pose.motion.points["D"].position[:2] for pose in sweep.poses(values)])
    cf = closed_form.r_rtr(values, sweep.drivers.v[0], 0.0)
    assert np.all(np.einsum("ij,ij->i", d - [0.05, 0.0], cf.B - [0.05, 0.0]) > 0)
    np.testing.assert_allclose(d, cf.D, rtol=0, atol=closure(np.abs(cf.D).max(), 2.5))
    np.testing.assert_allclose(d[-1], d[0], rtol=0, atol=closure(np.abs(cf.D).max()))
