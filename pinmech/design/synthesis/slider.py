"""A slider-crank's position in closed form on one assembly, for a batch of candidates at
once (the synthesis search's evaluator, as fourbar for the four-bar). Lengths
[m], angles [rad] from the world x axis, counter-clockwise.

A candidate is the row z = (O2x, O2y, slide, offset, crank, rod, along, across): the
crank's ground pivot O2, the slide's line at angle `slide` (u = e(slide), n = u turned +90
deg) through H = O2 + offset n, the crank and rod lengths, and the coupler point P on the
rod at `along` A -> B from A and `across` to its left. The block's pin B = H + x u.

At a crank angle theta, A = O2 + crank e(theta) is h = (A - H) . n = crank sin(theta -
slide) - offset from the line; the rod reaches it while |h| <= rod, and then x = (A - H) .
u + s sqrt(rod^2 - h^2): the assembly s = +1 puts B ahead of A's foot along u, s = -1
behind. The folds, where |h| = rod (the rod square to the slide), are at sin(theta -
slide) = (offset +- rod) / crank, in closed form:
a motion on one s that passes no fold is continuation on one assembly, exactly.

The transmission angle mu is the rod's angle from the slide's normal (90 deg: the rod
along the slide, the best; 0 or 180 deg: square to it, a dead point); its extremes over a
motion are at the ends or where the crank is square to the slide (`ground_angle`).
"""

from __future__ import annotations

import numpy as np

from pinmech.design.synthesis.fourbar import FourBarPose
from pinmech.solve.grashof import slider_crank_class

#: Names of a slider-crank candidate's entries, in order.
NAMES = ("O2x", "O2y", "slide", "offset", "crank", "rod", "along", "across")
_PERP = np.array([[0.0, -1.0], [1.0, 0.0]])


def pose(z: np.ndarray, s: np.ndarray, theta: np.ndarray) -> FourBarPose:
    """The batch z (n, 8) on assemblies s (n,) at crank angles theta (n, m) [rad]; B is
    the block's pin, mu the transmission angle."""
    z = np.asarray(z, dtype=float)
    o2x, o2y, psi, e, r, l, pu, pv = (z[:, k, None] for k in range(8))
    ux, uy = np.cos(psi), np.sin(psi)
    ax, ay = o2x + r * np.cos(theta), o2y + r * np.sin(theta)
    h = r * np.sin(theta - psi) - e
    rest2 = l * l - h * h
    closes = rest2 >= 0
    along_line = r * np.cos(theta - psi) + np.sqrt(np.where(closes, rest2, np.nan)) * np.asarray(s, float)[:, None]
    hx, hy = o2x - e * uy, o2y + e * ux
    bx, by = hx + along_line * ux, hy + along_line * uy
    wx, wy = (bx - ax) / l, (by - ay) / l
    px, py = ax + pu * wx - pv * wy, ay + pu * wy + pv * wx
    mu = np.arccos(np.clip(-wx * uy + wy * ux, -1.0, 1.0))
    return FourBarPose(np.stack((ax, ay), -1), np.stack((bx, by), -1), np.stack((px, py), -1), closes, mu)


def slide_position(z: np.ndarray, B: np.ndarray) -> np.ndarray:
    """x: the block's pin B (n, m, 2) along the slide from H [m]."""
    psi, e = z[:, 2, None], z[:, 3, None]
    hx, hy = z[:, 0, None] - e * np.sin(psi), z[:, 1, None] + e * np.cos(psi)
    return (B[..., 0] - hx) * np.cos(psi) + (B[..., 1] - hy) * np.sin(psi)


def ground_angle(z: np.ndarray) -> np.ndarray:
    """The crank square to the slide (slide + 90 deg) [rad], shape (n,): the transmission
    angle's extremes are there and half a turn on."""
    return z[:, 2] + np.pi / 2


