"""Singular and near-singular poses, approached on purpose.

Each approach checks what pinmech reports (the condition number k of the Jacobian it
solves grows by the mechanism's own law), that its answers just before the singularity
are right to the stated bounds, and where it stops (SingularPoseError past the default
limit k = 1e4, LoopClosureError where the loop cannot close).

The bounds (`Accuracy.error_bounds`), with m = max(closure residual, eps), eps = 2.2e-16:
relative error of positions <= 4 k m, of velocities <= 4 k^2 m, of accelerations <= 16 k^3 m.
The residual enters because Newton stops as soon as it is below its tolerance (1e-13),
and near a singularity that residual, not rounding, sets the error. Each guess is 1e-3 rad
off the answer, as a sweep's previous pose would be, so Newton really runs.

References are the closed forms of scripts/closed_form.py evaluated in np.longdouble
(eps 1.1e-19 on x86-64), for the exact float64 dimensions pinmech reads: a float64
reference suffers the same cancellation as the solver near these poses.
"""

from __future__ import annotations

import numpy as np
import pytest

import closed_form
from pinmech import LoopClosureError, LoopSolver, Mechanism, SingularPoseError, evaluate_motion
from pinmech.solve.results import EPS
from pinmech.solve.rates import RateSolver, Task
from tests._mechanisms import four_bar_urdf, write
from tests.conftest import MODELS
from tests.tolerance import REGULAR, closure

L = np.longdouble
PI = L("3.14159265358979323846264338327950288")
OFFSET = 1e-3  # rad: how far each Newton guess starts from the answer


def _relative(x, reference) -> float:
    """max |x - reference| / max |reference|, in extended precision."""
    reference = np.asarray(reference, dtype=L)
    return float(np.max(np.abs(np.asarray(x, dtype=L) - reference)) / np.max(np.abs(reference)))


def _angle_error(angle: float, reference) -> float:
    return abs(float((L(angle) - reference + PI) % (2 * PI) - PI))


def _within_bounds(accuracy, position: float, velocity: float, acceleration: float) -> None:
    bounds = accuracy.error_bounds
    for name, error, bound in zip(("position", "velocity", "acceleration"), (position, velocity, acceleration), bounds):
        assert error <= bound, f"{name} error {error:.3g} > bound {bound:.3g} (condition {accuracy.condition:.4g})"


# --------------------------------------------------------------------------- R-RTR, AB = AC
@pytest.fixture(scope="module")
def ab_equals_ac(tmp_path_factory):
    """R-RTR with AB = AC = 0.1 m: at phi = 0 the block B sits on the pivot C, and the
    guide's direction is undefined there (its rates are not: omega_3 = omega_1 / 2)."""
    text = (MODELS / "r_rtr.urdf").read_text()
    text = text.replace('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="0.10 0 0"')
    return Mechanism.from_urdf(write(tmp_path_factory.mktemp("r"), "r_rtr_ab_ac.urdf", text))


def _isosceles(phi: float, omega: float, alpha: float):
    """AB = AC: the triangle ABC is isosceles, so link 3 is at phi_3 = 90 deg + phi / 2 exactly,
    omega_3 = omega_1 / 2 and alpha_3 = alpha_1 / 2; D = C + CD (cos phi_3, sin phi_3)."""
    phi3, w3, a3 = PI / 2 + L(phi) / 2, L(omega) / 2, L(alpha) / 2
    u, n = np.array([np.cos(phi3), np.sin(phi3)]), np.array([-np.sin(phi3), np.cos(phi3)])
    CD = L(0.15)
    return phi3, np.array([L(0.1), L(0)]) + CD * u, CD * w3 * n, CD * (a3 * n - w3**2 * u)


def _r_rtr_at(mech, phi, **options):
    solver = LoopSolver(mech, ["A"], **options)
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", np.pi / 2 - phi / 2 + OFFSET)
    mech.set_coordinate(guess, "B_slider", -0.2 * np.sin(phi / 2))
    sol = solver.solve([phi], [1.0], [0.5], guess=guess)
    return sol, evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"], links=["link3"])


