"""One batch of an actuator-space workspace study (a Dask task): the forward kinematics
(forward.py) at each of its cells of the motors' grid, on the mechanism and seed
table this process built once."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmech.design.study.tolerance import Batch
from pinmech.design.workspace.file import WorkspaceSpec
from pinmech.design.workspace.forward import ForwardKinematics
from pinmech.design.workspace.solve import WorkspaceMechanism

ASSEMBLIES = ("+", "-")  # the sign of det Phi_p, slot 0 and 1
FIELDS = ("det1", "det2", "sigma1", "sigma2", "kappa")
_BUILT: dict[WorkspaceSpec, ForwardKinematics] = {}


@dataclass(frozen=True)
class ActuatorBatch:
    """Cells start .. start + count - 1 (C order over the motors' axes), in each assembly
    slot: reached (count, 2), end (count, 2, task axes) [m], modes (count, 2) working modes
    ("" where not reached), and each of FIELDS (count, 2) (NaN where not reached)."""

    start: int
    reached: np.ndarray
    end: np.ndarray
    modes: np.ndarray
    values: dict[str, np.ndarray]


def forward(spec: WorkspaceSpec, wm: WorkspaceMechanism) -> ForwardKinematics:
    """This process's forward kinematics of the study (its seed table), built on first use."""
    if spec not in _BUILT:
        _BUILT[spec] = ForwardKinematics(wm)
    return _BUILT[spec]


def motor_targets(spec: WorkspaceSpec, wm: WorkspaceMechanism, start: int, count: int) -> np.ndarray:
    """(count, motors) motor values [rad or m], in the mechanism's motor order, of cells
    start .. start + count - 1."""
    shape = tuple(a.count for a in spec.axes)
    index = np.unravel_index(np.arange(start, start + count), shape)
    out = np.empty((count, len(wm.motors)))
    for axis, i in zip(spec.axes, index):
        out[:, wm.motors.index(axis.name)] = np.asarray(axis.values)[i]
    return out


def run_actuator_batch(spec: WorkspaceSpec, wm: WorkspaceMechanism, batch: Batch) -> ActuatorBatch:
    """Every assembly at the batch's cells."""
    fk = forward(spec, wm)
    n, d = batch.count, len(wm.rows)
    reached, end = np.zeros((n, 2), bool), np.full((n, 2, d), np.nan)
    modes = np.full((n, 2), "", dtype=object)
    values = {f: np.full((n, 2), np.nan) for f in FIELDS}
    for i, target in enumerate(motor_targets(spec, wm, batch.start, n)):
        for s in fk.solve(target):
            k = ASSEMBLIES.index("+" if s.sign > 0 else "-")
            reached[i, k], end[i, k], modes[i, k] = True, s.x, s.modes
            for f in FIELDS:
                values[f][i, k] = getattr(s.point, f)
    return ActuatorBatch(batch.start, reached, end, modes, values)
