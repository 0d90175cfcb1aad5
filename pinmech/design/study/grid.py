"""Grid studies: the outputs over every point of a grid of 1 to 3 parameters' values.

Grid point i is the i-th of the axes' values in row-major order (the last axis fastest);
the parameters off the grid keep their nominal values. No randomness: a batch holds the
points start .. start + count - 1, so the results do not depend on the batching or on the
number of Dask workers. A point that fails keeps its cause (variant.CAUSES) and NaN
outputs: it is counted and marked in the table, never dropped. For a planar linkage with
dyads, each point also carries its least transmission angle over the cycle.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.study.grid_transmission import has_dyads, least_transmission
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.file import StudySpec
from pinmech.design.study.variant import StudyMechanism
from pinmech.design.study.tolerance import Batch, BatchResult, solve_variants


def grid_size(spec: StudySpec) -> int:
    """How many grid points the study has."""
    return math.prod(axis.count for axis in spec.grid)


def grid_points(spec: StudySpec, nominal: np.ndarray, start: int, count: int) -> np.ndarray:
    """Grid points start .. start + count - 1 as parameter values (count, n_par) [m]."""
    shape = tuple(axis.count for axis in spec.grid)
    index = np.unravel_index(np.arange(start, start + count), shape)
    p = np.tile(np.asarray(nominal, dtype=float), (count, 1))
    for axis, i in zip(spec.grid, index):
        p[:, axis.param] = np.asarray(axis.values)[i]
    return p


def run_grid_batch(sm: StudyMechanism, outputs: StudyOutputs, batch: Batch) -> BatchResult:
    """Solve the batch's grid points over the cycle, with each one's least transmission
    angle [rad] as the result's `extra` (None where the mechanism has no dyad)."""
    p = grid_points(sm.spec, sm.nominal, batch.start, batch.count)
    drivers = list(sm.sweep.drivers.names)
    mu = (lambda q: least_transmission(sm.mechanism, drivers, q)) if has_dyads(sm.mechanism, drivers) else None
    return solve_variants(sm, outputs, batch, p, mu)


def cycle_range(y: np.ndarray, kinds: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Each output's min and max over the cycle (N, n_out) [m, rad] from y (N, steps, n_out).

    An angle is unwrapped along the cycle first, so that a link turning through +-180 deg
    is not read as a jump of 360 deg. Failed points (NaN rows) stay NaN.
    """
    y = np.array(y, dtype=float)
    angles = [j for j, k in enumerate(kinds) if k == "angle"]
    ok = ~np.isnan(y).any(axis=(1, 2))
    if angles and ok.any():
        y[np.ix_(ok, np.arange(y.shape[1]), angles)] = np.unwrap(y[np.ix_(ok, np.arange(y.shape[1]), angles)], axis=1)
    lo, hi = np.full(y.shape[::2], np.nan), np.full(y.shape[::2], np.nan)
    lo[ok], hi[ok] = y[ok].min(axis=1), y[ok].max(axis=1)
    return lo, hi


def failures(causes: list[str]) -> dict[str, int]:
    """Cause -> how many grid points failed so."""
    counted: dict[str, int] = {}
    for cause in causes:
        if cause:
            counted[cause] = counted.get(cause, 0) + 1
    return counted
