"""Burmester's four-pose motion generation: the centre-point and circle-point curves, in the
complex-number (Erdman–Sandor) form, and the four-bars their dyad pairs make, the motion
search's starting rows and the tests' reference.

Poses j = 1..4: the coupler point P_j (complex, [m]) and the coupler's angle alpha_j [rad];
rotations from the first a_j = alpha_j - alpha_1, displacements d_j = P_j - P_1. A dyad
is a crank W (ground pivot M -> circle point C, at the first pose) turning by beta_j, and
the coupler's vector Z (C -> P); it carries P through the poses when

    W (e^{i beta_j} - 1) + Z (e^{i a_j} - 1) = d_j,   j = 2, 3, 4,

three complex equations in W, Z: solvable when the determinant of [e^{i beta_j} - 1,
e^{i a_j} - 1, d_j] vanishes: D1 + D2 e^{i beta_2} + D3 e^{i beta_3} + D4 e^{i beta_4} = 0
(the compatibility linkage, D_k its cofactors). For each beta_2, D3 e^{i beta_3} + D4
e^{i beta_4} = -(D1 + D2 e^{i beta_2}) closes as a triangle in two ways (or none); each
gives W, Z from the equations j = 2, 3, the centre point M = P_1 - Z - W and the circle
point C = P_1 - Z.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.model.compass import compass


def compatibility(places: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """D1..D4 (complex) of four poses: places (4, 2) [m], angles (4,) [rad]."""
    P = places[:, 0] + 1j * places[:, 1]
    a = np.exp(1j * (angles - angles[0])) - 1
    d = P - P[0]

    def minor(j: int, k: int) -> complex:
        return a[j] * d[k] - a[k] * d[j]

    D2, D3, D4 = minor(2, 3), -minor(1, 3), minor(1, 2)
    return np.array([-(D2 + D3 + D4), D2, D3, D4])


def dyads(places: np.ndarray, angles: np.ndarray, samples: int = 72) -> tuple[np.ndarray, np.ndarray]:
    """Points of the centre-point curve M (k, 2) and their circle points C (k, 2) at the
    first pose [m], for `samples` crank turns beta_2 over a turn (two dyads or none each).
    The trivial dyads (the coupler itself, |W| ~ 0) are left out."""
    if len(places) != 4:
        raise ValueError("Burmester's construction takes exactly four poses")
    D1, D2, D3, D4 = compatibility(places, angles)
    P = places[:, 0] + 1j * places[:, 1]
    a = np.exp(1j * (angles - angles[0])) - 1
    d = P - P[0]
    centres, circles = [], []
    size = max(float(np.max(np.abs(d))), 1e-300)
    for beta2 in np.linspace(0.0, 2 * math.pi, samples, endpoint=False):
        K = -(D1 + D2 * np.exp(1j * beta2))
        for X in _triangle(K, abs(D3), abs(D4)):  # X = D3 e^{i beta3}
            e2, e3 = np.exp(1j * beta2) - 1, X / D3 - 1
            M = np.array([[e2, a[1]], [e3, a[2]]])
            if abs(np.linalg.det(M)) < 1e-12:
                continue
            W, Z = np.linalg.solve(M, np.array([d[1], d[2]]))
            if abs(W) < 1e-9 * size:
                continue
            centre, circle = P[0] - Z - W, P[0] - Z
            centres.append((centre.real, centre.imag))
            circles.append((circle.real, circle.imag))
    return np.array(centres).reshape(-1, 2), np.array(circles).reshape(-1, 2)


def _triangle(K: complex, r3: float, r4: float) -> list[complex]:
    """The X with |X| = r3 and |K - X| = r4 (two, one or none): the circles about 0 and K
    meet (model/compass.py)."""
    if K == 0:
        return []
    ends = np.array([[0.0, 0.0], [K.real, K.imag]])
    points, meets = compass(ends[0], ends[1], r3, r4, np.array([1.0, -1.0]))
    return [complex(*p) for p in points] if bool(meets.all()) else []


def four_bar_rows(places: np.ndarray, angles: np.ndarray, samples: int = 72) -> np.ndarray:
    """Motion-search rows (z (9), gamma) of the four-bars made of two Burmester dyads: the
    crank's at O2, the other's at O4, P and the poses' line as at the first pose."""
    M, C = dyads(places, angles, samples)
    rows = []
    for i in range(len(M)):
        for k in range(len(M)):
            ab = C[k] - C[i]
            coupler = float(np.hypot(*ab))
            if i == k or coupler < 1e-9:
                continue
            e = ab / coupler
            r = places[0] - C[i]
            along, across = float(r @ e), float(e[0] * r[1] - e[1] * r[0])
            rows.append((*M[i], *M[k], np.hypot(*(C[i] - M[i])), coupler, np.hypot(*(C[k] - M[k])), along,
                         across, math.remainder(angles[0] - math.atan2(e[1], e[0]), 2 * math.pi)))
    return np.array(rows).reshape(-1, 10)
