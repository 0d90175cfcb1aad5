"""An inverted slider-crank's position in closed form on one assembly, for a batch of
candidates at once (the synthesis search's evaluator, as fourbar for the
four-bar). Lengths [m], angles [rad] from the world x axis, counter-clockwise.

A candidate is the row z = (O2x, O2y, O4x, O4y, crank, offset, along, across): the crank's
ground pivot O2, the guide's (the rocker's) ground pivot O4, the crank's length, the slot's
line on the guide at `offset` to the left of O4 (parallel to the guide's direction u =
e(phi), n = u turned +90 deg), and the coupler point P on the block (which slides in the
slot, pinned to the crank at A) at `along` u and `across` n from A.

At a crank angle theta, A = O2 + crank e(theta) and A - O4 = x u + offset n (A on the slot's
line, x its place along the slot from the foot F = O4 + offset n): with D = |A - O4|,
x = s sqrt(D^2 - offset^2) and phi = atan2(A - O4) - atan2(offset, x). The assembly s = +1
puts A ahead of the foot along u, s = -1 behind: the same linkage as s = +1 with the offset's
sign changed (u and n turned half a turn), so the search takes s = +1 alone (ASSEMBLIES),
the guide's direction u pointing from the slot's foot towards the crank's pin, and the
offset's sign saying on which side of O4 the slot passes. It closes while D >= |offset|; D depends
on theta through cos(theta - g) alone (g the direction O2 -> O4), so the folds, where
D = |offset| (the slot's line through A square to O4 -> A: the block cannot be pushed
along it, and the two assemblies meet), are at cos(theta - g) = (crank^2 + L^2 -
offset^2) / (2 crank L) (L = |O2 O4|), in closed form: a motion on one s that passes no
fold is continuation on one assembly, exactly. A slot through the pivot (offset 0) has
no fold unless the crank's pin passes over O4 (crank = L).

Transmission angle (as pinmech.solve.transmission defines it for a slot dyad, after
Norton, Design of Machinery, §4.7 and §4.10): without friction the block pushes the guide
along n, normal to the slot, and the guide's point at A moves normal to O4 -> A; the
pressure angle is the angle between those two directions, sin = |offset| / D, and the
transmission angle mu = 90 deg - pressure angle: cos(mu) = offset / D (here signed, mu in
0..180 deg: 90 deg best, always, for a slot through the pivot; 0 or 180 deg at a fold).
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.fourbar import FourBarPose, ground_angle

__all__ = ["ASSEMBLIES", "NAMES", "pose", "guide_angle", "folds", "ground_angle", "label", "lengths", "size",
           "loop_jacobian", "point_jacobian", "guide_jacobian"]

#: The assemblies searched: s = -1 with an offset e is s = +1 with -e (u, n and x turned
#: half a turn: A - O4 = x u + e n = (-x)(-u) + (-e)(-n)), the same linkage; so one.
ASSEMBLIES = (1.0,)
#: Names of an inverted slider-crank candidate's entries, in order.
NAMES = ("O2x", "O2y", "O4x", "O4y", "crank", "offset", "along", "across")
_PERP = np.array([[0.0, -1.0], [1.0, 0.0]])


def _place(z: np.ndarray, s: np.ndarray, theta: np.ndarray):
    """A (..., 2), the slot's place x of A, the guide's angle phi [rad], D and whether it closes."""
    z = np.asarray(z, dtype=float)
    o2x, o2y, o4x, o4y, r, e = (z[:, k, None] for k in range(6))
    ax, ay = o2x + r * np.cos(theta), o2y + r * np.sin(theta)
    dx, dy = ax - o4x, ay - o4y
    D2 = dx * dx + dy * dy
    closes = D2 >= e * e
    x = np.asarray(s, dtype=float)[:, None] * np.sqrt(np.where(closes, D2 - e * e, np.nan))
    phi = np.arctan2(dy, dx) - np.arctan2(e, x)
    return np.stack((ax, ay), -1), x, phi, np.sqrt(D2), closes


def pose(z: np.ndarray, s: np.ndarray, theta: np.ndarray) -> FourBarPose:
    """The batch z (n, 8) on assemblies s (n,) at crank angles theta (n, m) [rad]. B is the
    slot's foot F = O4 + offset n (the guide's point nearest O4 on the slot's line), P the
    block's point, mu the transmission angle."""
    z = np.asarray(z, dtype=float)
    A, x, phi, D, closes = _place(z, s, theta)
    e, pu, pv = z[:, 5, None], z[:, 6, None], z[:, 7, None]
    ux, uy = np.cos(phi), np.sin(phi)
    F = np.stack((z[:, 2, None] - e * uy, z[:, 3, None] + e * ux), -1)
    P = np.stack((A[..., 0] + pu * ux - pv * uy, A[..., 1] + pu * uy + pv * ux), -1)
    mu = np.arccos(np.clip(e / np.where(D > 0, D, np.nan), -1.0, 1.0))
    return FourBarPose(A, F, P, closes, mu)


