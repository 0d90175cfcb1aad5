"""Closed-form (vector-loop) kinematics of four planar mechanisms, in pure numpy.

This is the independent reference the Pinocchio-based solver is tested and benchmarked
against: every position comes from elementary geometry (a circle intersection or a square
root) and every velocity and acceleration from the vector loop differentiated by hand and
projected on two orthogonal directions (Cramer's rule written out), with no Pinocchio,
no linear solver and no finite differences. All functions broadcast over arrays of input
angles, so a whole 3600-pose cycle is one call.

Conventions: planar vectors have a last axis of length 2 (x, y); angles are in radians,
counter-clockwise positive about +z; an angular velocity or acceleration is its scalar z
component. ``k x v`` is the planar cross product of +z with v, i.e. (-v_y, v_x).

Mechanisms: the R-RTR of Problem Chapter I.9 (crank, slider block, rocker), the four-bar
linkage, the offset slider-crank and the planar 3R arm of text problem 17.110.

Run: python scripts/closed_form.py   (prints the R-RTR at the textbook pose)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


def _real(x: ArrayLike) -> Array:
    """x as a float array: float64, or np.longdouble when given in extended precision.

    Keeping np.longdouble lets a test evaluate these formulas with an epsilon of 1e-19
    (x86-64), a reference that does not share float64's rounding near a singular pose.
    """
    x = np.asarray(x)
    return x.astype(np.result_type(x.dtype, np.float64), copy=False)


def unit(angle: ArrayLike) -> Array:
    """Unit vector (cos angle, sin angle); last axis of length 2."""
    angle = _real(angle)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def perp(v: Array) -> Array:
    """k x v: v turned by +90 deg about +z."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def dot(v: Array, w: Array) -> Array:
    """Dot product over the last axis."""
    return np.sum(v * w, axis=-1)


def _vec(scalar: Array) -> Array:
    """Append an axis so a scalar field multiplies a field of vectors."""
    return np.asarray(scalar)[..., None]


# --------------------------------------------------------------------------- R-RTR

@dataclass(frozen=True)
class RRTR:
    """R-RTR pose, velocities and accelerations [m, rad, s]; vectors have shape (..., 2).

    ``vB``/``aB`` belong to the crank pin B (= slider point B2); ``vB3``/``aB3`` to the
    point B3 of link 3 under B; ``v_rel``/``a_rel`` to B3 relative to the slider block
    (along u); ``coriolis`` = 2 omega3 k x v_rel.
    """

    B: Array
    D: Array
    u: Array
    phi3: Array
    omega3: Array
    alpha3: Array
    s: Array
    s_dot: Array
    s_ddot: Array
    vB: Array
    aB: Array
    vB3: Array
    aB3: Array
    vD: Array
    aD: Array
    v_rel: Array
    a_rel: Array
    coriolis: Array


def r_rtr_closes(AB: float, AC: float, phi: ArrayLike) -> Array:
    """Whether the R-RTR loop is defined: True unless the crank pin B lies on C.

    Args:
        AB: crank length [m].
        AC: distance of the fixed joint C from A along +x [m].
        phi: crank angle(s) [rad].
    """
    rel = AB * unit(phi) - np.array([AC, 0.0])
    return np.hypot(rel[..., 0], rel[..., 1]) > 0.0


