"""One batch of a workspace study's grid points (a Dask task): every point in every working
mode asked, on the mechanism this process built once (`WorkspaceMechanism`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmech.design.study.tolerance import Batch
from pinmech.design.workspace.file import WorkspaceSpec
from pinmech.design.workspace.solve import WorkspaceMechanism

_BUILT: dict[WorkspaceSpec, WorkspaceMechanism] = {}
FIELDS = ("det1", "det2", "sigma1", "sigma2", "kappa")


@dataclass(frozen=True)
class WorkspaceBatch:
    """Grid points start .. start + count - 1 (C order over the axes) in each mode:
    reached (count, modes) bool, motors (count, modes, legs) [rad or m], and each of FIELDS
    (count, modes) (NaN where not reached)."""

    start: int
    reached: np.ndarray
    motors: np.ndarray
    values: dict[str, np.ndarray]


@dataclass(frozen=True)
class PointsBatch:
    """Points given by their coordinates (count, axes) [m], each in working mode `modes[i]`
    (an index into the study's modes): a refinement level's new points (a Dask task)."""

    index: int
    points: np.ndarray
    modes: np.ndarray

    @property
    def count(self) -> int:
        return len(self.points)


def built(spec: WorkspaceSpec) -> WorkspaceMechanism:
    """This process's WorkspaceMechanism of the study, built on first use."""
    if spec not in _BUILT:
        _BUILT[spec] = WorkspaceMechanism(spec)
    return _BUILT[spec]


def grid_points(spec: WorkspaceSpec, start: int, count: int) -> np.ndarray:
    """The (count, axes) task-space coordinates [m] of grid points start .. start+count-1."""
    shape = tuple(a.count for a in spec.axes)
    index = np.unravel_index(np.arange(start, start + count), shape)
    values = [np.asarray(a.values) for a in spec.axes]
    return np.column_stack([v[i] for v, i in zip(values, index)])


def run_workspace_batch(spec: WorkspaceSpec, batch: Batch | PointsBatch):
    """Solve the batch's grid points in every mode, or its given points each in its own mode
    (then `reached`, `motors` and `values` have one mode column: the point's)."""
    wm = built(spec)
    if isinstance(batch, PointsBatch):
        return _given_points(wm, batch)
    if spec.space == "actuator":
        from pinmech.design.workspace.actuator_batch import run_actuator_batch

        return run_actuator_batch(spec, wm, batch)
    modes, legs = len(wm.modes), len(wm.legs)
    reached = np.zeros((batch.count, modes), bool)
    motors = np.full((batch.count, modes, legs), np.nan)
    values = {f: np.full((batch.count, modes), np.nan) for f in FIELDS}
    for i, x in enumerate(grid_points(spec, batch.start, batch.count)):
        for k, mode in enumerate(wm.modes):
            s = wm.solve(x, mode)
            reached[i, k] = s.reached
            motors[i, k] = s.motors
            for f in FIELDS:
                values[f][i, k] = getattr(s, f)
    return WorkspaceBatch(batch.start, reached, motors, values)


def _given_points(wm: WorkspaceMechanism, batch: PointsBatch) -> WorkspaceBatch:
    reached = np.zeros((batch.count, 1), bool)
    motors = np.full((batch.count, 1, len(wm.legs)), np.nan)
    values = {f: np.full((batch.count, 1), np.nan) for f in FIELDS}
    for i, (x, k) in enumerate(zip(batch.points, batch.modes)):
        s = wm.solve(x, wm.modes[int(k)])
        reached[i, 0], motors[i, 0] = s.reached, s.motors
        for f in FIELDS:
            values[f][i, 0] = getattr(s, f)
    return WorkspaceBatch(batch.index, reached, motors, values)
