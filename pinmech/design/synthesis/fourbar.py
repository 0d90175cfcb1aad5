"""A four-bar's position in closed form on one assembly, for a batch of candidate linkages
at once: the search's evaluator (search.py). Lengths [m], angles [rad] from the
world x axis, counter-clockwise.

A candidate is the row z = (O2x, O2y, O4x, O4y, crank, coupler, rocker, along, across):
ground pivots O2 (crank) and O4 (rocker), link lengths, and the coupler point P at
`along` the coupler's bar A -> B and `across` to the left of it. The assembly s = +1 puts
B to the left of the line A -> O4 (the drawn linkage's `side = "left"`), s = -1 right.

At a crank angle theta the dyad A-B-O4 closes (model/compass.py, as a drawn linkage's B):
D = |O4 - A|, B = A + a u + s h n with a = (coupler^2 - rocker^2 + D^2) / 2D,
h = sqrt(coupler^2 - a^2), u the unit A -> O4 and n = u turned +90 deg. It closes while
|coupler - rocker| <= D <= coupler + rocker; D depends on theta through cos(theta - g)
alone (g the direction O2 -> O4), so the folds, where it stops closing, are known in
closed form (`folds`): a motion on one s that passes no fold is continuation on one
assembly, exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import math

import numpy as np

from pinmech.model.compass import compass
from pinmech.solve.grashof import four_bar_class

#: Names of a four-bar candidate's entries, in order.
NAMES = ("O2x", "O2y", "O4x", "O4y", "crank", "coupler", "rocker", "along", "across")


@dataclass(frozen=True)
class FourBarPose:
    """Positions of a batch at crank angles (arrays broadcast over the batch and angles).

    Attributes:
        A, B, P: pin A, pin B and the coupler point, shape (..., 2) [m].
        closes: whether the dyad closes there (where it does not, B and P are NaN).
        mu: the transmission angle between coupler and rocker [rad], 0..pi.
    """

    A: np.ndarray
    B: np.ndarray
    P: np.ndarray
    closes: np.ndarray
    mu: np.ndarray


def pose(z: np.ndarray, s: np.ndarray, theta: np.ndarray) -> FourBarPose:
    """The batch z (n, 9) on assemblies s (n,) at crank angles theta (n, m) [rad]."""
    z = np.asarray(z, dtype=float)
    col = [z[:, k, None] for k in range(9)]
    o2x, o2y, o4x, o4y, r2, r3, r4, pu, pv = col
    ax, ay = o2x + r2 * np.cos(theta), o2y + r2 * np.sin(theta)
    A = np.stack((ax, ay), -1)
    O4 = np.stack(np.broadcast_arrays(o4x, o4y), -1)
    B, closes = compass(A, O4, r3, r4, np.asarray(s, dtype=float)[:, None])
    B = np.where(closes[..., None], B, np.nan)
    bx, by = B[..., 0], B[..., 1]
    D2 = (o4x - ax) ** 2 + (o4y - ay) ** 2
    ex, ey = (bx - ax) / r3, (by - ay) / r3
    px, py = ax + pu * ex - pv * ey, ay + pu * ey + pv * ex
    cos_mu = np.clip((r3 * r3 + r4 * r4 - D2) / (2 * r3 * r4), -1.0, 1.0)
    return FourBarPose(A, B, np.stack((px, py), -1), closes,
                       np.arccos(cos_mu))


def label(z: np.ndarray) -> str:
    """The Grashof class of one candidate (grashof.four_bar_class: crank at O2, rocker at O4)."""
    return four_bar_class(*lengths(z))[0]


def lengths(z: np.ndarray) -> tuple[float, ...]:
    """The four links of one candidate (ground, crank, coupler, rocker) [m]."""
    return math.hypot(z[2] - z[0], z[3] - z[1]), float(z[4]), float(z[5]), float(z[6])


def size(z: np.ndarray) -> float:
    """The four-bar's size: its longest link [m]."""
    return float(max(lengths(z)))


def ground_angle(z: np.ndarray) -> np.ndarray:
    """g: the direction O2 -> O4 [rad], shape (n,)."""
    return np.arctan2(z[:, 3] - z[:, 1], z[:, 2] - z[:, 0])


