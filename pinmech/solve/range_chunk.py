"""A sweep's poses as arrays, chunk by chunk, and the helpers that fill and join them."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.solve.batch import BatchSolution
from pinmech.solve.results import Accuracy, LoopSolution


@dataclass(frozen=True)
class RangeChunk:
    """Consecutive poses of a range, as arrays.

    Attributes:
        start: index of the first pose in the range.
        values: the swept driver's value at each pose [rad or m].
        solution: q, v, a and the accuracy of each pose (NaN rows where a pose failed).
        interpolated: True where a pose was interpolated rather than solved.
        errors: position in the chunk -> the error of a pose that failed.
        notes: position in the chunk -> what the path passed on its way to that pose (a
            change point, or a fold crossed with `through_folds`: the assembly changed).
    """

    start: int
    values: np.ndarray
    solution: BatchSolution
    interpolated: np.ndarray
    errors: dict[int, PinmechError] = field(default_factory=dict)
    notes: dict[int, str] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.values)

    def pose(self, j: int) -> LoopSolution | None:
        """Pose j of the chunk as a `LoopSolution` (None where it failed)."""
        return None if j in self.errors else self.solution.solution(j)


class _Fallback(Exception):
    """A chunk that the quick path cannot take: solve it pose by pose."""


_ACCURACY = ("residual", "iterations", "condition", "sigma_min", "velocity_residual", "acceleration_residual")


def _accuracy_arrays(n: int) -> dict[str, np.ndarray]:
    acc = {name: np.zeros(n) for name in _ACCURACY}
    acc["iterations"] = np.zeros(n, dtype=int)
    acc["interpolation"] = np.zeros((n, 3))
    return acc


def _store(acc: dict[str, np.ndarray], j: int, accuracy: Accuracy) -> None:
    for name, value in zip(_ACCURACY, (accuracy.residual, accuracy.iterations, accuracy.condition,
                                        accuracy.sigma_min, accuracy.velocity_residual,
                                        accuracy.acceleration_residual)):
        acc[name][j] = value


def _stack(rows: list[LoopSolution | None], solver) -> BatchSolution:
    """LoopSolutions (None where a pose failed: NaN rows) as one BatchSolution."""
    n, model = len(rows), solver.model
    q, v, a = np.full((n, model.nq), np.nan), np.full((n, model.nv), np.nan), np.full((n, model.nv), np.nan)
    acc = {name: np.full(n, np.nan) for name in _ACCURACY}
    acc["iterations"] = np.zeros(n, dtype=int)
    for j, sol in enumerate(rows):
        if sol is not None:
            q[j], v[j], a[j] = sol.q, sol.v, sol.a
            _store(acc, j, sol.accuracy)
    return BatchSolution(q, v, a, *(acc[name] for name in _ACCURACY), solver.drivers)


def _concat(a: RangeChunk, b: RangeChunk) -> RangeChunk:
    """Two consecutive chunks as one."""
    sa, sb = a.solution, b.solution
    fields = ("q", "v", "a", *_ACCURACY)
    added = None
    if sa.interpolation is not None or sb.interpolation is not None:
        added = np.concatenate([np.zeros((len(x), 3)) if x.interpolation is None else x.interpolation for x in (sa, sb)])
    solution = BatchSolution(*(np.concatenate((getattr(sa, f), getattr(sb, f))) for f in fields), sa.drivers,
                             interpolation=added)
    errors = {**a.errors, **{len(a) + j: e for j, e in b.errors.items()}}
    return RangeChunk(a.start, np.concatenate((a.values, b.values)), solution,
                      np.concatenate((a.interpolated, b.interpolated)), errors)
