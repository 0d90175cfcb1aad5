"""Property-based tests (hypothesis, derandomized, bounded): random R-RTRs, four-bars,
slider-cranks and planar arm tasks, each against its closed form and against finite
differences in time; random mechanisms whose loop cannot close must raise, never answer.

Tolerances: the answers are held to `Accuracy.error_bounds` (4 k m for positions, 4 k^2 m for
velocities, 16 k^3 m for accelerations, m = max(closure residual, eps), k the condition
number) plus 1e-12, relative to the mechanism's scale (its size times its fastest link's
angular velocity, or that squared or its largest angular acceleration); poses pinmech refuses as singular
(k > 1e4) may raise SingularPoseError instead. Finite differences: the driver moves as
theta + omega t + alpha t^2 / 2, the poses at t = +-h are solved, and central differences
of q (on the manifold, `pin.difference`) and of v give v and a with an error of about
h^2 (the third derivative) + k r / h (r the closure residual, up to 1e-13, becomes a
position error k r): with the fastest joint turning 1e-4 rad in h that is 1e-8 k of the scale; the
test allows 1e-6 k.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import closed_form
from pinmech import LoopClosureError, LoopSolver, Mechanism, SingularPoseError, evaluate_motion
from pinmech.solve.rates import RateSolver, Task
from tests._mechanisms import four_bar_urdf, scaled_urdf
from tests.conftest import MODELS
from tests.tolerance import rounding

SETTINGS = settings(max_examples=40, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])
lengths = st.floats(0.01, 1.0)
angles = st.floats(-np.pi, np.pi)
rates = st.one_of(st.just(0.0), st.floats(1e-3, 100), st.floats(-100, -1e-3))  # no subnormal 1e-313 rad/s
sizes = st.sampled_from([1e-6, 1e-3, 1.0, 1e3])  # the same mechanism from micrometres to kilometres


def _mech(tmp_path_factory, text: str, name: str) -> Mechanism:
    path = tmp_path_factory.mktemp("h") / name
    path.write_text(text)
    return Mechanism.from_urdf(path)


def _close(ours, theirs, bound: float, scale: float) -> None:
    np.testing.assert_allclose(ours, np.asarray(theirs, dtype=float), rtol=0, atol=bound * scale + rounding(scale))


def _finite_differences(solver: LoopSolver, sol, theta: float, omega: float, alpha: float):
    """Joint velocities and accelerations by central differences of solved poses in time."""
    turns = sol.v / solver.mechanism.velocity_scale(), sol.a / solver.mechanism.velocity_scale()
    h = 1e-4 / max(np.abs(turns[0]).max(), np.sqrt(np.abs(turns[1]).max()), 1.0)  # fastest joint: 1e-4 rad

    def at(t):
        return solver.solve([theta + omega * t + 0.5 * alpha * t * t], [omega + alpha * t], [alpha], guess=sol.q)

    minus, plus = at(-h), at(h)
    return pin.difference(solver.model, minus.q, plus.q) / (2 * h), (plus.v - minus.v) / (2 * h)


def _check_by_finite_differences(mech, solver, sol, theta, omega, alpha):
    v, a = _finite_differences(solver, sol, theta, omega, alpha)
    scale = 1 / mech.velocity_scale()  # slides in mechanism sizes, turns in radians
    tol = 1e-6 * sol.accuracy.condition  # the closed poses are off by k r, not r, near a singularity
    np.testing.assert_allclose(v * scale, sol.v * scale, rtol=0, atol=tol * max(np.abs(sol.v * scale).max(), 1.0))
    np.testing.assert_allclose(a * scale, sol.a * scale, rtol=0, atol=tol * max(np.abs(sol.a * scale).max(), 1.0))


# ----------------------------------------------------------------------------------- R-RTR
def _r_rtr_text(AB: float, AC: float, CD: float) -> str:
    text = (MODELS / "r_rtr.urdf").read_text()
    text = text.replace('<origin xyz="0.10 0 0" rpy="0 0 0"/>', f'<origin xyz="{AB!r} 0 0" rpy="0 0 0"/>')
    text = text.replace('<parent_origin xyz="0.05 0 0"', f'<parent_origin xyz="{AC!r} 0 0"')
    return text.replace('<origin xyz="0.15 0 0"/>', f'<origin xyz="{CD!r} 0 0"/>')


@SETTINGS
@given(AB=lengths, AC=lengths, CD=lengths, phi=angles, omega=rates, alpha=rates, k=sizes)
def test_random_r_rtr_matches_its_closed_form_and_finite_differences(tmp_path_factory, AB, AC, CD, phi, omega, alpha, k):
    assume(np.hypot(AB * np.cos(phi) - AC, AB * np.sin(phi)) > 1e-3 * max(AB, AC))  # B not on C
    ref = closed_form.r_rtr(phi, omega, alpha, AB=AB, AC=AC, CD=CD)
    mech = _mech(tmp_path_factory, scaled_urdf(_r_rtr_text(AB, AC, CD), k), "r.urdf")
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", float(ref.phi3) - phi)
    mech.set_coordinate(guess, "B_slider", -float(ref.s) * k)
    solver = LoopSolver(mech, ["A"])
    try:
        sol = solver.solve([phi], [omega], [alpha], guess=guess)
    except SingularPoseError as exc:
        assert exc.condition > 1e4
        return
    d = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"]).points["D"]
    pos, vel, acc = sol.accuracy.error_bounds
    size, spin = AB + AC + CD, max(abs(omega), abs(ref.omega3))  # the mechanism's scales, not D's
    _close(d.position[:2] / k, ref.D, pos, size)
    _close(d.velocity[:2] / k, ref.vD, vel, size * spin)
    _close(d.acceleration[:2] / k, ref.aD, acc, size * max(spin**2, abs(alpha), abs(ref.alpha3)))
    _check_by_finite_differences(mech, solver, sol, phi, omega, alpha)


def test_an_r_rtr_whose_pin_passes_through_its_pivot_is_refused_there(tmp_path_factory):
    """AB = AC at phi = 0: B on C, the guide's direction undefined: an error, never a number."""
    for AB in (0.03, 0.1, 0.7):
        mech = _mech(tmp_path_factory, _r_rtr_text(AB, AB, 0.2), "r0.urdf")
        try:
            LoopSolver(mech, ["A"]).solve([0.0], [1.0], [0.0])
        except (SingularPoseError, LoopClosureError):
            continue
        raise AssertionError(f"AB = AC = {AB}: an answer at phi = 0")


