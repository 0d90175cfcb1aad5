"""Planar dynamic force analysis by hand (Norton's matrix method), in pure numpy.

The independent reference for pinmech's forces (tests/test_forces.py, tests/test_cut_forces.py)
for the slider-crank, the four-bar and the crank-and-slotted-lever (R-RTR): the kinematics
come from the vector-loop closed forms of closed_form.py, and the forces from Newton's
and Euler's laws written for each link separately, F = m a_G and M_G = I_G alpha, with
one unknown per pin force component, the slider's normal force and moment and the driver
torque: a 9 x 9 linear system per pose, as Norton (Design of Machinery, ch. 11) and
Shigley (Theory of Machines and Mechanisms, ch. 15) set it up. No Pinocchio, no joint
space, no constraint Jacobian.

Notation: F_ij is the force link i exerts on link j (1 = ground, 2 = crank, 3 = coupler or
connecting rod, 4 = rocker or piston; for the R-RTR 2 = crank, 3 = block, 4 = guide);
vectors are (x, y) in the world frame; moments and angular quantities are their z
components.

Run: python scripts/closed_form_forces.py   (the slider-crank of models/slider_crank_dynamic.urdf)
"""

from __future__ import annotations

from dataclasses import dataclass

import closed_form as cf
import numpy as np


@dataclass(frozen=True)
class Body:
    """A link's mass [kg], moment of inertia about its centre of mass [kg m^2], and centre
    of mass (x, y) [m] in the link's frame (x axis along the link)."""

    m: float
    I: float
    com: tuple[float, float]

    def g_offset(self, angle: float) -> np.ndarray:
        """The centre of mass from the link's origin, world frame [m]."""
        c, s = np.cos(angle), np.sin(angle)
        return np.array([c * self.com[0] - s * self.com[1], s * self.com[0] + c * self.com[1]])


def _accel(a_origin: np.ndarray, alpha: float, omega: float, rho: np.ndarray) -> np.ndarray:
    """a_origin + alpha k x rho - omega^2 rho: acceleration of a point of a rigid link."""
    return a_origin + alpha * cf.perp(rho) - omega**2 * rho


def _cross_row(r: np.ndarray) -> np.ndarray:
    """Coefficients (of F_x, F_y) of the moment r x F."""
    return np.array([-r[1], r[0]])


class _Equations:
    """Three rows (sum F_x, sum F_y, sum M_G) per link, columns per unknown."""

    def __init__(self, links: int, unknowns: int) -> None:
        self.A = np.zeros((3 * links, unknowns))
        self.b = np.zeros(3 * links)

    def force(self, link: int, col: int, at: np.ndarray, sign: float = 1.0) -> None:
        """Unknown force components (col, col + 1) acting on `link` at `at` (relative to G)."""
        self.A[3 * link, col] += sign
        self.A[3 * link + 1, col + 1] += sign
        self.A[3 * link + 2, col : col + 2] += sign * _cross_row(at)

    def known(self, link: int, m: float, a_g: np.ndarray, I: float, alpha: float, applied: np.ndarray,
              at: np.ndarray, couple: float = 0.0) -> None:
        """Right side: m a_G - applied known forces; I alpha - their moments about G."""
        self.b[3 * link : 3 * link + 2] = m * a_g - applied
        self.b[3 * link + 2] = I * alpha - float(_cross_row(at) @ applied) - couple

    def solve(self) -> np.ndarray:
        return np.linalg.solve(self.A, self.b)


@dataclass(frozen=True)
class SliderCrankForces:
    """Driver torque T [N m] on the crank, pin forces [N], and the piston's normal force
    N14 [N] (along y) and moment M14 [N m] about B from the guide."""

    T: float
    F12: np.ndarray
    F23: np.ndarray
    F34: np.ndarray
    N14: float
    M14: float


