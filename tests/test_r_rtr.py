"""The R-RTR mechanism of Problem Chapter I.9, against the independent vector-loop solution.

`scripts/closed_form.py` solves the loop B - C = s u by hand-derived formulas, with no
Pinocchio; pinmech solves the URDF with its <constraint> cut by Newton and frame
Jacobians. Over a full crank revolution they must agree to 1e-10 relative (the error of
each quantity divided by its largest magnitude over the cycle): both are exact, so the
only differences are rounding (~1e-15) amplified by the constraint's condition number
(< 100 on this cycle) and the Newton tolerance (1e-13 of the mechanism's size).
"""

from __future__ import annotations

import numpy as np
import pytest

import closed_form
from pinmech import CoincidentPoint, LoopSolver, Mechanism, evaluate_motion
from tests.tolerance import rounding

OMEGA1 = -50 * np.pi / 30  # -50 rpm [rad/s]
RTOL = 1e-10


@pytest.fixture(scope="module")
def cycle(request):
    """pinmech and the closed form at 360 crank angles, crank speeding up at 3 rad/s^2."""
    from tests.conftest import MODELS

    alpha1 = 3.0
    mech = Mechanism.from_urdf(MODELS / "r_rtr.urdf")
    solver = LoopSolver(mech, ["A"])
    q = mech.neutral()
    mech.set_coordinate(q, "B", np.radians(20))
    mech.set_coordinate(q, "B_slider", -0.06)
    phis = np.radians(30) + np.linspace(0, 2 * np.pi, 360, endpoint=False)
    b3 = [CoincidentPoint("B3", at="B", link="link3")]
    rows = []
    for phi in phis:
        sol = solver.solve([phi], [OMEGA1], [alpha1], guess=q)
        q = sol.q
        rows.append(evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, coincident=b3))
    return rows, closed_form.r_rtr(phis, OMEGA1, alpha1)


def _assert_cycle(ours, theirs):
    ours, theirs = np.asarray(ours), np.asarray(theirs)
    scale = np.max(np.abs(theirs))
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=RTOL * scale)


@pytest.mark.parametrize("point, field", [("B", "B"), ("D", "D")])
def test_positions_over_a_revolution(cycle, point, field):
    rows, cf = cycle
    _assert_cycle([m.points[point].position[:2] for m in rows], getattr(cf, field))


@pytest.mark.parametrize("point, field", [("B", "vB"), ("B3", "vB3"), ("D", "vD")])
def test_velocities_over_a_revolution(cycle, point, field):
    rows, cf = cycle
    _assert_cycle([m.points[point].velocity[:2] for m in rows], getattr(cf, field))


@pytest.mark.parametrize("point, field", [("B", "aB"), ("B3", "aB3"), ("D", "aD")])
def test_accelerations_over_a_revolution(cycle, point, field):
    rows, cf = cycle
    _assert_cycle([m.points[point].acceleration[:2] for m in rows], getattr(cf, field))


def test_link3_angle_rate_and_acceleration(cycle):
    rows, cf = cycle
    phi3 = np.array([m.links["link3"].angle for m in rows])
    wrapped = np.angle(np.exp(1j * (phi3 - cf.phi3)))  # difference of angles, in (-pi, pi]
    np.testing.assert_allclose(wrapped, 0.0, atol=RTOL * np.pi)
    _assert_cycle([m.links["link3"].angular_velocity[2] for m in rows], cf.omega3)
    _assert_cycle([m.links["link3"].angular_acceleration[2] for m in rows], cf.alpha3)


def test_link2_turns_with_link3(cycle):
    rows, _ = cycle
    for m in rows:
        np.testing.assert_allclose(m.links["link2"].angular_velocity, m.links["link3"].angular_velocity, atol=rounding(np.abs(m.links["link3"].angular_velocity).max()))


def test_slider_relative_motion_and_coriolis(cycle):
    """v_B32 = -s_dot u, a_B32 = -s_ddot u, a_cor = 2 omega_3 x v_B32 (the text's eq. 11)."""
    rows, cf = cycle
    _assert_cycle([m.sliders["B_slider"].relative_velocity[:2] for m in rows], cf.v_rel)
    _assert_cycle([m.sliders["B_slider"].relative_acceleration[:2] for m in rows], cf.a_rel)
    _assert_cycle([m.sliders["B_slider"].coriolis_acceleration[:2] for m in rows], cf.coriolis)


def test_acceleration_of_b3_is_b2_plus_relative_plus_coriolis(cycle):
    """The textbook's eq. (9), a_B3 = a_B2 + a_B32 + a_cor, from pinmech's own outputs."""
    rows, _ = cycle
    for m in rows:
        s = m.sliders["B_slider"]
        np.testing.assert_allclose(
            m.points["B3"].acceleration,
            m.points["B"].acceleration + s.relative_acceleration + s.coriolis_acceleration,
            atol=rounding(np.linalg.norm(m.points["B3"].acceleration)),
        )