def folds(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The crank angles where the dyad folds, (n, 4) [rad] (NaN where there is none), and
    whether the dyad closes at theta = g (n,), the crank pointing at O4.

    D^2 = crank^2 + L^2 - 2 crank L cos(theta - g) (L = |O2O4|) reaches coupler + rocker
    and |coupler - rocker| at cos(theta - g) = c, two angles g +- acos(c) for each |c| <= 1.
    """
    L = np.hypot(z[:, 2] - z[:, 0], z[:, 3] - z[:, 1])
    r2, r3, r4 = z[:, 4], z[:, 5], z[:, 6]
    g = ground_angle(z)
    out = []
    for Dlim in (r3 + r4, np.abs(r3 - r4)):
        c = (r2 * r2 + L * L - Dlim * Dlim) / (2 * r2 * L)
        t = np.where(np.abs(c) <= 1, np.arccos(np.clip(c, -1, 1)), np.nan)
        out += [g + t, g - t]
    Dmin = np.abs(L - r2)
    closes_at_g = (Dmin <= r3 + r4) & (Dmin >= np.abs(r3 - r4))
    return np.stack(out, -1), closes_at_g


def point_jacobian(z: np.ndarray, s: float, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P at crank angles theta (m,) of one linkage z (9,), with its exact derivatives by the
    implicit-function theorem on the loop equation.

    The loop O2 + crank e(theta) + coupler e(phi3) - O4 - rocker e(phi4) = 0 (e(x) = (cos x,
    sin x)) fixes phi3, phi4: G_phi dphi + G_z dz + G_theta dtheta = 0, so dphi = -G_phi^-1
    (G_z dz + G_theta dtheta). P = O2 + crank e(theta) + R(phi3) (along, across).

    Returns:
        P (m, 2) [m], dP/dz (m, 2, 9) [m/m], dP/dtheta (m, 2) [m/rad].
    """
    z = np.asarray(z, dtype=float)
    p = pose(z[None], np.array([s]), np.asarray(theta, dtype=float)[None])
    A, B, P = p.A[0], p.B[0], p.P[0]
    r2, r3, r4, pu, pv = z[4:9]
    e3 = (B - A) / r3
    e4 = (B - z[2:4]) / r4
    perp = np.array([[0.0, -1.0], [1.0, 0.0]])
    d3, d4 = e3 @ perp.T, e4 @ perp.T  # de/dphi: e turned +90 deg
    m = len(theta)
    et = np.stack((np.cos(theta), np.sin(theta)), -1)
    dt = et @ perp.T
    G_phi = np.stack((r3 * d3, -r4 * d4), -1)  # (m, 2, 2): columns dG/dphi3, dG/dphi4
    G_z = np.zeros((m, 2, 9))
    G_z[:, :, 0:2] = np.eye(2)
    G_z[:, :, 2:4] = -np.eye(2)
    G_z[:, :, 4], G_z[:, :, 5], G_z[:, :, 6] = et, e3, -e4
    G_t = r2 * dt
    inv = np.linalg.inv(G_phi)  # LinAlgError at a fold (coupler and rocker in line)
    dphi3_z = -(inv @ G_z)[:, 0, :]  # (m, 9)
    dphi3_t = -(inv @ G_t[..., None])[:, 0, 0]  # (m,)
    dP_dphi3 = pu * d3 + pv * (d3 @ perp.T)  # d/dphi3 of R(phi3)(along, across)
    dP_z = np.zeros((m, 2, 9))
    dP_z[:, :, 0:2] = np.eye(2)
    dP_z[:, :, 4] = et
    dP_z[:, :, 7], dP_z[:, :, 8] = e3, d3
    dP_z += dP_dphi3[:, :, None] * dphi3_z[:, None, :]
    dP_t = r2 * dt + dP_dphi3 * dphi3_t[:, None]
    return P, dP_z, dP_t


def rocker_jacobian(z: np.ndarray, s: float, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rocker's angle phi4 (direction O4 -> B) at crank angles theta (m,) of one
    linkage z (9,), and its exact derivatives: `link_angle_jacobian` of the rocker."""
    return link_angle_jacobian(z, s, theta, 1)


def link_angle_jacobian(z: np.ndarray, s: float, theta: np.ndarray,
                        link: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The coupler's (link 0: direction A -> B) or the rocker's (link 1: O4 -> B) angle at
    crank angles theta (m,) of one linkage z (9,), and its exact derivatives from the loop
    equation of `point_jacobian`: dphi = -G_phi^-1 (G_z dz + G_theta dtheta), row `link`.

    Returns:
        phi (m,) [rad], dphi/dz (m, 9) [rad/m], dphi/dtheta (m,) [rad/rad].
    """
    z = np.asarray(z, dtype=float)
    theta = np.asarray(theta, dtype=float)
    p = pose(z[None], np.array([s]), theta[None])
    A, B = p.A[0], p.B[0]
    r2, r3, r4 = z[4:7]
    e3, e4 = (B - A) / r3, (B - z[2:4]) / r4
    perp = np.array([[0.0, -1.0], [1.0, 0.0]])
    d3, d4 = e3 @ perp.T, e4 @ perp.T
    m = len(theta)
    et = np.stack((np.cos(theta), np.sin(theta)), -1)
    G_phi = np.stack((r3 * d3, -r4 * d4), -1)
    G_z = np.zeros((m, 2, 9))
    G_z[:, :, 0:2] = np.eye(2)
    G_z[:, :, 2:4] = -np.eye(2)
    G_z[:, :, 4], G_z[:, :, 5], G_z[:, :, 6] = et, e3, -e4
    G_t = r2 * (et @ perp.T)
    inv = np.linalg.inv(G_phi)  # LinAlgError at a fold
    e = (e3, e4)[link]
    return (np.arctan2(e[:, 1], e[:, 0]), -(inv @ G_z)[:, link, :], -(inv @ G_t[..., None])[:, link, 0])
