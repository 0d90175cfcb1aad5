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
