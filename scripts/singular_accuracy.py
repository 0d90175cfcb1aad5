"""How accurate pinmech is near singular poses: the errors it makes against the condition number.

For five approaches to a singularity (tests/test_singular.py checks the same ones against
the bounds), print the condition number k pinmech reports, the closure residual r it left,
and its relative errors in positions, velocities and accelerations against closed forms
evaluated in np.longdouble; then each error divided by its law, with m = max(r, eps):
position / (k m), velocity / (k^2 m), acceleration / (k^2 m) and / (k^3 m). Each guess
starts 1e-3 rad off the answer, as a sweep's previous pose would.

Run: python scripts/singular_accuracy.py        (a Markdown table, a few seconds)
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import closed_form

from pinmech import LoopSolver, Mechanism, evaluate_motion
from pinmech.solve.rates import RateSolver, Task

L = np.longdouble
PI = L("3.14159265358979323846264338327950288")
EPS = 2.2e-16
MODELS = Path(__file__).resolve().parents[1] / "models"


def _rel(x, ref) -> float:
    ref = np.asarray(ref, dtype=L)
    return float(np.max(np.abs(np.asarray(x, dtype=L) - ref)) / np.max(np.abs(ref)))


def _ang(x, ref) -> float:
    return abs(float((L(x) - ref + PI) % (2 * PI) - PI))


def _load(name: str, text: str | None = None) -> Mechanism:
    if text is None:
        return Mechanism.from_urdf(MODELS / name)
    path = Path(tempfile.gettempdir()) / f"pinmech_singular_{name}"
    path.write_text(text)
    return Mechanism.from_urdf(path)


def r_rtr_pivot(phi: float):
    """R-RTR with AB = AC: link 3 at 90 deg + phi / 2 exactly, omega_3 = omega_1 / 2."""
    mech = _load("r_rtr_ab_ac.urdf", (MODELS / "r_rtr.urdf").read_text().replace(
        '<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="0.10 0 0"'))
    solver = LoopSolver(mech, ["A"], max_condition=1e30)
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", np.pi / 2 - phi / 2 + 1e-3)
    mech.set_coordinate(guess, "B_slider", -0.2 * np.sin(phi / 2))
    sol = solver.solve([phi], [1.0], [0.5], guess=guess)
    m = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"], links=["link3"])
    phi3, w3, a3 = PI / 2 + L(phi) / 2, L(0.5), L(0.25)
    u, n = np.array([np.cos(phi3), np.sin(phi3)]), np.array([-np.sin(phi3), np.cos(phi3)])
    d = m.points["D"]
    return sol, _ang(m.links["link3"].angle, phi3), _rel(d.velocity[:2], L(0.15) * w3 * n), \
        _rel(d.acceleration[:2], L(0.15) * (a3 * n - w3**2 * u))


def four_bar_limit(delta: float):
    """Non-Grashof four-bar (0.08, 0.05, 0.06, 0.10): crank delta before its limit angle."""
    a, b, c, d = 0.08, 0.05, 0.06, 0.10
    mech = _load("four_bar_limit.urdf", _four_bar_text(a, b, c, d))
    theta = float(np.arccos((L(a) ** 2 + L(d) ** 2 - (L(b) + L(c)) ** 2) / (2 * L(a) * L(d)))) - delta
    ref = closed_form.four_bar(L(theta), L(1), L(0.5), L(a), L(b), L(c), L(d), branch=1)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(ref.theta3) - theta + 1e-3)
    mech.set_coordinate(guess, "O4", float(ref.theta4) - 1e-3)
    solver = LoopSolver(mech, ["O2"], max_condition=1e30)
    sol = solver.solve([theta], [1.0], [0.5], guess=guess)
    rocker = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["rocker"], points=[]).links["rocker"]
    return sol, _ang(rocker.angle, ref.theta4), _rel(rocker.angular_velocity[2], ref.omega4), \
        _rel(rocker.angular_acceleration[2], ref.alpha4)


def _four_bar_text(a: float, b: float, c: float, d: float) -> str:
    link = '<link name="{0}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>' \
           '</inertial></link>'
    joint = '<joint name="{0}" type="continuous"><parent link="{1}"/><child link="{2}"/><origin xyz="{3} 0 0"/>' \
            '<axis xyz="0 0 1"/></joint>'
    return (f'<robot name="fb"><link name="ground"/>{"".join(link.format(n) for n in ("crank", "coupler", "rocker"))}'
            f'{joint.format("O2", "ground", "crank", 0)}{joint.format("A", "crank", "coupler", a)}'
            f'{joint.format("O4", "ground", "rocker", d)}<constraint name="B" type="revolute">'
            f'<parent link="coupler"/><parent_origin xyz="{b} 0 0"/><child link="rocker"/>'
            f'<child_origin xyz="{c} 0 0"/></constraint></robot>')


def four_bar_dead_centre(delta: float, stretched: bool = True):
    """models/four_bar.urdf driven from its rocker, delta before a dead centre."""
    mech = _load("four_bar.urdf")
    a, b, c, d = (L(x) for x in (0.04, 0.12, 0.08, 0.10))
    reach = b + a if stretched else b - a
    t = float(-np.arccos((c**2 + d**2 - reach**2) / (2 * c * d))) + (delta if stretched else -delta)
    refs = [closed_form.four_bar(L(t), L(1), L(0.5), c, b, a, d, branch=s) for s in (1, -1)]
    guess = mech.neutral()
    mech.set_coordinate(guess, "O2", float(refs[0].theta4 - PI) + 1e-3)
    mech.set_coordinate(guess, "A", float(refs[0].theta3 - refs[0].theta4 + PI))
    solver = LoopSolver(mech, ["O4"], max_condition=1e30)
    sol = solver.solve([t - np.pi], [1.0], [0.5], guess=guess)
    crank = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["crank"], points=[]).links["crank"]
    ref = min(refs, key=lambda r: _ang(crank.angle, r.theta4 - PI))
    return sol, _ang(crank.angle, ref.theta4 - PI), _rel(crank.angular_velocity[2], ref.omega4), \
        _rel(crank.angular_acceleration[2], ref.alpha4)


def slider_crank_dead_centre(delta: float, outer: bool = True):
    """models/slider_crank.urdf driven from its piston, delta x 0.2 m before a dead centre."""
    mech = _load("slider_crank.urdf")
    r, l, e = L(0.05), L(0.15), L(0.01)
    x_dead = np.sqrt((r + l) ** 2 - e**2) if outer else np.sqrt((l - r) ** 2 - e**2)
    x = float(x_dead) + (-1 if outer else 1) * delta * 0.2

    def crank_angles():
        B = np.array([L(x), e])
        dist = np.hypot(B[0], B[1])
        u = B / dist
        along = (r**2 - l**2 + dist**2) / (2 * dist)
        across = np.sqrt(max(r**2 - along**2, L(0)))
        return [np.arctan2(*(along * u + s * across * np.array([-u[1], u[0]]))[::-1]) for s in (1, -1)]

    theta = crank_angles()[0]
    guess = mech.neutral()
    mech.set_coordinate(guess, "O", float(theta) + 1e-3)
    mech.set_coordinate(guess, "A", float(closed_form.slider_crank(theta, L(1), L(0), r, l, e).beta - theta))
    solver = LoopSolver(mech, ["slide"], max_condition=1e30)
    sol = solver.solve([x], [0.3], [-0.7], guess=guess)
    crank = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, links=["crank"], points=[]).links["crank"]
    theta = min(crank_angles(), key=lambda th: _ang(crank.angle, th))
    turn = closed_form.slider_crank(theta, L(1), L(0), r, l, e)
    omega = L(0.3) / turn.v_B
    alpha = (L(-0.7) - turn.a_B * omega**2) / turn.v_B
    return sol, _ang(crank.angle, theta), _rel(crank.angular_velocity[2], omega), \
        _rel(crank.angular_acceleration[2], alpha)


def arm_stretched(bend: float):
    """Text 17.110's arm, BC bent by `bend` from AB (0 stretched, pi folded); an open chain."""
    arm = _load("planar_arm.urdf")
    q = arm.neutral()
    angles = (0.5, bend, -np.pi / 2 - 0.5 - bend)
    for name, angle in zip("ABC", angles):
        arm.set_coordinate(q, name, angle)
    tasks = [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    sol = RateSolver(arm, tasks, max_condition=1e30).solve(q)
    th1 = L(angles[0])
    ref = closed_form.planar_arm_rates(th1, th1 + L(bend), th1 + L(bend) + L(angles[2]), L(0.3), L(0.3), L(0.17),
                                       np.array([L(1), L(0)]), np.array([L(0), L(0)]))
    return sol, 0.0, _rel(sol.v, ref.q_dot), _rel(sol.a, ref.q_ddot)


CASES = [
    ("R-RTR, B through C (AB = AC)", "phi", r_rtr_pivot, [1e-1, 1e-2, 1e-3, 1e-4, 1e-5]),
    ("four-bar, crank at its limit", "delta", four_bar_limit, [1e-2, 1e-4, 1e-6, 1e-8, 1e-10]),
    ("four-bar from its rocker, dead centre", "delta", four_bar_dead_centre, [1e-2, 1e-4, 1e-6, 1e-8]),
    ("slider-crank from its piston, dead centre", "delta", slider_crank_dead_centre, [1e-2, 1e-4, 1e-6, 1e-8]),
    ("planar arm nearly stretched", "bend", arm_stretched, [1e-1, 1e-2, 1e-3, 1e-4, 1e-6]),
]


def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    print("| mechanism | distance | k | residual r | position error | velocity error | acceleration error |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    worst: dict[str, list[float]] = {}
    for label, variable, case, distances in CASES:
        for distance in distances:
            sol, pos, vel, acc = case(distance)
            accuracy = getattr(sol, "accuracy", None)  # a LoopSolution, or the arm's RateSolution
            k = accuracy.condition if accuracy else sol.condition
            r = accuracy.residual if accuracy else 0.0
            m = max(r, EPS)
            print(f"| {label} | {variable} = {distance:.0e} | {k:.3g} | {r:.1e} | "
                  f"{pos:.1e} | {vel:.1e} | {acc:.1e} |" if accuracy else
                  f"| {label} | {variable} = {distance:.0e} | {k:.3g} | - | - | {vel:.1e} | {acc:.1e} |")
            ratios = [pos / (k * m), vel / (k * m), vel / (k * k * m), acc / (k * m), acc / (k * k * m),
                      acc / (k**3 * m)]
            worst[label] = [max(a, b) for a, b in zip(worst.get(label, ratios), ratios)]
    print("\nLargest error / law, m = max(r, eps):\n")
    print("| mechanism | position / (k m) | velocity / (k m) | velocity / (k^2 m) | acceleration / (k m) "
          "| acceleration / (k^2 m) | acceleration / (k^3 m) |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for label, ratios in worst.items():
        print(f"| {label} | " + " | ".join(f"{x:.2g}" for x in ratios) + " |")


if __name__ == "__main__":
    main()