def test_the_isosceles_reference_is_the_closed_form():
    """The exact isosceles form against closed_form.r_rtr in extended precision, whose own
    error near phi = 0 grows like eps_longdouble x k^3 (k = 2.5 / phi)."""
    for phi in (1e-1, -1e-2, 1e-3):  # phi < 0: D lies on the far side of C from B (branch -1)
        ref = closed_form.r_rtr(L(phi), L(1), L(0.5), AB=L(0.1), AC=L(0.1), CD=L(0.15), branch=int(np.sign(phi)))
        _, D, vD, aD = _isosceles(phi, 1.0, 0.5)
        bound = float(np.finfo(L).eps) * (2.5 / abs(phi)) ** 3
        assert max(_relative(ref.D, D), _relative(ref.vD, vD), _relative(ref.aD, aD)) <= bound


@pytest.mark.parametrize("phi", [1e-1, -1e-1, 1e-2, -1e-2, 1e-3, -1e-3])
def test_r_rtr_guide_through_its_pivot_approached(ab_equals_ac, phi):
    sol, motion = _r_rtr_at(ab_equals_ac, phi)
    phi3, D, vD, aD = _isosceles(phi, 1.0, 0.5)
    d = motion.points["D"]
    # grows like 1 / phi; 1.0 / phi with the guide's slide measured in sizes of the loop A-B-C (0.1 m)
    assert sol.accuracy.condition == pytest.approx(1.0 / abs(phi), rel=0.05)
    assert sol.accuracy.iterations > 0
    _within_bounds(sol.accuracy, max(_angle_error(motion.links["link3"].angle, phi3), _relative(d.position[:2], D)),
                   _relative(d.velocity[:2], vD), _relative(d.acceleration[:2], aD))


@pytest.mark.parametrize("phi", [4e-5, -4e-5])
def test_r_rtr_too_close_to_its_pivot_is_refused(ab_equals_ac, phi):
    with pytest.raises(SingularPoseError, match=r"condition number 2\.5\d*e\+04 > 1e\+04") as info:
        _r_rtr_at(ab_equals_ac, phi)
    assert info.value.condition == pytest.approx(2.5e4, rel=0.05)


def test_r_rtr_through_its_pivot_is_refused_or_answered_within_bounds(ab_equals_ac):
    """With the limit raised, phi = 4e-5 answers, and its bounds say how little to trust it."""
    sol, motion = _r_rtr_at(ab_equals_ac, 4e-5, max_condition=1e6)
    _, _, _, aD = _isosceles(4e-5, 1.0, 0.5)
    error = _relative(motion.points["D"].acceleration[:2], aD)
    assert error <= sol.accuracy.error_bounds[2]
    assert sol.accuracy.error_bounds[2] > 1e-4  # k^3 eps at k = 2.5e4: no digits to spare


def test_r_rtr_at_its_pivot(ab_equals_ac):
    with pytest.raises((SingularPoseError, LoopClosureError)):
        _r_rtr_at(ab_equals_ac, 0.0)


# ------------------------------------------------------------ four-bar at its limit position
# Non-Grashof four-bar: the crank rocks between +-theta_limit, where coupler and rocker align.
A_, B_, C_, D_ = 0.08, 0.05, 0.06, 0.10
THETA_LIMIT = np.arccos((L(A_) ** 2 + L(D_) ** 2 - (L(B_) + L(C_)) ** 2) / (2 * L(A_) * L(D_)))


@pytest.fixture(scope="module")
def toggle_four_bar(tmp_path_factory):
    return Mechanism.from_urdf(write(tmp_path_factory.mktemp("f"), "fb.urdf", four_bar_urdf(A_, B_, C_, D_)))


def _four_bar_at(mech, theta, **options):
    ref = closed_form.four_bar(L(theta), L(1), L(0.5), L(A_), L(B_), L(C_), L(D_), branch=1)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(ref.theta3) - theta + OFFSET)
    mech.set_coordinate(guess, "O4", float(ref.theta4) - OFFSET)
    solver = LoopSolver(mech, ["O2"], **options)
    sol = solver.solve([theta], [1.0], [0.5], guess=guess)
    return sol, evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["rocker"], points=[]), ref