def folds(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The crank angles where the rod folds square to the slide, (n, 4) [rad] (NaN where
    there is none): sin(theta - slide) = (offset +- rod) / crank; and whether the rod
    reaches the slide with the crank square to it (n,)."""
    psi, e, r, l = z[:, 2], z[:, 3], z[:, 4], z[:, 5]
    out = []
    for sign in (1.0, -1.0):
        c = (e + sign * l) / r
        t = np.where(np.abs(c) <= 1, np.arcsin(np.clip(c, -1, 1)), np.nan)
        out += [psi + t, psi + np.pi - t]
    return np.stack(out, -1), np.abs(r - np.abs(e)) <= l


def label(z: np.ndarray) -> str:
    """"crank" (it turns fully: crank + |offset| <= rod) or "rocker" (grashof.slider_crank_class)."""
    return slider_crank_class(float(z[4]), float(z[5]), float(z[3]))[0]


def lengths(z: np.ndarray) -> tuple[float, ...]:
    """The links whose ratio a file may bound: crank and rod [m]."""
    return float(z[4]), float(z[5])


def size(z: np.ndarray) -> float:
    """The slider-crank's size: the largest of crank, rod and |offset| [m]."""
    return float(max(z[4], z[5], abs(z[3])))


def loop_jacobian(z: np.ndarray, s: float, theta: np.ndarray) -> tuple[FourBarPose, np.ndarray, np.ndarray]:
    """The pose of one linkage z (8,) at crank angles theta (m,), and the exact
    derivatives of (phi3, x), the rod's angle and the block's place along the slide, by the
    implicit-function theorem on the loop G = crank e(theta) - offset n + rod e(phi3) -
    x u = 0 (relative to O2): d(phi3, x) = -G_q^-1 (G_z dz + G_theta dtheta).

    Returns:
        the pose, d(phi3, x)/dz (m, 2, 8), d(phi3, x)/dtheta (m, 2).
    """
    z = np.asarray(z, dtype=float)
    theta = np.asarray(theta, dtype=float)
    p = pose(z[None], np.array([s]), theta[None])
    A, B = p.A[0], p.B[0]
    psi, e, r, l = z[2:6]
    u, n = np.array([np.cos(psi), np.sin(psi)]), np.array([-np.sin(psi), np.cos(psi)])
    w = (B - A) / l
    x = slide_position(z[None], B[None])[0]
    m = len(theta)
    et = np.stack((np.cos(theta), np.sin(theta)), -1)
    G_q = np.stack((l * (w @ _PERP.T), np.broadcast_to(-u, (m, 2))), -1)  # (m, 2, 2)
    G_z = np.zeros((m, 2, 8))
    G_z[:, :, 2] = e * u[None] - x[:, None] * n[None]  # d/dslide of -offset n - x u
    G_z[:, :, 3] = -n
    G_z[:, :, 4], G_z[:, :, 5] = et, w
    G_t = r * (et @ _PERP.T)
    inv = np.linalg.inv(G_q)  # LinAlgError at a fold (the rod square to the slide)
    return p, -(inv @ G_z), -(inv @ G_t[..., None])[..., 0]


def point_jacobian(z: np.ndarray, s: float, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P at crank angles theta (m,) of one linkage z (8,), dP/dz (m, 2, 8) [m/m] and
    dP/dtheta (m, 2) [m/rad] (fourbar.point_jacobian's contract)."""
    p, dq_z, dq_t = loop_jacobian(z, s, theta)
    A, B, P = p.A[0], p.B[0], p.P[0]
    r, l, pu, pv = z[4], z[5], z[6], z[7]
    w = (B - A) / l
    dw = w @ _PERP.T
    et = np.stack((np.cos(theta), np.sin(theta)), -1)
    dP_dphi = pu * dw + pv * (dw @ _PERP.T)
    dP_z = np.zeros((len(theta), 2, 8))
    dP_z[:, :, 0:2] = np.eye(2)
    dP_z[:, :, 4] = et
    dP_z[:, :, 6], dP_z[:, :, 7] = w, dw
    dP_z += dP_dphi[:, :, None] * dq_z[:, None, 0, :]
    dP_t = r * (et @ _PERP.T) + dP_dphi * dq_t[:, 0, None]
    return P, dP_z, dP_t
