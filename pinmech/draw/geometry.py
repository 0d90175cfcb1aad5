"""Small geometry of drawings: bounding boxes, screen axes, round lengths, 4x4 transforms."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin


def _local_corners(obj: pin.GeometryObject) -> np.ndarray:
    """The 8 corners of a visual's bounding box in its own frame [m] (its origin if none)."""
    geometry = obj.geometry
    try:
        geometry.computeLocalAABB()
        lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    except (AttributeError, RuntimeError):
        return np.zeros((1, 3))
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo <= hi)):
        return np.zeros((1, 3))
    return np.array(list(itertools.product(*zip(lo, hi))))


def _screen_up(back: np.ndarray) -> np.ndarray:
    """The world direction shown upwards when the camera sits along `back` (unit).

    meshcat's orbit keeps world z up; looking along z itself, world y is shown up.
    """
    axis = np.array([0.0, 1.0, 0.0]) if abs(back[2]) > 0.999 else np.array([0.0, 0.0, 1.0])
    up = axis - back * (back @ axis)
    return up / np.linalg.norm(up)


def _size(points: np.ndarray) -> float:
    """Largest side of the points' bounding box [m] (1 mm at least, so that there is a view)."""
    return max(float(np.max(np.ptp(points, axis=0))), 1e-3) if len(points) else 1e-3


def _round_length(length: float) -> float:
    """The largest of 1, 2, 5 times a power of ten that is at most `length` [m]."""
    power = 10.0 ** math.floor(math.log10(length))
    return max(m * power for m in (1, 2, 5) if m * power <= length * (1 + 1e-9))


def _translation(p: Any) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def _pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = _translation(p)
    T[:3, :3] = R
    return T


def _hex(rgb: Sequence[float]) -> int:
    r, g, b = (round(255 * min(max(c, 0.0), 1.0)) for c in rgb[:3])
    return r << 16 | g << 8 | b


def _node(name: str) -> str:
    """A point's name as one meshcat path element."""
    return name.replace("/", "_") or "_"