# -------------------------------------------------------------------------------- four-bar
@SETTINGS
@given(a=lengths, b=lengths, c=lengths, d=lengths, theta=angles, omega=rates, alpha=rates)
def test_random_four_bar_closes_or_says_why(tmp_path_factory, a, b, c, d, theta, omega, alpha):
    mech = _mech(tmp_path_factory, four_bar_urdf(a, b, c, d), "f.urdf")
    reach = np.hypot(a * np.cos(theta) - d, a * np.sin(theta))  # |A - O4|
    if not abs(b - c) * 1.001 < reach < (b + c) * 0.999:
        # out of reach (or at the limit): an error, never a number
        try:
            LoopSolver(mech, ["O2"]).solve([theta], [omega], [alpha])
        except (LoopClosureError, SingularPoseError):
            return
        assert abs(b - c) * 0.999 <= reach <= (b + c) * 1.001, "a four-bar out of reach gave an answer"
        return
    ref = closed_form.four_bar(theta, omega, alpha, a, b, c, d, branch=1)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(ref.theta3) - theta)
    mech.set_coordinate(guess, "O4", float(ref.theta4))
    solver = LoopSolver(mech, ["O2"])
    try:
        sol = solver.solve([theta], [omega], [alpha], guess=guess)
    except SingularPoseError as exc:
        assert exc.condition > 1e4
        return
    rocker = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["rocker"], points=[]).links["rocker"]
    pos, vel, acc = sol.accuracy.error_bounds
    assert abs((rocker.angle - ref.theta4 + np.pi) % (2 * np.pi) - np.pi) <= pos + rounding(np.pi)
    spin = max(abs(omega), abs(ref.omega3), abs(ref.omega4))
    _close(rocker.angular_velocity[2], ref.omega4, vel, spin)
    _close(rocker.angular_acceleration[2], ref.alpha4, acc, max(spin**2, abs(alpha), abs(ref.alpha3), abs(ref.alpha4)))
    _check_by_finite_differences(mech, solver, sol, theta, omega, alpha)


# ---------------------------------------------------------------------------- slider-crank
def _slider_crank_text(r: float, l: float, e: float) -> str:
    text = (MODELS / "slider_crank.urdf").read_text()
    text = text.replace('<origin xyz="0.05 0 0"/><axis', f'<origin xyz="{r!r} 0 0"/><axis')
    text = text.replace('<parent_origin xyz="0.15 0 0"/>', f'<parent_origin xyz="{l!r} 0 0"/>')
    return text.replace('<origin xyz="0 0.01 0"/><axis xyz="1 0 0"/>', f'<origin xyz="0 {e!r} 0"/><axis xyz="1 0 0"/>')


@SETTINGS
@given(r=st.floats(0.01, 0.5), ratio=st.floats(1.2, 5.0), e_frac=st.floats(-0.8, 0.8), theta=angles,
       omega=rates, alpha=rates, k=sizes)
