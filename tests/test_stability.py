"""Scale and speed: micrometres to kilometres, 1e-3 to 1e5 rpm, the same dimensionless answers.

Kinematics scales exactly. With every length of a URDF times k and the driver at omega
[rad/s]: angles do not change, angular velocities scale like omega and accelerations like
omega^2, lengths like k, velocities like omega k and accelerations like omega^2 k. So
angle, omega_i / omega, alpha_i / omega^2, x / k, v / (omega k), a / (omega^2 k) must agree
to 1e-10 relative with the closed form at every size and speed. That holds only if no
tolerance inside pinmech is in metres or seconds: closure residuals are divided by the
mechanism's size, condition numbers and rate solves use dimensionless rows and columns,
and the structural rank of the cuts is found on dimensionless Jacobians.
"""

from __future__ import annotations

import numpy as np
import pytest

import closed_form
from pinmech import LoopSolver, Mechanism, evaluate_motion
from pinmech.solve.rates import RateSolver, Task
from tests._mechanisms import scaled_urdf, slider_crank_prismatic_cut_urdf, spatial_rsur_revolute_cut_urdf, spatial_rsur_urdf
from tests.conftest import MODELS
from tests.tolerance import closure, stated

SIZES = [1e-6, 1e-3, 1.0, 1e3]  # micrometres to kilometres
RPMS = [1e-3, -50.0, 1e5]
THETA = 0.6  # rad: the driver's angle in every case, away from singular poses


def _load(tmp_path, text: str, k: float) -> Mechanism:
    path = tmp_path / f"scaled_{k:g}.urdf"
    path.write_text(scaled_urdf(text, k))
    return Mechanism.from_urdf(path)


def _solve(mech: Mechanism, driver: str, omega: float, guess: dict[str, float], k: float):
    """Solve at THETA with omega [rad/s] and alpha = omega^2 / 2 (so alpha scales like omega^2)."""
    q = mech.neutral()
    for name, value in guess.items():
        mech.set_coordinate(q, name, value * (k if mech.joint(name).kind == "prismatic" else 1.0))
    solver = LoopSolver(mech, [driver])
    return solver, solver.solve([THETA], [omega], [omega**2 / 2], guess=q)


@pytest.mark.parametrize("k", SIZES)
@pytest.mark.parametrize("rpm", RPMS)
def test_r_rtr_same_dimensionless_answers(tmp_path, k, rpm):
    mech = _load(tmp_path, (MODELS / "r_rtr.urdf").read_text(), k)
    w = rpm * np.pi / 30
    solver, sol = _solve(mech, "A", w, {"B": 0.35, "B_slider": -0.06}, k)
    m = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"], links=["link3"])
    link3, d = m.links["link3"], m.points["D"]
    ours = np.r_[link3.angle, link3.angular_velocity[2] / w, link3.angular_acceleration[2] / w**2,
                 d.position[:2] / k, d.velocity[:2] / (w * k), d.acceleration[:2] / (w**2 * k)]
    cf = closed_form.r_rtr(THETA, 1.0, 0.5)
    np.testing.assert_allclose(ours, np.r_[cf.phi3, cf.omega3, cf.alpha3, cf.D, cf.vD, cf.aD], rtol=1e-10, atol=stated(sol.accuracy.residual, sol.accuracy.condition, 1.0, 2))


@pytest.mark.parametrize("k", SIZES)
@pytest.mark.parametrize("rpm", RPMS)
def test_four_bar_same_dimensionless_answers(tmp_path, k, rpm):
    mech = _load(tmp_path, (MODELS / "four_bar.urdf").read_text(), k)
    w = rpm * np.pi / 30
    solver, sol = _solve(mech, "O2", w, {"A": 0.7, "O4": 1.75}, k)
    m = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["B_pin"], links=["coupler", "rocker"])
    rocker, b = m.links["rocker"], m.points["B_pin"]
    ours = np.r_[rocker.angle, rocker.angular_velocity[2] / w, rocker.angular_acceleration[2] / w**2,
                 m.links["coupler"].angular_velocity[2] / w, b.position[:2] / k, b.acceleration[:2] / (w**2 * k)]
    cf = closed_form.four_bar(THETA, 1.0, 0.5, 0.04, 0.12, 0.08, 0.10, branch=1)
    np.testing.assert_allclose(ours, np.r_[cf.theta4, cf.omega4, cf.alpha4, cf.omega3, cf.B, cf.aB],
                               rtol=1e-10, atol=stated(sol.accuracy.residual, sol.accuracy.condition, 1.0, 2))


