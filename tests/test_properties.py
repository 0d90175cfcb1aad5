"""Property-based tests (hypothesis, derandomized): random R-RTRs, four-bars and planar
arms against their closed forms, and random unreachable four-bars must raise, never answer.

Tolerances: a relative error bound of eps x condition^3 (`Accuracy.error_estimate`, see
test_singular.py) plus 1e-12 for the Newton tolerance; poses pinmech refuses as singular
(condition > 1e4) are allowed to raise SingularPoseError instead.
"""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import closed_form
from pinmech import LoopClosureError, LoopSolver, Mechanism, SingularPoseError, evaluate_motion
from pinmech.solve_rates import RateSolver, Task
from tests._mechanisms import four_bar_urdf

SETTINGS = settings(max_examples=60, derandomize=True, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])
lengths = st.floats(0.01, 1.0)
angles = st.floats(-np.pi, np.pi)


def _mech(tmp_path_factory, text, name):
    path = tmp_path_factory.mktemp("h") / name
    path.write_text(text)
    return Mechanism.from_urdf(path)


@SETTINGS
@given(AB=lengths, AC=lengths, CD=lengths, phi=angles, omega=st.floats(-100, 100))
def test_random_r_rtr_matches_its_closed_form(tmp_path_factory, models_dir, AB, AC, CD, phi, omega):
    assume(np.hypot(AB * np.cos(phi) - AC, AB * np.sin(phi)) > 1e-3 * max(AB, AC))  # B not on C
    ref = closed_form.r_rtr(phi, omega, 0.0, AB=AB, AC=AC, CD=CD)
    text = (models_dir / "r_rtr.urdf").read_text()
    text = text.replace('<origin xyz="0.10 0 0" rpy="0 0 0"/>', f'<origin xyz="{AB!r} 0 0" rpy="0 0 0"/>')
    text = text.replace('<parent_origin xyz="0.05 0 0"', f'<parent_origin xyz="{AC!r} 0 0"')
    text = text.replace('<origin xyz="0.15 0 0"/>', f'<origin xyz="{CD!r} 0 0"/>')
    mech = _mech(tmp_path_factory, text, "r.urdf")
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", float(ref.phi3) - phi)
    mech.set_coordinate(guess, "B_slider", -float(ref.s))
    solver = LoopSolver(mech, ["A"])
    try:
        sol = solver.solve([phi], [omega], [0.0], guess=guess)
    except SingularPoseError as exc:
        assert exc.condition > 1e4
        return
    m = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"])
    rtol = sol.accuracy.error_estimate + 1e-12
    scale = max(np.abs(ref.aD).max(), 1e-300)
    np.testing.assert_allclose(m.points["D"].position[:2], ref.D, atol=1e-12 * (AB + AC + CD))
    np.testing.assert_allclose(m.points["D"].acceleration[:2], ref.aD, atol=rtol * scale)


@SETTINGS
@given(a=lengths, b=lengths, c=lengths, d=lengths, theta=angles)
def test_random_four_bar_closes_or_says_why(tmp_path_factory, a, b, c, d, theta):
    mech = _mech(tmp_path_factory, four_bar_urdf(a, b, c, d), "f.urdf")
    reach = np.hypot(a * np.cos(theta) - d, a * np.sin(theta))  # |A - O4|
    if not abs(b - c) * 1.001 < reach < (b + c) * 0.999:
        # out of reach (or at the limit): an error, never a number
        try:
            LoopSolver(mech, ["O2"]).solve([theta], [1.0], [0.0])
        except (LoopClosureError, SingularPoseError):
            return
        assert abs(b - c) * 0.999 <= reach <= (b + c) * 1.001, "a four-bar out of reach gave an answer"
        return
    ref = closed_form.four_bar(theta, 1.0, 0.0, a, b, c, d, branch=1)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(ref.theta3) - theta)
    mech.set_coordinate(guess, "O4", float(ref.theta4))
    solver = LoopSolver(mech, ["O2"])
    try:
        sol = solver.solve([theta], [1.0], [0.0], guess=guess)
    except SingularPoseError as exc:
        assert exc.condition > 1e4
        return
    m = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["rocker"], points=[])
    w4 = m.links["rocker"].angular_velocity[2]
    assert abs(w4 - ref.omega4) <= (sol.accuracy.error_estimate + 1e-11) * max(abs(ref.omega4), 1.0)