def slider_crank_forces(theta: float, omega: float, alpha: float, r: float, l: float, e: float,
                        crank: Body, rod: Body, piston: Body, gravity=(0.0, 0.0),
                        load_B=(0.0, 0.0)) -> SliderCrankForces:
    """Inverse dynamics of the offset slider-crank (piston to the right, on y = e).

    Args:
        theta, omega, alpha: crank angle [rad], rate [rad/s], acceleration [rad/s^2].
        gravity: (g_x, g_y) [m/s^2]. load_B: a force on the piston at B [N].
    """
    k = cf.slider_crank(theta, omega, alpha, r, l, e)
    beta, w3, a3 = float(k.beta), float(k.omega_rod), float(k.alpha_rod)
    A, B = np.asarray(k.A, float), np.asarray(k.B, float)
    g = np.asarray(gravity, float)
    rho2, rho3, rho4 = crank.g_offset(theta), rod.g_offset(beta), piston.g_offset(0.0)
    aA = _accel(np.zeros(2), alpha, omega, A)
    aG2 = _accel(np.zeros(2), alpha, omega, rho2)
    aG3 = _accel(aA, a3, w3, rho3)
    aG4 = np.array([float(k.a_B), 0.0])  # the piston translates
    G2, G3, G4 = rho2, A + rho3, B + rho4
    eq = _Equations(3, 9)  # unknowns: F12 (0, 1), F23 (2, 3), F34 (4, 5), N14 (6), M14 (7), T (8)
    eq.force(0, 0, -G2)
    eq.force(0, 2, A - G2, -1.0)
    eq.A[2, 8] = 1.0
    eq.known(0, crank.m, aG2, crank.I, alpha, crank.m * g, np.zeros(2))
    eq.force(1, 2, A - G3)
    eq.force(1, 4, B - G3, -1.0)
    eq.known(1, rod.m, aG3, rod.I, a3, rod.m * g, np.zeros(2))
    eq.force(2, 4, B - G4)
    eq.A[7, 6] = 1.0                       # N14 along y, through B
    eq.A[8, 6] = float(_cross_row(B - G4)[1])
    eq.A[8, 7] = 1.0
    load = np.asarray(load_B, float)
    eq.b[6:8] = piston.m * aG4 - piston.m * g - load
    eq.b[8] = -float(_cross_row(B - G4) @ load)  # the piston does not turn; its weight acts at G4
    x = eq.solve()
    return SliderCrankForces(float(x[8]), x[0:2], x[2:4], x[4:6], float(x[6]), float(x[7]))


@dataclass(frozen=True)
class FourBarForces:
    """Driver torque T [N m] on the crank and the four pin forces [N]."""

    T: float
    F12: np.ndarray
    F23: np.ndarray
    F34: np.ndarray
    F14: np.ndarray


def four_bar_forces(theta2: float, omega2: float, alpha2: float, a: float, b: float, c: float, d: float,
                    crank: Body, coupler: Body, rocker: Body, gravity=(0.0, 0.0), rocker_torque: float = 0.0,
                    branch: int = +1) -> FourBarForces:
    """Inverse dynamics of the four-bar O2-A-B-O4 (O2 = (0, 0), O4 = (d, 0)), with a torque
    `rocker_torque` [N m] (z) applied to the rocker."""
    k = cf.four_bar(theta2, omega2, alpha2, a, b, c, d, branch)
    t3, t4 = float(k.theta3), float(k.theta4)
    w3, w4, a3, a4 = (float(x) for x in (k.omega3, k.omega4, k.alpha3, k.alpha4))
    A, B, O4 = np.asarray(k.A, float), np.asarray(k.B, float), np.array([d, 0.0])
    g = np.asarray(gravity, float)
    rho2, rho3, rho4 = crank.g_offset(theta2), coupler.g_offset(t3), rocker.g_offset(t4)
    aA = np.asarray(k.aA, float)
    aG2 = _accel(np.zeros(2), alpha2, omega2, rho2)
    aG3 = _accel(aA, a3, w3, rho3)
    aG4 = _accel(np.zeros(2), a4, w4, rho4)
    G2, G3, G4 = rho2, A + rho3, O4 + rho4
    eq = _Equations(3, 9)  # unknowns: F12 (0, 1), F23 (2, 3), F34 (4, 5), F14 (6, 7), T (8)
    eq.force(0, 0, -G2)
    eq.force(0, 2, A - G2, -1.0)
    eq.A[2, 8] = 1.0
    eq.known(0, crank.m, aG2, crank.I, alpha2, crank.m * g, np.zeros(2))
    eq.force(1, 2, A - G3)
    eq.force(1, 4, B - G3, -1.0)
    eq.known(1, coupler.m, aG3, coupler.I, a3, coupler.m * g, np.zeros(2))
    eq.force(2, 4, B - G4)
    eq.force(2, 6, O4 - G4)
    eq.known(2, rocker.m, aG4, rocker.I, a4, rocker.m * g, np.zeros(2), couple=rocker_torque)
    x = eq.solve()
    return FourBarForces(float(x[8]), x[0:2], x[2:4], x[4:6], x[6:8])