@pytest.mark.parametrize("k", SIZES)
@pytest.mark.parametrize("rpm", RPMS)
def test_slider_crank_same_dimensionless_answers(tmp_path, k, rpm):
    """A prismatic joint among the dependent ones: its column is scaled by the size, so the
    condition number is the same at every size (it read 1.6e7 on a micrometre R-RTR once)."""
    mech = _load(tmp_path, (MODELS / "slider_crank.urdf").read_text(), k)
    w = rpm * np.pi / 30
    _, sol = _solve(mech, "O", w, {"A": -0.3, "slide": 0.18}, k)
    j = mech.joint("slide")
    ours = [sol.q[j.idx_q] / k, sol.v[j.idx_v] / (w * k), sol.a[j.idx_v] / (w**2 * k)]
    cf = closed_form.slider_crank(THETA, 1.0, 0.5, 0.05, 0.15, 0.01)
    np.testing.assert_allclose(ours, [cf.x_B, cf.v_B, cf.a_B], rtol=1e-10)
    assert sol.accuracy.condition == pytest.approx(1.3693654102026, rel=1e-9)  # slide in sizes of the loop


@pytest.mark.parametrize("k", [1e-9, 1e-6, 1.0, 1e3, 1e6])
@pytest.mark.parametrize(
    "text, rows", [(slider_crank_prismatic_cut_urdf(), 2), (spatial_rsur_urdf(), 3), (spatial_rsur_revolute_cut_urdf(), 5)],
    ids=["planar prismatic cut", "spatial spherical cut", "spatial revolute cut"],
)
def test_cut_rows_found_at_every_size(tmp_path, k, text, rows):
    """Which rows of a cut are independent is found on dimensionless Jacobians: at a
    nanometre the prismatic cut kept 1 row and the revolute cut 2 when they were in metres."""
    mech = _load(tmp_path, text, k)
    assert mech.constraint_rows == rows and mech.mobility == 1


@pytest.mark.parametrize("k", SIZES)
def test_spatial_loop_same_motion_at_every_size(tmp_path, k):
    """The RSUR cut at its rocker pivot, from a guess near its k = 1 solution."""
    text = spatial_rsur_revolute_cut_urdf()
    reference = _load(tmp_path, text, 1.0)
    start = {"U1": 2.0, "U2": 0.3}
    _, ref = _solve(reference, "R1", 1.0, start, 1.0)
    mech = _load(tmp_path, text, k)
    _, sol = _solve(mech, "R1", 1.0, start, k)
    np.testing.assert_allclose(sol.q, ref.q, atol=closure(np.pi, sol.accuracy.condition))
    np.testing.assert_allclose(sol.v, ref.v, rtol=1e-10, atol=closure(np.abs(ref.v).max(), sol.accuracy.condition, 1))
    np.testing.assert_allclose(sol.a, ref.a, rtol=1e-10, atol=closure(np.abs(ref.a).max(), sol.accuracy.condition, 2))
    assert sol.accuracy.condition == pytest.approx(ref.accuracy.condition, rel=1e-9)


@pytest.mark.parametrize("k", SIZES)
@pytest.mark.parametrize("speed", [1e-3, 1.0, 1e5])
@pytest.mark.parametrize("method", ["exact", "damped"])
def test_arm_task_same_dimensionless_answers(tmp_path, k, speed, method):
    """Text 17.110's arm scaled, D moving at (1, 0.3) k speed [m/s], CD turning at 0.2 speed:
    joint rates scale like speed, accelerations like speed^2, the damped answer too (its
    damping is dimensionless)."""
    arm = _load(tmp_path, (MODELS / "planar_arm.urdf").read_text(), k)
    q = arm.neutral()
    for name, angle in zip("ABC", (0.8, -1.1, -1.3)):
        arm.set_coordinate(q, name, angle)
    v = speed * k
    tasks = [Task("D", ("x", "y"), np.array([v, 0.3 * v]), np.array([0.1 * v * speed, 0.0])),
             Task("CD", ("wz",), np.array([0.2 * speed]), np.zeros(1))]
    sol = RateSolver(arm, tasks, method=method).solve(q)
    unit_arm = _load(tmp_path, (MODELS / "planar_arm.urdf").read_text(), 1.0)
    unit_tasks = [Task("D", ("x", "y"), np.array([1.0, 0.3]), np.array([0.1, 0.0])),
                  Task("CD", ("wz",), np.array([0.2]), np.zeros(1))]
    expected = RateSolver(unit_arm, unit_tasks, method=method).solve(q)
    np.testing.assert_allclose(np.r_[sol.v / speed, sol.a / speed**2], np.r_[expected.v, expected.a], rtol=1e-10)
    if method == "exact":
        th = np.cumsum([0.8, -1.1, -1.3])
        cf = closed_form.planar_arm_rates(th[0], th[1], th[2], 0.3, 0.3, 0.17, [1.0, 0.3], [0.1, 0.0], 0.2, 0.0)
        np.testing.assert_allclose(expected.v, cf.q_dot, rtol=1e-10)
        np.testing.assert_allclose(expected.a, cf.q_ddot, rtol=1e-10)