@SETTINGS
@given(th1=angles, bend=st.floats(0.05, np.pi - 0.05), vx=st.floats(-2, 2), vy=st.floats(-2, 2),
       ax=st.floats(-5, 5), ay=st.floats(-5, 5))
def test_random_planar_arm_tasks(models_dir, th1, bend, vx, vy, ax, ay):
    arm = Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    q = arm.neutral()
    th_bc = th1 + bend
    for name, value in zip("ABC", (th1, bend, -np.pi / 2 - th_bc)):
        arm.set_coordinate(q, name, value)
    tasks = [Task("D", ("x", "y"), np.array([vx, vy]), np.array([ax, ay])),
             Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    try:
        sol = RateSolver(arm, tasks).solve(q)
    except SingularPoseError:
        return
    ref = closed_form.planar_arm_rates(th1, th_bc, -np.pi / 2, 0.3, 0.3, 0.17, np.array([vx, vy]), np.array([ax, ay]))
    bound = 2.2e-16 * sol.condition**3 + 1e-12
    np.testing.assert_allclose(sol.v, ref.q_dot, rtol=bound, atol=bound * (1 + np.abs(ref.q_dot).max()))
    np.testing.assert_allclose(sol.a, ref.q_ddot, rtol=bound, atol=bound * (1 + np.abs(ref.q_ddot).max()))


@SETTINGS
@given(r=st.floats(0.01, 0.5), ratio=st.floats(1.2, 5.0), e_frac=st.floats(-0.8, 0.8), theta=angles,
       omega=st.floats(-50, 50), alpha=st.floats(-50, 50))
def test_random_slider_crank_matches_closed_form_and_finite_differences(tmp_path_factory, models_dir, r, ratio, e_frac,
                                                                        theta, omega, alpha):
    """Offset slider-cranks (rod = ratio x crank, offset e < rod - crank so it always closes):
    the piston's x, v, a against the closed form, and v, a against central differences of
    the solved positions and velocities in time (h = 1e-6 s: error ~ h^2 + eps/h, 1e-6 of the scale)."""
    l, e = ratio * r, e_frac * (ratio - 1) * r
    text = (models_dir / "slider_crank.urdf").read_text()
    text = text.replace('<origin xyz="0.05 0 0"/><axis', f'<origin xyz="{r!r} 0 0"/><axis')
    text = text.replace('<parent_origin xyz="0.15 0 0"/>', f'<parent_origin xyz="{l!r} 0 0"/>')
    text = text.replace('<origin xyz="0 0.01 0"/><axis xyz="1 0 0"/>', f'<origin xyz="0 {e!r} 0"/><axis xyz="1 0 0"/>')
    mech = _mech(tmp_path_factory, text, "sc.urdf")
    ref = closed_form.slider_crank(theta, omega, alpha, r, l, e, branch=1)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(ref.beta) - theta)
    mech.set_coordinate(guess, "slide", float(ref.x_B))
    solver = LoopSolver(mech, ["O"])
    sol = solver.solve([theta], [omega], [alpha], guess=guess)
    j = mech.joint("slide")
    scale = r * max(1.0, abs(omega), omega**2, abs(alpha))
    tol = (sol.accuracy.error_estimate + 1e-12) * scale
    np.testing.assert_allclose([sol.q[j.idx_q], sol.v[j.idx_v], sol.a[j.idx_v]],
                               [ref.x_B, ref.v_B, ref.a_B], atol=tol)
    h = 1e-6

    def state_at(t):
        s = solver.solve([theta + omega * t + 0.5 * alpha * t * t], [omega + alpha * t], [alpha], guess=sol.q)
        return s.q[j.idx_q], s.v[j.idx_v]

    (x_m, v_m), (x_p, v_p) = state_at(-h), state_at(h)
    np.testing.assert_allclose((x_p - x_m) / (2 * h), sol.v[j.idx_v], atol=1e-6 * scale)
    np.testing.assert_allclose((v_p - v_m) / (2 * h), sol.a[j.idx_v], atol=1e-6 * scale)