def r_rtr(phi: ArrayLike, omega1: ArrayLike, alpha1: ArrayLike, AB: float = 0.10,
          AC: float = 0.05, CD: float = 0.15, branch: int = +1) -> RRTR:
    """R-RTR kinematics from the loop B - C = s u with u = (cos phi3, sin phi3).

    Differentiating once and projecting on u and on n = k x u:
    ``s_dot = vB.u``, ``omega3 = vB.n / s``; twice:
    ``s_ddot = aB.u + s omega3^2``, ``alpha3 = (aB.n - 2 s_dot omega3) / s``.

    Args:
        phi: crank angle [rad].
        omega1: crank angular velocity [rad/s].
        alpha1: crank angular acceleration [rad/s^2].
        AB: crank length [m].
        AC: x coordinate of the fixed joint C [m].
        CD: distance from C to the point D of link 3 [m].
        branch: +1 when D lies beyond B seen from C (the textbook), -1 for the other way.

    Raises:
        ValueError: where B coincides with C (link 3's direction is undefined).
    """
    phi, omega1, alpha1 = np.broadcast_arrays(*(_real(x)
                                                for x in (phi, omega1, alpha1)))
    if not np.all(r_rtr_closes(AB, AC, phi)):
        raise ValueError(f"R-RTR singular: crank pin B lies on C (AB={AB}, AC={AC})")
    e1 = unit(phi)
    B = AB * e1
    vB = AB * _vec(omega1) * perp(e1)
    aB = AB * (_vec(alpha1) * perp(e1) - _vec(omega1**2) * e1)
    rel = B - np.array([AC, 0.0])
    u = branch * rel / _vec(np.hypot(rel[..., 0], rel[..., 1]))
    n = perp(u)
    s = dot(rel, u)
    s_dot = dot(vB, u)
    omega3 = dot(vB, n) / s
    s_ddot = dot(aB, u) + s * omega3**2
    alpha3 = (dot(aB, n) - 2.0 * s_dot * omega3) / s
    v_rel = -_vec(s_dot) * u
    return RRTR(
        B=B, D=np.array([AC, 0.0]) + CD * u, u=u, phi3=np.arctan2(u[..., 1], u[..., 0]),
        omega3=omega3, alpha3=alpha3, s=s, s_dot=s_dot, s_ddot=s_ddot, vB=vB, aB=aB,
        vB3=_vec(omega3) * perp(rel), aB3=_vec(alpha3) * perp(rel) - _vec(omega3**2) * rel,
        vD=CD * _vec(omega3) * n, aD=CD * (_vec(alpha3) * n - _vec(omega3**2) * u),
        v_rel=v_rel, a_rel=-_vec(s_ddot) * u, coriolis=2.0 * _vec(omega3) * perp(v_rel))


# ------------------------------------------------------------------------ four-bar

@dataclass(frozen=True)
class FourBar:
    """Four-bar angles [rad], rates [rad/s, rad/s^2] and pin kinematics [m, m/s, m/s^2]."""

    theta3: Array
    theta4: Array
    omega3: Array
    omega4: Array
    alpha3: Array
    alpha4: Array
    A: Array
    B: Array
    vA: Array
    vB: Array
    aA: Array
    aB: Array


def four_bar(theta2: ArrayLike, omega2: ArrayLike, alpha2: ArrayLike, a: float, b: float,
             c: float, d: float, branch: int = +1) -> FourBar:
    """Four-bar O2-A-B-O4 with O2 = (0, 0), O4 = (d, 0), driven by the crank O2A.

    B is the intersection of the circles (A, b) and (O4, c); ``branch=+1`` takes B to
    the left of the directed line A -> O4 (cross(O4 - A, B - A) > 0), -1 to the right.
    Rates from a e2 + b e3 - c e4 - d = 0 projected on e4 and e3 (Norton's formulas):
    ``omega3 = a omega2 sin(theta4 - theta2) / (b sin(theta3 - theta4))``,
    ``omega4 = a omega2 sin(theta2 - theta3) / (c sin(theta4 - theta3))``.
    At a toggle pose (theta3 = theta4 mod pi) the rates are not finite.

    Args:
        theta2, omega2, alpha2: crank angle [rad], velocity [rad/s], acceleration [rad/s^2].
        a, b, c, d: crank, coupler, rocker and ground lengths [m].
        branch: +1 or -1, the assembly (see above).

    Raises:
        ValueError: where the loop cannot close (|A - O4| > b + c or < |b - c|).
    """
    theta2, omega2, alpha2 = np.broadcast_arrays(*(_real(x)
                                                   for x in (theta2, omega2, alpha2)))
    e2 = unit(theta2)
    A = a * e2
    O4 = np.array([d, 0.0])
    w = O4 - A
    L = np.hypot(w[..., 0], w[..., 1])
    bad = (L > b + c) | (L < abs(b - c)) | (L == 0.0)
    if np.any(bad):
        Lb = np.atleast_1d(L)[np.atleast_1d(bad)][0]
        raise ValueError(f"four-bar cannot close: |A - O4| = {Lb:.17g} outside "
                         f"[|b - c|, b + c] = [{abs(b - c):.17g}, {b + c:.17g}]")
    x = (b**2 - c**2 + L**2) / (2.0 * L)  # distance from A to the chord along A -> O4
    h = np.sqrt(np.maximum(b**2 - x**2, 0.0))
    wh = w / _vec(L)
    B = A + _vec(x) * wh + branch * _vec(h) * perp(wh)
    theta3 = np.arctan2(B[..., 1] - A[..., 1], B[..., 0] - A[..., 0])
    theta4 = np.arctan2(B[..., 1], B[..., 0] - d)
    e3, e4 = unit(theta3), unit(theta4)
    with np.errstate(divide="ignore", invalid="ignore"):
        omega3 = a * omega2 * np.sin(theta4 - theta2) / (b * np.sin(theta3 - theta4))
        omega4 = a * omega2 * np.sin(theta2 - theta3) / (c * np.sin(theta4 - theta3))
        # Known part K of b alpha3 k x e3 - c alpha4 k x e4 = -K, projected on e4 and e3.
        aA = a * (_vec(alpha2) * perp(e2) - _vec(omega2**2) * e2)
        K = aA - b * _vec(omega3**2) * e3 + c * _vec(omega4**2) * e4
        alpha3 = -dot(K, e4) / (b * np.sin(theta4 - theta3))
        alpha4 = dot(K, e3) / (c * np.sin(theta3 - theta4))
    return FourBar(
        theta3=theta3, theta4=theta4, omega3=omega3, omega4=omega4, alpha3=alpha3,
        alpha4=alpha4, A=A, B=B, vA=a * _vec(omega2) * perp(e2),
        vB=c * _vec(omega4) * perp(e4), aA=aA,
        aB=c * (_vec(alpha4) * perp(e4) - _vec(omega4**2) * e4))


