"""The compass construction: the point at r1 from a and r2 from b, left or right of a -> b,
the one closed form used to draw a linkage's `from = [P, Q], lengths = [...]` joints
(model/linkage.py) and to solve a synthesis candidate's dyads (design/synthesis/fourbar.py,
design/synthesis/burmester.py). Batched: arrays broadcast, points in the last axis (2)."""

from __future__ import annotations

import numpy as np


def compass(a: np.ndarray, b: np.ndarray, r1: np.ndarray | float, r2: np.ndarray | float,
            side: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """The meeting point of the circles of radii r1 about a and r2 about b [m], on `side`
    (+1: left of a -> b, -1: right), and whether they meet (r1^2 >= along^2, along the
    foot's distance from a: along = (d^2 + r1^2 - r2^2) / 2d). Where they do not meet (or
    just miss by rounding), the point is the foot on a -> b (across clipped to 0).

    Shapes: a, b (..., 2); r1, r2, side broadcast against (...). d = |b - a| must be > 0.
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    d2 = dx * dx + dy * dy
    d = np.sqrt(d2)
    along = (d2 + r1 * r1 - r2 * r2) / (2 * d)
    across2 = r1 * r1 - along * along
    across = np.sqrt(np.maximum(across2, 0.0)) * side
    ux, uy = dx / d, dy / d
    point = np.stack((a[..., 0] + along * ux - across * uy, a[..., 1] + along * uy + across * ux), -1)
    return point, across2 >= 0
