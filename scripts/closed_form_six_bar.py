"""Closed form of the Stephenson III six-bar of tests/_mechanisms.py, derived apart from
pinmech: the four-bar O2-A-B-O4 (scripts/closed_form.py), then the dyad C-D-O6 as the
intersection of the circles (C, b2) and (O6, c2).

    C = A + R(theta3) (cx, cy)
    D = C + x w + branch2 h k x w,  w = (O6 - C) / |O6 - C|,  x = (b2^2 - c2^2 + L^2) / 2L

``branch2 = +1`` puts D to the left of the directed line C -> O6.
"""

from __future__ import annotations

import numpy as np
from closed_form import four_bar, perp


def stephenson_d(theta2, a, b, c, d, cx, cy, b2, c2, o6, branch=+1, branch2=+1) -> np.ndarray:
    """Position of the pin D [m], shape (..., 2), for crank angles theta2 [rad].

    Raises:
        ValueError: where a loop cannot close.
    """
    fb = four_bar(theta2, 0.0, 0.0, a, b, c, d, branch)
    e3 = np.stack([np.cos(fb.theta3), np.sin(fb.theta3)], axis=-1)
    C = fb.A + cx * e3 + cy * perp(e3)
    w = np.asarray(o6, dtype=float) - C
    L = np.hypot(w[..., 0], w[..., 1])
    if np.any((L > b2 + c2) | (L < abs(b2 - c2))):
        raise ValueError("the dyad C-D-O6 cannot close")
    x = (b2**2 - c2**2 + L**2) / (2 * L)
    h = np.sqrt(np.maximum(b2**2 - x**2, 0.0))
    wh = w / L[..., None]
    return C + x[..., None] * wh + branch2 * h[..., None] * perp(wh)


def stephenson_far_crank(phi6: float, a, b, c, d, cx, cy, b2, c2, o6, samples: int = 20000) -> list[dict]:
    """Every assembly of the same six-bar driven at its far crank O6-D instead.

    With the crank O6-D at angle phi6 [rad] (D = O6 + c2 (cos phi6, sin phi6)), the
    four-bar O2-A-B-O4 has one freedom left: its crank angle theta2. An assembly is a
    root of f(theta2) = |C(theta2) - D|^2 - b2^2 on either branch of the four-bar (C the
    coupler point of the closed form above): the coupler curve meets the circle (D, b2).
    The roots are bracketed on a grid of `samples` crank angles per branch and bisected
    to rounding; nothing here shares code with pinmech.

    Returns:
        one dict per assembly: the pins "A", "B", "C", "D" [m] and "theta2", "branch".
    """
    D = np.asarray(o6, dtype=float) + c2 * np.array([np.cos(phi6), np.sin(phi6)])
    out = []
    for branch in (+1, -1):
        def f(theta2):
            fb = four_bar(theta2, 0.0, 0.0, a, b, c, d, branch)
            e3 = np.stack([np.cos(fb.theta3), np.sin(fb.theta3)], axis=-1)
            C = fb.A + cx * e3 + cy * perp(e3)
            return np.sum((C - D) ** 2, axis=-1) - b2**2

        grid = np.linspace(0.0, 2 * np.pi, samples + 1)
        values = f(grid)
        brackets = np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)
        lo, hi, f_lo = grid[brackets], grid[brackets + 1], values[brackets]
        for _ in range(56):  # bisection of every bracket at once, to the spacing of floats
            mid = 0.5 * (lo + hi)
            f_mid = f(mid)
            left = np.sign(f_mid) == np.sign(f_lo)
            lo, hi, f_lo = np.where(left, mid, lo), np.where(left, hi, mid), np.where(left, f_mid, f_lo)
        for theta2 in 0.5 * (lo + hi):
            fb = four_bar(theta2, 0.0, 0.0, a, b, c, d, branch)
            e3 = np.array([np.cos(fb.theta3), np.sin(fb.theta3)])
            C = fb.A + cx * e3 + cy * perp(e3)
            out.append({"theta2": float(theta2), "branch": branch, "A": fb.A, "B": fb.B, "C": C, "D": D})
    return out