# ------------------------------------------------------------------- slider-crank

@dataclass(frozen=True)
class SliderCrank:
    """Offset slider-crank: slider x_B [m], v_B [m/s], a_B [m/s^2]; rod angle beta [rad]."""

    x_B: Array
    v_B: Array
    a_B: Array
    beta: Array
    omega_rod: Array
    alpha_rod: Array
    A: Array
    B: Array


def slider_crank(theta: ArrayLike, omega: ArrayLike, alpha: ArrayLike, r: float, l: float,
                 e: float = 0.0, branch: int = +1) -> SliderCrank:
    """Offset slider-crank from r sin(theta) + l sin(beta) = e, x_B = r cos(theta) + l cos(beta).

    ``omega_rod = -r omega cos(theta) / (l cos(beta))``; alpha_rod likewise from the
    second derivative. Rates are not finite where cos(beta) = 0.

    Args:
        theta, omega, alpha: crank angle [rad], velocity [rad/s], acceleration [rad/s^2].
        r: crank length [m].
        l: connecting rod length [m].
        e: offset of the slider line y = e [m].
        branch: +1 slider to the right of the crank pin, -1 to the left.

    Raises:
        ValueError: where |e - r sin(theta)| > l (the rod cannot reach the line).
    """
    theta, omega, alpha = np.broadcast_arrays(*(_real(x)
                                                for x in (theta, omega, alpha)))
    rise = e - r * np.sin(theta)
    if np.any(np.abs(rise) > l):
        worst = np.max(np.abs(rise))
        raise ValueError(f"slider-crank cannot close: |e - r sin(theta)| = {worst:.17g} > l = {l}")
    run = branch * np.sqrt(l**2 - rise**2)
    beta = np.arctan2(rise, run)
    s, c, sb, cb = np.sin(theta), np.cos(theta), np.sin(beta), np.cos(beta)
    with np.errstate(divide="ignore", invalid="ignore"):
        omega_rod = -r * omega * c / (l * cb)
        alpha_rod = (-r * (alpha * c - omega**2 * s) + l * omega_rod**2 * sb) / (l * cb)
    x_B = r * c + run
    return SliderCrank(
        x_B=x_B, v_B=-r * omega * s - l * omega_rod * sb,
        a_B=-r * (alpha * s + omega**2 * c) - l * (alpha_rod * sb + omega_rod**2 * cb),
        beta=beta, omega_rod=omega_rod, alpha_rod=alpha_rod, A=r * unit(theta),
        B=np.stack([x_B, np.full_like(x_B, e)], axis=-1))


# ------------------------------------------------------------------------- 3R arm