@pytest.mark.parametrize("delta", [1e-2, 1e-4, 1e-6, 1e-8])
def test_four_bar_limit_position_approached(toggle_four_bar, delta):
    sol, motion, ref = _four_bar_at(toggle_four_bar, float(THETA_LIMIT) - delta)
    rocker = motion.links["rocker"]
    assert sol.accuracy.condition == pytest.approx(0.9 / np.sqrt(delta), rel=0.1)  # grows like delta^-1/2
    _within_bounds(sol.accuracy, _angle_error(rocker.angle, ref.theta4),
                   _relative(rocker.angular_velocity[2], ref.omega4),
                   _relative(rocker.angular_acceleration[2], ref.alpha4))


def test_four_bar_closer_to_its_limit_is_refused(toggle_four_bar):
    with pytest.raises(SingularPoseError) as info:
        _four_bar_at(toggle_four_bar, float(THETA_LIMIT) - 1e-10)
    assert info.value.condition > 1e4


def test_four_bar_past_its_limit_cannot_close(toggle_four_bar):
    with pytest.raises(LoopClosureError, match=r"cannot be closed at O2 = 74\.4\d* deg"):
        LoopSolver(toggle_four_bar, ["O2"]).solve([float(THETA_LIMIT) + 1e-3])


# ----------------------------------------- the bundled four-bar driven by its rocker: dead centres
# Driven from the rocker O4, the crank-rocker of models/four_bar.urdf has two dead centres,
# where crank and coupler line up (stretched: |O2 B| = a + b; folded: b - a). Its reference
# is the four-bar turned half a turn about the middle of O2 O4: there the rocker is the
# crank (length c), and the crank is the rocker (length a); angles are those + pi.
a4, b4, c4, d4 = (L(x) for x in (0.04, 0.12, 0.08, 0.10))


def _rocker_limit(reach):
    return -np.arccos((c4**2 + d4**2 - reach**2) / (2 * c4 * d4))  # the scene's branch: rocker below O4


def _crank_driven_by_rocker(t):
    """Both assemblies of the half-turned four-bar at rocker angle t - pi (t in its frame)."""
    return [closed_form.four_bar(L(t), L(1), L(0.5), c4, b4, a4, d4, branch=b) for b in (1, -1)]


@pytest.fixture(scope="module")
def bundled_four_bar():
    return Mechanism.from_urdf(MODELS / "four_bar.urdf")


@pytest.mark.parametrize("reach, side, growth", [(b4 + a4, +1, 5.0), (b4 - a4, -1, 2.7)], ids=["stretched", "folded"])
@pytest.mark.parametrize("delta", [1e-2, 1e-4, 1e-6])
def test_four_bar_dead_centres_approached_from_the_rocker(bundled_four_bar, reach, side, growth, delta):
    mech = bundled_four_bar
    t = float(_rocker_limit(reach)) + side * delta
    refs = _crank_driven_by_rocker(t)
    guess = mech.neutral()
    mech.set_coordinate(guess, "O2", float(refs[0].theta4 - PI) + OFFSET)
    mech.set_coordinate(guess, "A", float(refs[0].theta3 - refs[0].theta4 + PI))
    solver = LoopSolver(mech, ["O4"])
    sol = solver.solve([t - np.pi], [1.0], [0.5], guess=guess)
    crank = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["crank"], points=[]).links["crank"]
    ref = min(refs, key=lambda r: _angle_error(crank.angle, r.theta4 - PI))  # the assembly it closed on
    assert sol.accuracy.condition == pytest.approx(growth / np.sqrt(delta), rel=0.05)  # like delta^-1/2
    _within_bounds(sol.accuracy, _angle_error(crank.angle, ref.theta4 - PI),
                   _relative(crank.angular_velocity[2], ref.omega4), _relative(crank.angular_acceleration[2], ref.alpha4))


def test_four_bar_rocker_past_its_extreme_cannot_close(bundled_four_bar):
    limit = float(_rocker_limit(b4 + a4)) - np.pi
    with pytest.raises(LoopClosureError, match="cannot be closed at O4"):
        LoopSolver(bundled_four_bar, ["O4"]).solve([limit - 1e-3])


# ------------------------------------ the bundled slider-crank driven by its piston: dead centres
r_, l_, e_ = L(0.05), L(0.15), L(0.01)
X_OUTER, X_INNER = np.sqrt((r_ + l_) ** 2 - e_**2), np.sqrt((l_ - r_) ** 2 - e_**2)


