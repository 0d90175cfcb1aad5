"""Unit directions from the vectors users write (gravity, axes, lines), at any scale.

np.linalg.norm of [0, -1e200, 0] overflows to inf (the direction became 0 and gravity
went off in silence) and of [1e-200, 0, 0] underflows to 0 (refused as "[0, 0, 0]").
Dividing by the largest |component| first brings every vector to norm in [1, sqrt(n)].
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def unit_vector(values: Sequence[float] | np.ndarray) -> np.ndarray | None:
    """values / |values| [-], or None for a zero or non-finite vector (the caller names it)."""
    v = np.asarray(values, dtype=float)
    if v.size == 0 or not np.all(np.isfinite(v)):
        return None
    largest = float(np.max(np.abs(v)))
    if largest == 0.0:
        return None
    scaled = v / largest
    return scaled / float(np.linalg.norm(scaled))


def written(values: Sequence[float] | np.ndarray) -> str:
    """A vector as the user wrote it, every number at full precision ([1e-200, 0, 0])."""
    items = values.tolist() if isinstance(values, np.ndarray) else list(values)
    return "[" + ", ".join(repr(float(x)) if isinstance(x, np.floating) else repr(x) for x in items) + "]"


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for 3-vectors; np.cross costs ~10 us per call, this ~1 us (hot paths)."""
    return np.array((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))