@dataclass(frozen=True)
class RRTRForces:
    """Driver torque T [N m] on the crank, the pin forces F12 (ground on crank at A), F23
    (crank on block at B) and F14 (ground on guide at C) [N], and the block's push on the
    guide: N34 [N] along n = k x u (u from C towards B) and the moment M34 [N m] about B."""

    T: float
    F12: np.ndarray
    F23: np.ndarray
    F14: np.ndarray
    N34: float
    M34: float


def r_rtr_forces(phi: float, omega1: float, alpha1: float, crank: Body, block: Body, guide: Body,
                 AB: float = 0.10, AC: float = 0.05, gravity=(0.0, 0.0)) -> RRTRForces:
    """Inverse dynamics of the R-RTR (crank-and-slotted-lever) of closed_form.r_rtr: the
    crank AB about A, its pin B carrying a block that slides along the guide, which turns
    about C. The block turns with the guide; their contact is a normal force and a moment
    (no friction), unknown at B.

    Args:
        phi, omega1, alpha1: crank angle [rad], rate [rad/s], acceleration [rad/s^2].
        crank, block, guide: the bodies, in frames at A, B and C with x along A -> B,
            along u and along u.
        gravity: (g_x, g_y) [m/s^2].
    """
    k = cf.r_rtr(phi, omega1, alpha1, AB=AB, AC=AC)
    phi3, w3, a3 = float(k.phi3), float(k.omega3), float(k.alpha3)
    B, C, u = np.asarray(k.B, float), np.array([AC, 0.0]), np.asarray(k.u, float)
    n = cf.perp(u)
    g = np.asarray(gravity, float)
    rho1, rho2, rho3 = crank.g_offset(phi), block.g_offset(phi3), guide.g_offset(phi3)
    G1, G2, G3 = rho1, B + rho2, C + rho3
    aG1 = _accel(np.zeros(2), alpha1, omega1, rho1)
    aG2 = _accel(np.asarray(k.aB, float), a3, w3, rho2)  # the block is carried by the crank pin B
    aG3 = _accel(np.zeros(2), a3, w3, rho3)
    eq = _Equations(3, 9)  # unknowns: F12 (0, 1), F23 (2, 3), N34 (4), M34 (5), F14 (6, 7), T (8)
    eq.force(0, 0, -G1)
    eq.force(0, 2, B - G1, -1.0)
    eq.A[2, 8] = 1.0
    eq.known(0, crank.m, aG1, crank.I, alpha1, crank.m * g, np.zeros(2))
    eq.force(1, 2, B - G2)
    for link, sign, G in ((1, -1.0, G2), (2, 1.0, G3)):  # the block's push on the guide, and back
        eq.A[3 * link : 3 * link + 2, 4] += sign * n
        eq.A[3 * link + 2, 4] += sign * float(_cross_row(B - G) @ n)
        eq.A[3 * link + 2, 5] += sign
    eq.known(1, block.m, aG2, block.I, a3, block.m * g, np.zeros(2))
    eq.force(2, 6, C - G3)
    eq.known(2, guide.m, aG3, guide.I, a3, guide.m * g, np.zeros(2))
    x = eq.solve()
    return RRTRForces(float(x[8]), x[0:2], x[2:4], x[6:8], float(x[4]), float(x[5]))


#: The bodies of models/slider_crank_dynamic.urdf and models/four_bar_dynamic.urdf.
SLIDER_CRANK_BODIES = (Body(0.4, 2e-4, (0.02, 0.0)), Body(0.6, 1.5e-3, (0.06, 0.0)), Body(0.5, 1e-4, (0.0, 0.0)))
FOUR_BAR_BODIES = (Body(0.1, 2e-5, (0.02, 0.0)), Body(0.3, 4e-4, (0.06, 0.015)), Body(0.2, 1.1e-4, (0.04, 0.0)))


def main() -> None:
    """Print the slider-crank of models/scenes/slider_crank_dynamic.toml at its pose."""
    f = slider_crank_forces(np.radians(45.0), 3000 * np.pi / 30, 0.0, 0.05, 0.15, 0.01, *SLIDER_CRANK_BODIES,
                            gravity=(0.0, -9.81), load_B=(-200.0, 0.0))
    print("slider-crank at 45 deg, 3000 rpm, g = 9.81 m/s^2 down, 200 N on the piston")
    print(f"  crank torque T = {f.T:.6g} N m")
    for name in ("F12", "F23", "F34"):
        print(f"  {name} = {np.array2string(getattr(f, name), precision=6)} N")
    print(f"  N14 = {f.N14:.6g} N, M14 = {f.M14:.6g} N m")


if __name__ == "__main__":
    main()