@dataclass(frozen=True)
class ArmRates:
    """3R arm rates for a prescribed motion of D: absolute [rad/s, rad/s^2] and relative."""

    omega_AB: Array
    omega_BC: Array
    omega_CD: Array
    alpha_AB: Array
    alpha_BC: Array
    alpha_CD: Array
    q_dot: Array
    q_ddot: Array
    D: Array


@dataclass(frozen=True)
class ArmState:
    """3R arm joint positions [m], velocities [m/s] and accelerations [m/s^2] of B, C, D."""

    B: Array
    C: Array
    D: Array
    vB: Array
    vC: Array
    vD: Array
    aB: Array
    aC: Array
    aD: Array


def planar_arm_rates(th1: ArrayLike, th_BC: ArrayLike, th_CD: ArrayLike, r1: float,
                     r2: float, r3: float, vD: ArrayLike, aD: ArrayLike,
                     omega_CD: ArrayLike = 0.0, alpha_CD: ArrayLike = 0.0) -> ArmRates:
    """Link rates of the 3R arm A-B-C-D that give D the velocity vD and acceleration aD.

    With e1, e2, e3 the directions of AB, BC, CD: vC = vD - omega_CD k x (D - C) =
    omega_AB r1 k x e1 + omega_BC r2 k x e2, a 2x2 system of determinant
    det = r1 r2 sin(th_BC - th1) solved by Cramer's rule:
    ``omega_AB = r2 vC.e2 / det``, ``omega_BC = -r1 vC.e1 / det``. The accelerations solve
    the same system with right-hand side aC + omega_AB^2 r1 e1 + omega_BC^2 r2 e2.

    Args:
        th1, th_BC, th_CD: absolute link angles [rad].
        r1, r2, r3: link lengths AB, BC, CD [m].
        vD: velocity of D [m/s], shape (..., 2).
        aD: acceleration of D [m/s^2], shape (..., 2).
        omega_CD: prescribed angular velocity of CD [rad/s].
        alpha_CD: prescribed angular acceleration of CD [rad/s^2].

    Raises:
        ValueError: where det = 0 (arm stretched or folded at B).
    """
    th1, th_BC, th_CD, omega_CD, alpha_CD = np.broadcast_arrays(
        *(_real(x) for x in (th1, th_BC, th_CD, omega_CD, alpha_CD)))
    e1, e2, e3 = unit(th1), unit(th_BC), unit(th_CD)
    det = r1 * r2 * np.sin(th_BC - th1)
    if np.any(det == 0.0):
        raise ValueError(f"3R arm singular: det = r1 r2 sin(th_BC - th1) = "
                         f"{np.atleast_1d(det)[np.atleast_1d(det == 0.0)][0]!r}")
    CD = r3 * e3
    vC = _real(vD) - _vec(omega_CD) * perp(CD)
    omega_AB = r2 * dot(vC, e2) / det
    omega_BC = -r1 * dot(vC, e1) / det
    aC = _real(aD) - _vec(alpha_CD) * perp(CD) + _vec(omega_CD**2) * CD
    rhs = aC + _vec(omega_AB**2) * r1 * e1 + _vec(omega_BC**2) * r2 * e2
    alpha_AB = r2 * dot(rhs, e2) / det
    alpha_BC = -r1 * dot(rhs, e1) / det
    return ArmRates(
        omega_AB=omega_AB, omega_BC=omega_BC, omega_CD=omega_CD, alpha_AB=alpha_AB,
        alpha_BC=alpha_BC, alpha_CD=alpha_CD,
        q_dot=np.stack([omega_AB, omega_BC - omega_AB, omega_CD - omega_BC], axis=-1),
        q_ddot=np.stack([alpha_AB, alpha_BC - alpha_AB, alpha_CD - alpha_BC], axis=-1),
        D=r1 * e1 + r2 * e2 + CD)


def planar_arm_forward(q: ArrayLike, q_dot: ArrayLike, q_ddot: ArrayLike, r1: float,
                       r2: float, r3: float) -> ArmState:
    """Forward kinematics of the 3R arm from relative joint coordinates (qA, qB, qC).

    Absolute angles are the running sums th1 = qA, th_BC = qA + qB, th_CD = qA + qB + qC.

    Args:
        q: joint angles [rad], shape (..., 3).
        q_dot: joint velocities [rad/s], shape (..., 3).
        q_ddot: joint accelerations [rad/s^2], shape (..., 3).
        r1, r2, r3: link lengths AB, BC, CD [m].
    """
    th, w, al = (np.cumsum(_real(x), axis=-1) for x in (q, q_dot, q_ddot))
    points, vels, accs = [], [], []
    p = v = acc = 0.0
    for i, r in enumerate((r1, r2, r3)):
        e = unit(th[..., i])
        p = p + r * e
        v = v + r * _vec(w[..., i]) * perp(e)
        acc = acc + r * (_vec(al[..., i]) * perp(e) - _vec(w[..., i] ** 2) * e)
        points.append(p), vels.append(v), accs.append(acc)
    return ArmState(*points, *vels, *accs)


