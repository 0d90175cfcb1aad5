"""The area or volume of a region known only by a membership test at points (a workspace
mode: "is this point reached?"), as a rigorous interval, refined adaptively where the
region's boundary crosses a grid cell.

Cells are the boxes between neighbouring grid points (their corners are grid points).
Assumption (A): the region's boundary crosses every edge of every cell examined at most
once, and no piece of the region or of its complement lies inside a cell without holding
one of that cell's corners (the grid resolves the region). Under (A):

* a cell whose corners all agree is wholly in or wholly out: an edge whose two ends agree
  is crossed an even number of times, so not at all, and nothing hides inside;
* a cell whose corners disagree (a *mixed* cell) is partly in: its share lies in [0, cell].

So the exact measure lies in [inside, inside + mixed] (sums of cell sizes); the value is
that interval's midpoint and the bound its half width. Refinement splits each mixed cell
into 2^d halves (the new corners tested), keeps the halves that agree, and splits the
mixed ones again, to `depth` levels or until bound <= tolerance x value: the bound halves
a level while the boundary's length (area) stays put. Only the grid's box is measured:
a region touching the grid's outer faces is flagged (`edge`), as it may go on beyond.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from itertools import product

import numpy as np

#: membership of points: (n, d) coordinates [m] -> key -> (n,) bool
Membership = Callable[[np.ndarray], dict[str, np.ndarray]]
MAX_DEPTH = 10


@dataclass(frozen=True)
class Measure:
    """An area [m^2] or volume [m^3]: value +- bound holds the exact measure under (A).

    Attributes:
        value: the interval's midpoint; bound: its half width; edge: the region touches the
            grid's outer faces (it may go on beyond the grid); depth: refinement levels used;
        points: points tested by the refinement (beyond the grid's).
    """

    value: float
    bound: float
    edge: bool
    depth: int = 0
    points: int = 0

    @property
    def interval(self) -> tuple[float, float]:
        """(lower, upper) [m^2 or m^3]: the exact measure lies within it under (A)."""
        return self.value - self.bound, self.value + self.bound

    @property
    def relative_bound(self) -> float:
        """bound / value (inf for an empty region)."""
        return self.bound / self.value if self.value > 0 else float("inf")


def cell(steps: tuple[float, ...]) -> float:
    """One grid cell's area or volume [m^2 or m^3]."""
    return float(np.prod(steps))


def measure(reached: np.ndarray, steps: tuple[float, ...]) -> Measure:
    """The measure of a boolean grid (axes in the grid's order) without refinement."""
    inside, mixed = _classify(reached)
    size = cell(steps)
    lo, width = float(inside.sum()) * size, float(mixed.sum()) * size
    return Measure(lo + width / 2, width / 2, _touches_edge(reached))


def refined_measures(grid: dict[str, np.ndarray], coords: list[np.ndarray], member: Membership, *,
                     depth: int, tolerance: float | None) -> dict[str, Measure]:
    """Each key's measure, its mixed cells refined by `member` (called once a level with the
    new points of every key still refining).

    Args:
        grid: key -> bool (grid shape): membership at the grid points.
        coords: the grid's evenly spaced axes [m].
        member: membership of new points for every key of `grid`.
        depth: the most levels of halving (0: none); tolerance: stop a key's refinement
            once its bound <= tolerance x value (None: refine to `depth`).
    """
    steps = np.array([float(c[1] - c[0]) for c in coords])
    start = np.array([float(c[0]) for c in coords])
    scale = 1 << depth  # lattice units a grid step: every corner down to `depth` is a whole number
    keys = list(grid)
    memo: dict[tuple[int, ...], dict[str, bool]] = {}
    for index in np.ndindex(*next(iter(grid.values())).shape):
        memo[tuple(i * scale for i in index)] = {k: bool(grid[k][index]) for k in keys}
    inside, mixed, level_of = {}, {}, {}
    for k in keys:
        full, part = _classify(grid[k])
        inside[k] = float(full.sum()) * cell(tuple(steps))
        mixed[k] = np.argwhere(part) * scale  # origins of mixed cells [lattice units]
        level_of[k] = 0
    tested = 0
    for level in range(1, depth + 1):
        size = cell(tuple(steps / (1 << (level - 1))))
        busy = [k for k in keys if len(mixed[k]) and not _done(inside[k], len(mixed[k]) * size, tolerance)]
        if not busy:
            break
        half = scale >> level  # a child's side [lattice units]
        children = {k: _children(mixed[k], half) for k in busy}
        corners = np.unique(np.concatenate([_corners(c, half) for c in children.values()]), axis=0)
        new = np.array([c for c in corners if tuple(c) not in memo], dtype=int).reshape(-1, len(coords))
        if len(new):
            found = member(start + new * (steps / scale))
            for i, c in enumerate(new):
                memo[tuple(c)] = {k: bool(found[k][i]) for k in keys}
            tested += len(new)
        for k in busy:
            agree_in, part = _classify_children(children[k], half, memo, k)
            inside[k] += float(agree_in.sum()) * size / (1 << len(coords))
            mixed[k] = children[k][part]
            level_of[k] = level
    out = {}
    for k in keys:
        width = len(mixed[k]) * cell(tuple(steps / (1 << level_of[k])))
        out[k] = Measure(inside[k] + width / 2, width / 2, _touches_edge(grid[k]), level_of[k], tested)
    return out


def _done(inside: float, width: float, tolerance: float | None) -> bool:
    """Whether a key's interval [inside, inside + width] is already within tolerance."""
    return tolerance is not None and width / 2 <= tolerance * (inside + width / 2)


def _classify(reached: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(cells whose corners are all in, cells whose corners disagree), shape grid - 1."""
    corners = [reached[tuple(slice(o, o + n - 1) for o, n in zip(offset, reached.shape))]
               for offset in product((0, 1), repeat=reached.ndim)]
    every, some = np.logical_and.reduce(corners), np.logical_or.reduce(corners)
    return every, some & ~every


def _children(origins: np.ndarray, half: int) -> np.ndarray:
    """The 2^d halves' origins of cells at `origins` (side 2 half) [lattice units]."""
    offsets = np.array(list(product((0, half), repeat=origins.shape[1])), dtype=int)
    return (origins[:, None, :] + offsets[None, :, :]).reshape(-1, origins.shape[1])


def _corners(origins: np.ndarray, side: int) -> np.ndarray:
    """Every corner of cells of `side` at `origins` [lattice units]."""
    offsets = np.array(list(product((0, side), repeat=origins.shape[1])), dtype=int)
    return (origins[:, None, :] + offsets[None, :, :]).reshape(-1, origins.shape[1])


def _classify_children(origins: np.ndarray, side: int, memo: dict, key: str) -> tuple[np.ndarray, np.ndarray]:
    """(all corners in, corners disagree) for cells of `side` at `origins`."""
    corners = _corners(origins, side).reshape(len(origins), -1, origins.shape[1])
    values = np.array([[memo[tuple(c)][key] for c in cell_corners] for cell_corners in corners], dtype=bool)
    every, some = values.all(axis=1), values.any(axis=1)
    return every, some & ~every


def _touches_edge(reached: np.ndarray) -> bool:
    """Whether a point on the grid's outer faces is in."""
    return bool(any(np.take(reached, i, axis=a).any() for a in range(reached.ndim) for i in (0, -1)))
