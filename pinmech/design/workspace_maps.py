"""What a workspace grid says, from its points alone: the area or volume reached and its
discretisation bound, the singularity loci where a determinant changes sign between grid
neighbours, and each point's distance to them.

Area: each reached grid point stands for one cell (the product of the steps). Only cells
the workspace's boundary crosses can be counted wrongly, and every such cell lies next to
a neighbour of the other kind: the bound is (points with a neighbour of the other kind) x
cell. It holds when the boundary is resolved by the grid (no sliver of the workspace
thinner than a step between two points); points on the grid's edge are flagged, as the
workspace may go on beyond it.

Loci: an edge between two reached neighbours whose determinants have opposite signs holds
a zero of it (for a continuous determinant): its midpoint is within half a step of the
locus along the edge. Type I loci also include the edges where reachability changes (the
workspace boundary of a mode is where a leg stretches or folds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Measure:
    """A mode's area [m^2] or volume [m^3], its bound, and whether it touches the grid's edge."""

    value: float
    bound: float
    edge: bool


def cell(steps: tuple[float, ...]) -> float:
    """One grid cell's area or volume [m^2 or m^3]."""
    return float(np.prod(steps))


def measure(reached: np.ndarray, steps: tuple[float, ...]) -> Measure:
    """The measure of a boolean grid (axes in the grid's order) with its bound."""
    border = _boundary_points(reached)
    edge = any(np.take(reached, i, axis=a).any() for a in range(reached.ndim) for i in (0, -1))
    return Measure(reached.sum() * cell(steps), border.sum() * cell(steps), bool(edge))


def _boundary_points(reached: np.ndarray) -> np.ndarray:
    """Points with a neighbour (along an axis) of the other kind."""
    out = np.zeros(reached.shape, bool)
    for a in range(reached.ndim):
        differ = np.diff(reached.astype(np.int8), axis=a) != 0
        lo = [slice(None)] * reached.ndim
        hi = [slice(None)] * reached.ndim
        lo[a], hi[a] = slice(0, -1), slice(1, None)
        out[tuple(lo)] |= differ
        out[tuple(hi)] |= differ
    return out


def sign_change_edges(value: np.ndarray, coords: list[np.ndarray]) -> np.ndarray:
    """Midpoints (k, axes) [m] of edges between finite neighbours whose values have opposite signs."""
    return _edges(value, coords, lambda a, b: np.isfinite(a) & np.isfinite(b) & (np.sign(a) * np.sign(b) < 0))


def boundary_edges(reached: np.ndarray, coords: list[np.ndarray]) -> np.ndarray:
    """Midpoints (k, axes) [m] of edges between a reached and an unreached neighbour."""
    return _edges(reached, coords, lambda a, b: a != b)


def _edges(value: np.ndarray, coords: list[np.ndarray], differ) -> np.ndarray:
    mesh = np.meshgrid(*coords, indexing="ij")
    out = []
    for a in range(value.ndim):
        lo = [slice(None)] * value.ndim
        hi = [slice(None)] * value.ndim
        lo[a], hi[a] = slice(0, -1), slice(1, None)
        mask = differ(value[tuple(lo)], value[tuple(hi)])
        out.append(np.column_stack([(m[tuple(lo)][mask] + m[tuple(hi)][mask]) / 2 for m in mesh]))
    return np.concatenate(out) if out else np.zeros((0, value.ndim))


def distances(points: np.ndarray, locus: np.ndarray) -> np.ndarray:
    """Each point's distance [m] to the nearest locus midpoint (inf if the locus is empty).
    Within half the largest step of the distance to the locus itself."""
    if len(locus) == 0:
        return np.full(len(points), np.inf)
    out = np.empty(len(points))
    chunk = max(1, 1_000_000 // len(locus))  # ~24 MB of differences at a time
    for s in range(0, len(points), chunk):
        d = points[s : s + chunk, None, :] - locus[None, :, :]
        out[s : s + chunk] = np.sqrt(np.min(np.einsum("ijk,ijk->ij", d, d), axis=1))
    return out