def guide_angle(z: np.ndarray, s: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """The guide's angle phi (the slot's direction u) [rad], (n, m); NaN where it does not close."""
    return _place(z, s, theta)[2]


def folds(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The crank angles where the block folds (D = |offset|), (n, 2) [rad] (NaN where
    there is none): cos(theta - g) = (crank^2 + L^2 - offset^2) / (2 crank L); and whether
    it closes with the crank pointing at O4 (n,): |L - crank| >= |offset|."""
    L = np.hypot(z[:, 2] - z[:, 0], z[:, 3] - z[:, 1])
    r, e = z[:, 4], z[:, 5]
    g = ground_angle(z)
    c = (r * r + L * L - e * e) / (2 * r * L)
    t = np.where(np.abs(c) <= 1, np.arccos(np.clip(c, -1, 1)), np.nan)
    return np.stack((g + t, g - t), -1), np.abs(L - r) >= np.abs(e)


def label(z: np.ndarray) -> str:
    """"crank" (it turns fully: |L - crank| > |offset|, no fold) or "rocker"."""
    L = math.hypot(z[2] - z[0], z[3] - z[1])
    return "crank" if abs(L - z[4]) > abs(z[5]) else "rocker"


def lengths(z: np.ndarray) -> tuple[float, ...]:
    """The links whose ratio a file may bound: ground and crank [m]."""
    return math.hypot(z[2] - z[0], z[3] - z[1]), float(z[4])


def size(z: np.ndarray) -> float:
    """The inverted slider-crank's size: the largest of ground, crank and |offset| [m]."""
    return float(max(*lengths(z), abs(z[5])))


def loop_jacobian(z: np.ndarray, s: float, theta: np.ndarray) -> tuple[FourBarPose, np.ndarray, np.ndarray]:
    """The pose of one linkage z (8,) at crank angles theta (m,), and the exact derivatives
    of (phi, x), the guide's angle and A's place along the slot, by the implicit-function
    theorem on the loop G = O2 + crank e(theta) - O4 - x u(phi) - offset n(phi) = 0:
    d(phi, x) = -G_q^-1 (G_z dz + G_theta dtheta).

    Returns:
        the pose, d(phi, x)/dz (m, 2, 8), d(phi, x)/dtheta (m, 2).
    """
    z = np.asarray(z, dtype=float)
    theta = np.asarray(theta, dtype=float)
    p = pose(z[None], np.array([s]), theta[None])
    _, x, phi, _, _ = _place(z[None], np.array([s]), theta[None])
    x, phi = x[0], phi[0]
    r, e = z[4], z[5]
    u = np.stack((np.cos(phi), np.sin(phi)), -1)
    n = u @ _PERP.T
    m = len(theta)
    et = np.stack((np.cos(theta), np.sin(theta)), -1)
    G_q = np.stack((-x[:, None] * n + e * u, -u), -1)  # (m, 2, 2): dG/dphi, dG/dx
    G_z = np.zeros((m, 2, 8))
    G_z[:, :, 0:2] = np.eye(2)
    G_z[:, :, 2:4] = -np.eye(2)
    G_z[:, :, 4], G_z[:, :, 5] = et, -n
    G_t = r * (et @ _PERP.T)
    inv = np.linalg.inv(G_q)  # LinAlgError at a fold (x = 0)
    return p, -(inv @ G_z), -(inv @ G_t[..., None])[..., 0]


def guide_jacobian(z: np.ndarray, s: float, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The guide's angle phi (m,) [rad] at crank angles theta (m,) of one linkage z (8,),
    dphi/dz (m, 8) [rad/m] and dphi/dtheta (m,) [rad/rad]."""
    _, dq_z, dq_t = loop_jacobian(z, s, theta)
    return guide_angle(z[None], np.array([s]), np.asarray(theta, float)[None])[0], dq_z[:, 0, :], dq_t[:, 0]


def point_jacobian(z: np.ndarray, s: float, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P at crank angles theta (m,) of one linkage z (8,), dP/dz (m, 2, 8) [m/m] and
    dP/dtheta (m, 2) [m/rad] (fourbar.point_jacobian's contract)."""
    p, dq_z, dq_t = loop_jacobian(z, s, theta)
    P = p.P[0]
    r, pu, pv = z[4], z[6], z[7]
    phi = guide_angle(z[None], np.array([s]), np.asarray(theta, float)[None])[0]
    u = np.stack((np.cos(phi), np.sin(phi)), -1)
    n = u @ _PERP.T
    et = np.stack((np.cos(theta), np.sin(theta)), -1)
    dP_dphi = pu * n - pv * u
    dP_z = np.zeros((len(theta), 2, 8))
    dP_z[:, :, 0:2] = np.eye(2)
    dP_z[:, :, 4] = et
    dP_z[:, :, 6], dP_z[:, :, 7] = u, n
    dP_z += dP_dphi[:, :, None] * dq_z[:, None, 0, :]
    dP_t = r * (et @ _PERP.T) + dP_dphi * dq_t[:, 0, None]
    return P, dP_z, dP_t