def test_random_slider_crank_matches_closed_form_and_finite_differences(tmp_path_factory, r, ratio, e_frac,
                                                                        theta, omega, alpha, k):
    """Offset slider-cranks (rod = ratio x crank, offset e < rod - crank so it always closes):
    the piston's x, v, a against the closed form and against finite differences."""
    l, e = ratio * r, e_frac * (ratio - 1) * r
    mech = _mech(tmp_path_factory, scaled_urdf(_slider_crank_text(r, l, e), k), "sc.urdf")
    ref = closed_form.slider_crank(theta, omega, alpha, r, l, e, branch=1)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(ref.beta) - theta)
    mech.set_coordinate(guess, "slide", float(ref.x_B) * k)
    solver = LoopSolver(mech, ["O"])
    sol = solver.solve([theta], [omega], [alpha], guess=guess)
    j = mech.joint("slide")
    pos, vel, acc = sol.accuracy.error_bounds
    _close(sol.q[j.idx_q] / k, ref.x_B, pos, r + l)
    spin = max(abs(omega), abs(ref.omega_rod))
    _close(sol.v[j.idx_v] / k, ref.v_B, vel, (r + l) * spin)
    _close(sol.a[j.idx_v] / k, ref.a_B, acc, (r + l) * max(spin**2, abs(alpha), abs(ref.alpha_rod)))
    _check_by_finite_differences(mech, solver, sol, theta, omega, alpha)


@SETTINGS
@given(r=st.floats(0.01, 0.5), ratio=st.floats(0.2, 0.95), e_frac=st.floats(-0.5, 0.5), theta=angles)
def test_random_slider_crank_that_cannot_reach_its_line_raises(tmp_path_factory, r, ratio, e_frac, theta):
    """A rod shorter than the crank pin's distance from the slider's line: |e - r sin(theta)| > l."""
    l = ratio * r
    e = e_frac * r
    assume(abs(e - r * np.sin(theta)) > 1.01 * l)
    mech = _mech(tmp_path_factory, _slider_crank_text(r, l, e), "bad.urdf")
    try:
        LoopSolver(mech, ["O"]).solve([theta], [1.0], [0.0])
    except (LoopClosureError, SingularPoseError):
        return
    raise AssertionError(f"r = {r}, l = {l}, e = {e}, theta = {theta}: a slider-crank out of reach gave an answer")


# ------------------------------------------------------------------------------ planar arm
@SETTINGS
@given(th1=angles, bend=st.floats(0.05, np.pi - 0.05), wrist=angles, vx=st.floats(-2, 2), vy=st.floats(-2, 2),
       w=st.floats(-2, 2), ax=st.floats(-5, 5), ay=st.floats(-5, 5))
def test_random_planar_arm_tasks(th1, bend, wrist, vx, vy, w, ax, ay):
    """D's velocity and acceleration and CD's angular velocity asked: the joint rates against
    Cramer's rule, and D moved along q(t) = q + q_dot t + q_ddot t^2 / 2 (on the manifold)
    against the asked motion by central differences (the arm turning 1e-4 rad in h: error
    (omega h)^2 a + eps / h^2, about 1e-7 of the scale)."""
    arm = Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    q = arm.neutral()
    for name, value in zip("ABC", (th1, bend, wrist)):
        arm.set_coordinate(q, name, value)
    tasks = [Task("D", ("x", "y"), np.array([vx, vy]), np.array([ax, ay])),
             Task("CD", ("wz",), np.array([w]), np.zeros(1))]
    try:
        sol = RateSolver(arm, tasks).solve(q)
    except SingularPoseError:
        return
    th = np.cumsum([th1, bend, wrist])
    ref = closed_form.planar_arm_rates(th[0], th[1], th[2], 0.3, 0.3, 0.17, [vx, vy], [ax, ay], w, 0.0)
    bound = rounding(1.0, sol.condition)  # an open arm: k eps (tests/test_singular.py)
    _close(sol.v, ref.q_dot, bound, max(np.abs(ref.q_dot).max(), 1.0))
    _close(sol.a, ref.q_ddot, bound, max(np.abs(ref.q_ddot).max(), 1.0))
    data, fid = arm.model.createData(), arm.frame_id("D")
    h = 1e-4 / max(np.abs(sol.v).max(), np.sqrt(np.abs(sol.a).max()), 1.0)

    def d_at(t):
        pin.framesForwardKinematics(arm.model, data, pin.integrate(arm.model, q, sol.v * t + 0.5 * sol.a * t * t))
        return data.oMf[fid].translation[:2].copy()

    minus, mid, plus = d_at(-h), d_at(0.0), d_at(h)
    scale = 0.77 * max(np.abs(sol.v).max() ** 2, np.abs(sol.a).max(), 1.0)  # reach x omega^2 [m/s^2]
    np.testing.assert_allclose((plus - minus) / (2 * h), [vx, vy], rtol=0, atol=1e-6 * scale)
    np.testing.assert_allclose((plus - 2 * mid + minus) / h**2, [ax, ay], rtol=0, atol=1e-6 * scale)