def five_bar_elbow(p: ArrayLike, base: ArrayLike, l1: float, l2: float, sign: float) -> Array:
    """The elbow B of a five-bar's leg (motor at `base`, proximal link l1, distal link l2 [m])
    reaching the end point p [m] with the turn base -> B -> p of the given sign
    (cross(B - base, p - B) > 0 for +1): B at the angle phi -+ alpha of the line base -> p,
    alpha from the law of cosines.

    Raises:
        ValueError: p outside the leg's annulus, or no elbow of that sign (p on its circles).
    """
    p, base = _real(p), _real(base)
    v = p - base
    d = float(np.hypot(v[0], v[1]))
    cosine = (l1 * l1 + d * d - l2 * l2) / (2 * l1 * d) if d > 0 else np.inf
    if not abs(cosine) <= 1.0 + 1e-12:  # a point on the annulus' circle, rounded: the stretched leg
        raise ValueError(f"five-bar leg cannot reach: |p - base| = {d!r} outside [|l2 - l1|, l1 + l2]")
    alpha = math.acos(min(1.0, max(-1.0, cosine)))
    for angle in (math.atan2(v[1], v[0]) - alpha, math.atan2(v[1], v[0]) + alpha):
        b = base + l1 * np.array([math.cos(angle), math.sin(angle)])
        turn = (b - base)[0] * (p - b)[1] - (b - base)[1] * (p - b)[0]
        if np.sign(turn) == sign:
            return b
    raise ValueError(f"five-bar leg has no elbow of sign {sign:+g} at p = {p!r} (a stretched or folded leg)")


def five_bar_motors(p: ArrayLike, mode: str, bases: ArrayLike, l1: float, l2: float,
                    zero: ArrayLike) -> Array:
    """The motors' readings [rad] of a planar five-bar reaching the end point p [m] in the
    working mode `mode` ("+-": each leg's elbow sign, as five_bar_elbow), each reading its
    proximal link's angle less that motor's zero direction `zero` [rad] (a URDF's rpy)."""
    out = []
    for i, s in enumerate(mode):
        b = five_bar_elbow(p, bases[i], l1, l2, 1.0 if s == "+" else -1.0)
        out.append(math.atan2(b[1] - bases[i][1], b[0] - bases[i][0]) - zero[i])
    return np.array(out)


def main() -> None:
    """Print the R-RTR of Problem Chapter I.9 at phi = 30 deg, omega1 = -50 rpm."""
    r = r_rtr(np.radians(30.0), -50.0 * np.pi / 30.0, 0.0)
    print("R-RTR, phi = 30 deg, omega1 = -50 rpm, alpha1 = 0 (AB = 0.10, AC = 0.05, CD = 0.15 m)")
    rows = [("B [m]", r.B), ("D [m]", r.D), ("phi3 [rad]", r.phi3),
            ("phi3 [deg]", np.degrees(r.phi3)), ("omega3 [rad/s]", r.omega3),
            ("alpha3 [rad/s^2]", r.alpha3), ("s [m]", r.s), ("v32 = -s_dot [m/s]", -r.s_dot),
            ("a32 = -s_ddot [m/s^2]", -r.s_ddot), ("vB [m/s]", r.vB), ("aB [m/s^2]", r.aB),
            ("vB3 [m/s]", r.vB3), ("aB3 [m/s^2]", r.aB3), ("v_rel [m/s]", r.v_rel),
            ("a_rel [m/s^2]", r.a_rel), ("coriolis [m/s^2]", r.coriolis),
            ("vD [m/s]", r.vD), ("aD [m/s^2]", r.aD)]
    for name, value in rows:
        print(f"  {name:22s} {np.array2string(np.asarray(value), precision=6)}")


if __name__ == "__main__":
    main()
