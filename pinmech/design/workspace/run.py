"""Workspace studies of parallel mechanisms (`kind = "workspace"`): the reachable workspace
of each working mode and assembly mode on a task-space grid, the type I and type II
singularity loci, the conditioning map, and the area or volume with its bound.

    import pinmech
    result = pinmech.study("models/studies/five_bar_workspace.toml", workers=2)
    print(result.measures["+-"].value)      # m^2

The grid's points are solved in batches here or on Dask (cluster.py); the maps are then
read from the whole grid (maps.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pinmech.design.cluster import Runner, batch_runner
from pinmech.design.workspace.grid_maps import GridMaps, grid_batches
from pinmech.design.study.tolerance import batches
from pinmech.design.workspace.batch import FIELDS, PointsBatch, WorkspaceBatch, built
from pinmech.design.workspace.file import WorkspaceSpec
from pinmech.design.workspace.maps import boundary_edges, distances, sign_change_edges
from pinmech.design.workspace.measure import Measure, refined_measures
from pinmech.exceptions import SceneError


@dataclass(frozen=True)
class WorkspaceResult(GridMaps):
    """A workspace study's maps (SI; grid axes first, then the mode axis).

    Fields (SI):
        spec: the study file; modes: working modes ("+-": a sign a leg); motors: motor names.
        length: the characteristic length L [m]; coords: each axis's values [m].
        reached: (grid..., modes) bool; motor_q: (grid..., modes, legs) [rad or m];
        values: det1, det2, sigma1, sigma2, kappa (grid..., modes) (NaN where not reached);
        measures: per mode, and per "mode/assembly" (assembly "+" or "-": the sign of det
            Phi_p), the area [m^2] or volume [m^3] with its bound;
        type1, type2: per mode, locus midpoints (k, axes) [m]; dist1, dist2: (grid...,
            modes) distance to them [m] (within `locus_bound`).
    """

    modes: tuple[str, ...]
    motor_q: np.ndarray
    dist1: np.ndarray
    dist2: np.ndarray

    @property
    def kind(self) -> str:
        """"area" for a plane grid, "volume" for a box."""
        return "area" if len(self.coords) == 2 else "volume"


def run_workspace(spec: WorkspaceSpec, *, workers: int = 0, scheduler: str | None = None,
                  progress: Callable[[int, int], None] | None = None):
    """Solve the study's grid (here, or on Dask) and read its maps; `progress` is called with
    (grid points done, grid points) as each batch finishes. A task-space grid gives a
    WorkspaceResult, a grid over the motors (`[workspace.actuators]`) an ActuatorResult
    (actuator.py).

    Raises:
        SceneError: the study file's or the scene's mistakes, a mechanism that is not parallel
            (key "scene"), a grid where no point is reached in any mode (key "workspace");
            FrameNotFound: an unknown end point.
    """
    wm = built(spec)  # here first: the file's and the mechanism's errors before any worker starts
    if spec.space == "actuator":
        from pinmech.design.workspace.actuator import run_actuator_workspace

        return run_actuator_workspace(spec, wm, workers=workers, scheduler=scheduler, progress=progress)
    with batch_runner(workers=workers, scheduler=scheduler) as run:
        results: list[WorkspaceBatch] = grid_batches(spec, run, progress)
        return _maps(spec, wm, results, run)


def _maps(spec: WorkspaceSpec, wm, results: list[WorkspaceBatch], run: Runner) -> WorkspaceResult:
    """The grid's maps from its batches; the measures refined through `run`."""
    shape = tuple(a.count for a in spec.axes)
    modes = wm.modes
    reached = np.concatenate([b.reached for b in results]).reshape(*shape, len(modes))
    if not reached.any():
        span = ", ".join(f"{a.name} {a.start / spec.unit_si:g} to {a.stop / spec.unit_si:g} {spec.unit}"
                         for a in spec.axes)
        raise SceneError(f"no grid point is reachable in working modes {', '.join(modes)}: the grid "
                         f"({span}) misses the workspace of '{spec.point}'", path=str(spec.path), key="workspace")
    values = {f: np.concatenate([b.values[f] for b in results]).reshape(*shape, len(modes)) for f in FIELDS}
    motor_q = np.concatenate([b.motors for b in results]).reshape(*shape, len(modes), len(wm.legs))
    coords = [np.asarray(a.values) for a in spec.axes]
    mesh = np.stack(np.meshgrid(*coords, indexing="ij"), axis=-1)
    measures, type1, type2 = {}, {}, {}
    dist1, dist2 = np.full(reached.shape, np.nan), np.full(reached.shape, np.nan)
    for k, mode in enumerate(modes):
        here = reached[..., k]
        measures.update(_mode_measures(spec, run, k, mode, here, values["det2"][..., k], coords))
        type1[mode] = np.concatenate([boundary_edges(here, coords), sign_change_edges(values["det1"][..., k], coords)])
        type2[mode] = sign_change_edges(values["det2"][..., k], coords)
        points = mesh[here]
        dist1[..., k][here] = distances(points, type1[mode])
        dist2[..., k][here] = distances(points, type2[mode])
    return WorkspaceResult(spec=spec, motors=wm.motors, length=wm.length, coords=coords, reached=reached,
                           values=values, measures=measures, type1=type1, type2=type2, modes=modes,
                           motor_q=motor_q, dist1=dist1, dist2=dist2)


def _members(mode: str, reached: np.ndarray, det2: np.ndarray) -> dict[str, np.ndarray]:
    """A working mode's regions: reached, and reached in each assembly mode (sign of det Phi_p)."""
    return {mode: reached, f"{mode}/+": reached & (np.sign(det2) > 0), f"{mode}/-": reached & (np.sign(det2) < 0)}


def _mode_measures(spec: WorkspaceSpec, run: Runner, k: int, mode: str, reached: np.ndarray, det2: np.ndarray,
                   coords: list[np.ndarray]) -> dict[str, Measure]:
    """The area or volume of working mode k and of its two assembly modes, each refined
    (measure.py) by solving the new corners in mode k through `run`."""
    def member(points: np.ndarray) -> dict[str, np.ndarray]:
        todo = [PointsBatch(b.index, points[b.start : b.start + b.count], np.full(b.count, k))
                for b in batches(len(points), spec.batch)]
        done = run(spec, todo)
        return _members(mode, np.concatenate([d.reached[:, 0] for d in done]),
                        np.concatenate([d.values["det2"][:, 0] for d in done]))

    return refined_measures(_members(mode, reached, det2), coords, member, depth=spec.refine_depth,
                            tolerance=spec.area_tolerance)
