"""Closed form of the Jansen leg of models/jansen_leg.urdf, derived apart from pinmech: each
new pin is the intersection of two circles about pins already placed (dyads, in turn).

Theo Jansen's numbers (cm, here m): the crank axis O at the origin, the fixed pivot
B = (-a, -l), the crank pin A = m (cos theta, sin theta); then
C from (A, j) and (B, b), D from (A, k) and (B, c), E from (B, d) and (C, e),
F from (E, f) and (D, g), the foot G from (D, i) and (F, h).

    P = Q + x u + side h (k x u),  u = (R - Q) / |R - Q|,  x = (rQ^2 - rR^2 + L^2) / 2L,
    h = sqrt(rQ^2 - x^2)

with `side` +1 or -1 fixed per dyad: the walking assembly of the Strandbeest (C above the
crank, the foot G at the bottom).
"""

from __future__ import annotations

import numpy as np

#: Jansen's "holy numbers" [m].
HOLY = {"a": 0.38, "b": 0.415, "c": 0.393, "d": 0.401, "e": 0.558, "f": 0.394, "g": 0.367,
        "h": 0.657, "i": 0.49, "j": 0.50, "k": 0.619, "l": 0.078, "m": 0.15}


def _dyad(Q: np.ndarray, rQ: float, R: np.ndarray, rR: float, side: int) -> np.ndarray:
    """The point at rQ from Q and rR from R, on the `side` of the line Q -> R [m], (..., 2)."""
    w = R - Q
    L = np.hypot(w[..., 0], w[..., 1])
    x = (rQ**2 - rR**2 + L**2) / (2 * L)
    h2 = rQ**2 - x**2
    if np.any(h2 < 0):
        raise ValueError("a dyad of the Jansen leg cannot close")
    u = w / L[..., None]
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    return Q + x[..., None] * u + side * np.sqrt(h2)[..., None] * n


def jansen_leg(theta) -> dict[str, np.ndarray]:
    """The pins O, A, B, C, D, E, F, G [m], each of shape (..., 2), at crank angles theta [rad]."""
    n = HOLY
    theta = np.asarray(theta, dtype=float)
    A = n["m"] * np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    B = np.broadcast_to(np.array([-n["a"], -n["l"]]), A.shape)
    C = _dyad(A, n["j"], B, n["b"], -1)
    D = _dyad(A, n["k"], B, n["c"], +1)
    E = _dyad(B, n["d"], C, n["e"], +1)
    F = _dyad(E, n["f"], D, n["g"], -1)
    G = _dyad(D, n["i"], F, n["h"], +1)
    return {"O": np.zeros_like(A), "A": A, "B": B, "C": C, "D": D, "E": E, "F": F, "G": G}