def _crank_angles(x):
    """Both crank angles that put the wrist pin B at (x, e): circle (O, r) meets circle (B, l)."""
    B = np.array([L(x), e_])
    d = np.hypot(B[0], B[1])
    u = B / d
    along = (r_**2 - l_**2 + d**2) / (2 * d)
    across = np.sqrt(max(r_**2 - along**2, L(0)))
    return [np.arctan2(*(along * u + s * across * np.array([-u[1], u[0]]))[::-1]) for s in (1, -1)]


@pytest.fixture(scope="module")
def bundled_slider_crank():
    return Mechanism.from_urdf(MODELS / "slider_crank.urdf")


@pytest.mark.parametrize("x_dead, side, growth", [(X_OUTER, -1, 2.55), (X_INNER, +1, 1.88)], ids=["outer", "inner"])
@pytest.mark.parametrize("delta", [1e-2, 1e-4, 1e-6])
def test_slider_crank_dead_centres_approached_from_the_piston(bundled_slider_crank, x_dead, side, growth, delta):
    """The piston at x, moving at 0.3 m/s, -0.7 m/s^2: the crank turns at omega = v / (dx/dtheta)
    and alpha = (a - x'' omega^2) / x', x' and x'' from closed_form.slider_crank at omega 1."""
    mech = bundled_slider_crank
    x = float(x_dead) + side * delta * 0.2
    theta = _crank_angles(x)[0]
    guess = mech.neutral()
    mech.set_coordinate(guess, "O", float(theta) + OFFSET)
    mech.set_coordinate(guess, "A", float(closed_form.slider_crank(theta, L(1), L(0), r_, l_, e_).beta - theta))
    solver = LoopSolver(mech, ["slide"])
    sol = solver.solve([x], [0.3], [-0.7], guess=guess)
    crank = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["crank"], points=[]).links["crank"]
    theta = min(_crank_angles(x), key=lambda th: _angle_error(crank.angle, th))  # the assembly it closed on
    per_turn = closed_form.slider_crank(theta, L(1), L(0), r_, l_, e_)
    omega = L(0.3) / per_turn.v_B
    alpha = (L(-0.7) - per_turn.a_B * omega**2) / per_turn.v_B
    assert sol.accuracy.condition == pytest.approx(growth / np.sqrt(delta), rel=0.05)  # like delta^-1/2
    _within_bounds(sol.accuracy, _angle_error(crank.angle, theta), _relative(crank.angular_velocity[2], omega),
                   _relative(crank.angular_acceleration[2], alpha))


def test_slider_crank_piston_past_its_stroke_cannot_close(bundled_slider_crank):
    with pytest.raises(LoopClosureError, match=r"cannot be closed at slide = 0\.1998\d* m"):
        LoopSolver(bundled_slider_crank, ["slide"]).solve([float(X_OUTER) + 1e-4])


# ------------------------------------------------------------- planar arm, stretched and folded
def _arm_tasks():
    return [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]


@pytest.mark.parametrize("bend", [1e-1, 1e-2, 1e-3, np.pi - 1e-1, np.pi - 1e-2, np.pi - 1e-3])
def test_planar_arm_near_stretched_and_folded(models_dir, bend):
    """D at (1, 0) m/s, CD not turning; AB at 0.5 rad, BC bent by `bend` from it. An open arm
    has no loop to close: its rates are right to 2 k eps (k grows like 1 / bend^2 here:
    the wz row and D's rows meet at C)."""
    arm = Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    q = arm.neutral()
    angles = (0.5, bend, -np.pi / 2 - 0.5 - bend)
    for name, angle in zip("ABC", angles):
        arm.set_coordinate(q, name, angle)
    sol = RateSolver(arm, _arm_tasks(), max_condition=1e6).solve(q)
    th1 = L(angles[0])
    ref = closed_form.planar_arm_rates(th1, th1 + L(angles[1]), th1 + L(angles[1]) + L(angles[2]), L(0.3), L(0.3),
                                       L(0.17), np.array([L(1), L(0)]), np.array([L(0), L(0)]))
    bound = 2 * EPS * sol.condition
    assert _relative(sol.v, ref.q_dot) <= bound and _relative(sol.a, ref.q_ddot) <= bound


def test_planar_arm_stretched_is_refused(models_dir):
    arm = Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    q = arm.neutral()
    arm.set_coordinate(q, "C", -np.pi / 2)
    with pytest.raises(SingularPoseError, match="A = 0 deg, B = 0 deg, C = -90 deg"):
        RateSolver(arm, _arm_tasks()).solve(q)


