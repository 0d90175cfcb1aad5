"""Worked example: the R-RTR mechanism of Problem Chapter I.9 through the Python API.

Loads the URDF with its loop cut, drives the crank at -50 rpm, solves one pose, and
prints the quantities the textbook computes by hand; then turns the crank through a few
angles with one solver, warm-starting each pose from the previous one.

Run: python scripts/r_rtr_example.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import pinmech

MODEL = Path(__file__).resolve().parents[1] / "models" / "r_rtr.urdf"


def main() -> None:
    mech = pinmech.Mechanism.from_urdf(MODEL)
    print(f"{mech.source}: {mech.model.nv} joint freedoms, {mech.constraint_rows} closure rows, "
          f"mobility {mech.mobility}, plane normal {mech.plane_normal}")
    solver = pinmech.LoopSolver(mech, drivers=["A"])
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", np.radians(20))  # link 3 from C through B towards D
    mech.set_coordinate(guess, "B_slider", -0.06)

    omega1 = -50 * np.pi / 30  # -50 rpm in rad/s
    sol = solver.solve([np.radians(30)], [omega1], [0.0], guess=guess)
    b3 = pinmech.CoincidentPoint("B3", at="B", link="link3")
    motion = pinmech.evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, coincident=[b3])
    link3 = motion.links["link3"]
    slider = motion.sliders["B_slider"]
    print(f"phi3   = {np.degrees(link3.angle):.6f} deg")
    print(f"omega3 = {link3.angular_velocity[2]:.6f} rad/s,  alpha3 = {link3.angular_acceleration[2]:.6f} rad/s^2")
    print(f"v_D    = {motion.points['D'].velocity[:2]} m/s")
    print(f"a_D    = {motion.points['D'].acceleration[:2]} m/s^2")
    print(f"v_B32  = {slider.relative_velocity[:2]} m/s,  Coriolis = {slider.coriolis_acceleration[:2]} m/s^2")
    print(f"accuracy: {sol.accuracy}")

    print("\n crank [deg]   phi3 [deg]   omega3 [rad/s]   |v_D| [m/s]")
    q = sol.q
    for phi in range(0, 360, 45):
        sol = solver.solve([np.radians(phi)], [omega1], [0.0], guess=q)
        q = sol.q
        m = pinmech.evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"])
        print(f"{phi:12d} {np.degrees(m.links['link3'].angle):12.4f} "
              f"{m.links['link3'].angular_velocity[2]:16.6f} {np.linalg.norm(m.points['D'].velocity):13.6f}")


if __name__ == "__main__":
    main()
