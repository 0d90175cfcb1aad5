"""Actuator-space workspace studies (`[workspace.actuators]`): at each cell of a grid over
the motors' values, the forward kinematics in each assembly mode (forward.py),
the type II locus in actuator space, and the task-space image of the grid.

    import pinmech
    result = pinmech.study("models/studies/five_bar_actuators.toml")
    result.reached[..., 0], result.end[..., 0, :]   # assembly "+": found?, end point [m]

Type II in actuator space: an assembly mode ends where its solution meets the other sign's
and both vanish (det Phi_p -> 0: the five-bar's distal links collinear), so the locus is
the edge between a cell where the assembly exists and one where it does not (its midpoint,
within half a step). Type I: det K changes sign between neighbours of one assembly (a leg
stretched or folded, its working mode changing).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmech.design.cluster import batch_runner
from pinmech.design.workspace.grid_maps import GridMaps, grid_batches
from pinmech.design.workspace.actuator_batch import ASSEMBLIES, FIELDS, ActuatorBatch
from pinmech.design.workspace.file import WorkspaceSpec
from pinmech.design.workspace.maps import boundary_edges, sign_change_edges
from pinmech.design.workspace.measure import measure
from pinmech.design.workspace.solve import WorkspaceMechanism
from pinmech.exceptions import SceneError


@dataclass(frozen=True)
class ActuatorResult(GridMaps):
    """An actuator-space workspace study's maps (SI; the motors' axes first, then the
    assembly slot "+", "-").

    Fields (SI):
        spec: the study file; motors: the axes' motor names (the file's order); angular
            (each axis): a turn [rad], else a slide [m]; length: L [m];
        coords: each axis's motor values [rad or m]; reached: (grid..., 2) bool;
        end: (grid..., 2, task axes) end point [m]; modes: (grid..., 2) working modes;
        values: det1, det2, sigma1, sigma2, kappa (grid..., 2);
        measures: per assembly (and "any": either) the region's area [rad^2] or volume
            [rad^3] in actuator space; type1, type2: per assembly, locus midpoints (k, axes)
            [rad or m] in actuator space.
    """

    angular: tuple[bool, ...]
    end: np.ndarray
    modes: np.ndarray


def run_actuator_workspace(spec: WorkspaceSpec, wm: WorkspaceMechanism, *, workers: int = 0,
                           scheduler: str | None = None, progress=None) -> ActuatorResult:
    """Solve the motors' grid (here, or on Dask) and read its maps.

    Raises:
        SceneError: no cell of the grid assembles in either mode (key "workspace.actuators").
    """
    with batch_runner(workers=workers, scheduler=scheduler) as run:
        results: list[ActuatorBatch] = grid_batches(spec, run, progress)
    shape = tuple(a.count for a in spec.axes)
    reached = np.concatenate([b.reached for b in results]).reshape(*shape, 2)
    if not reached.any():
        span = ", ".join(f"{a.name} {np.degrees(a.start):g} to {np.degrees(a.stop):g} deg" for a in spec.axes)
        raise SceneError(f"no cell of the motors' grid ({span}) assembles in either assembly mode",
                         path=str(spec.path), key="workspace.actuators")
    end = np.concatenate([b.end for b in results]).reshape(*shape, 2, len(wm.rows))
    modes = np.concatenate([b.modes for b in results]).reshape(*shape, 2)
    values = {f: np.concatenate([b.values[f] for b in results]).reshape(*shape, 2) for f in FIELDS}
    coords = [np.asarray(a.values) for a in spec.axes]
    steps = tuple(float(c[1] - c[0]) for c in coords)
    measures = {a: measure(reached[..., k], steps) for k, a in enumerate(ASSEMBLIES)}
    measures["any"] = measure(reached.any(axis=-1), steps)
    type1 = {a: sign_change_edges(values["det1"][..., k], coords) for k, a in enumerate(ASSEMBLIES)}
    type2 = {a: boundary_edges(reached[..., k], coords) for k, a in enumerate(ASSEMBLIES)}
    angular = tuple(not wm.prismatic_motor[wm.motors.index(a.name)] for a in spec.axes)
    return ActuatorResult(spec=spec, motors=tuple(a.name for a in spec.axes), length=wm.length, coords=coords,
                          reached=reached, values=values, measures=measures, type1=type1, type2=type2,
                          angular=angular, end=end, modes=modes)