# ------------------------------------------------------------------- what the report shows
def test_the_report_shows_the_condition_number_and_the_bounds(scenes_dir, capsys):
    """The bundled four-bar driven from its rocker 1e-4 rad before its stretched dead centre."""
    import json

    from pinmech.cli import main

    t = float(_rocker_limit(b4 + a4)) + 1e-4
    ref = _crank_driven_by_rocker(t)[0]
    drivers = f'drivers={{O4={{angle="{t - np.pi!r} rad", speed="1 rad/s"}}}}'
    guess = f'guess={{O2="{float(ref.theta4 - PI)!r} rad", A="{float(ref.theta3 - ref.theta4 + PI)!r} rad"}}'
    assert main(["solve", str(scenes_dir / "four_bar.toml"), "--json", "--set", drivers, "--set", guess]) == 0
    accuracy = json.loads(capsys.readouterr().out)["accuracy"]
    k, m = accuracy["condition_number"], max(accuracy["closure_residual"], EPS)
    assert k == pytest.approx(5.0 / np.sqrt(1e-4), rel=0.05)
    assert accuracy["relative_error_bound_velocity"] == pytest.approx(4 * k**2 * m)
    assert accuracy["relative_error_bound_acceleration"] == pytest.approx(16 * k**3 * m)
    assert accuracy["estimated_relative_error"] == accuracy["relative_error_bound_acceleration"]


# ---------------------------------------------------------------------- internal signals never leave pinmech
def _parallelogram_at(tmp_path, theta: float, max_condition: float):
    """The parallelogram a = c = 50 mm, b = d = 100 mm closed on its parallelogram branch
    at crank angle theta (coupler parallel to the ground: A's coordinate -theta, rocker
    theta), as the solver's reference. At theta = 0 its two branches cross: the
    dependent Jacobian's condition number grows as 1/theta."""
    mech = Mechanism.from_urdf(write(tmp_path, "pg.urdf", four_bar_urdf(0.05, 0.1, 0.05, 0.1)))
    q = mech.neutral()
    for name, value in (("O2", theta), ("A", -theta), ("O4", theta)):
        mech.set_coordinate(q, name, value)
    solver = LoopSolver(mech, ["O2"], max_condition=max_condition)
    return mech, solver, solver.set_reference([theta], q)


def test_a_reference_on_a_crossing_under_a_raised_max_condition_is_a_singular_pose_error(tmp_path):
    """Issue 22 item 13: with max_condition = 1e15 (allowed), a reference 1e-11 rad from the
    parallelogram's crossing (condition number about 1e11, above the 1e10 where a path's
    tangent is noise) let continuation's internal signal out, with no message. Now:
    SingularPoseError naming the pose and its condition number, from solve and from a sweep."""
    from pinmech.solve.cycle import solve_range

    _, solver, _ = _parallelogram_at(tmp_path, 1e-11, 1e15)
    with pytest.raises(SingularPoseError, match=r"O2 = .*condition number") as info:
        solver.solve([0.5])
    assert info.value.condition > 1e10
    chunks = solve_range(solver, "O2", [0.3, 0.5], driver_q=np.zeros(1), driver_v=np.ones(1), driver_a=np.zeros(1))
    try:
        errors = [e for c in chunks for e in c.errors.values()]
    except SingularPoseError as exc:
        errors = [exc]
    assert errors and all(isinstance(e, SingularPoseError) and str(e) for e in errors)


def test_the_reference_the_api_returns_cannot_be_written_into(tmp_path):
    """Issue 22 item 13: writing into `Reference.q` corrupted the solver's reference (the
    next solve raised an internal signal with an empty message). Its arrays are read-only;
    the solver then still answers the closed form: on the parallelogram branch the rocker
    turns with the crank (theta4 = theta2), to 1e-12 rad (closed to 1e-13, condition ~5)."""
    mech, solver, ref = _parallelogram_at(tmp_path, 1.0, 1e4)
    for array in (ref.q, ref.driver_q):
        with pytest.raises(ValueError, match="read-only"):
            array[:] = 0.0
    np.testing.assert_allclose(mech.coordinate(solver.solve([1.3]).q, "O4"), 1.3, rtol=0, atol=closure(np.pi, REGULAR))
