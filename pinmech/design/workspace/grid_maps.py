"""What a workspace grid's maps (task space or the motors') share: their grid, what each
point reached, the determinants and conditioning, the measures, the loci, and what they say
of their own resolution."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmech.design.study.tolerance import batches
from pinmech.design.workspace.file import WorkspaceSpec
from pinmech.design.workspace.measure import Measure


@dataclass(frozen=True)
class GridMaps:
    """A workspace study's maps over grid axes `coords` (1-D arrays in the axes' units: m,
    or rad for a motor's angle): the study `spec`, the `motors`' names, the characteristic
    `length` [m], what each grid point `reached` (grid..., columns), the determinants and
    conditioning in `values` (det1, det2, sigma1, sigma2, kappa), each region's area or
    volume with its bound in `measures`, and each region's locus midpoints (k, axes) in
    `type1` and `type2`. The fields each kind adds are in its own class.
    """

    spec: WorkspaceSpec
    motors: tuple[str, ...]
    length: float
    coords: list[np.ndarray]
    reached: np.ndarray
    values: dict[str, np.ndarray]
    measures: dict[str, Measure]
    type1: dict[str, np.ndarray]
    type2: dict[str, np.ndarray]

    @property
    def steps(self) -> tuple[float, ...]:
        """The grid's steps [the axes' units]."""
        return tuple(float(c[1] - c[0]) for c in self.coords)

    @property
    def locus_bound(self) -> float:
        """How far a locus midpoint (and so a distance to it) can be from the locus: half the
        largest step [the axes' units]."""
        return max(self.steps) / 2


def grid_batches(spec: WorkspaceSpec, run, progress=None) -> list:
    """The grid's points solved in batches of `spec.batch` by `run` (cluster.batch_runner's:
    here or on Dask), in order; `progress(points done, points)` after each batch."""
    done = [0]

    def tick(batch) -> None:
        done[0] += batch.count
        progress(done[0], spec.size)

    return run(spec, batches(spec.size, spec.batch), tick if progress else None)
