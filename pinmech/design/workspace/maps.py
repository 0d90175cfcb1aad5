"""What a workspace grid says, from its points alone: the singularity loci where a
determinant changes sign between grid neighbours, and each point's distance to them (the
area or volume and its bound: measure.py).

Loci: an edge between two reached neighbours whose determinants have opposite signs holds
a zero of it (for a continuous determinant): its midpoint is within half a step of the
locus along the edge. Type I loci also include the edges where reachability changes (the
workspace boundary of a mode is where a leg stretches or folds).
"""

from __future__ import annotations

import numpy as np


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
