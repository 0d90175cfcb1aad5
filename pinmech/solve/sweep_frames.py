"""Named points and links along a sweep: positions, rotations, velocities and accelerations
at every pose of a chunk, as arrays, in one call.

The numbers are those of `evaluate_motion` (Pinocchio's forward kinematics, frame
velocities and classical accelerations in world axes), from the same compiled call
(csrc/kinematics.cpp), here over every pose of a chunk at once.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.solve.core import _core
from pinmech.exceptions import ModelError
from pinmech.model.mechanism import Mechanism

@dataclass(frozen=True)
class FramePaths:
    """Frames at N poses, world axes.

    Attributes:
        names: the points and links asked, in order (axis 1 of every array).
        position: (N, F, 3) [m]; rotation: (N, F, 3, 3).
        velocity: (N, F, 3) [m/s]; angular_velocity: (N, F, 3) [rad/s].
        acceleration: (N, F, 3) classical [m/s^2]; angular_acceleration: (N, F, 3) [rad/s^2].
    """

    names: tuple[str, ...]
    position: np.ndarray
    rotation: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    acceleration: np.ndarray
    angular_acceleration: np.ndarray

    def index(self, name: str) -> int:
        return self.names.index(name)


def frame_paths(mechanism: Mechanism, names: Sequence[str], q: np.ndarray, v: np.ndarray,
                a: np.ndarray) -> FramePaths:
    """Points (URDF points, or any frame) and links (their frames) at every row of q, v, a.

    Raises:
        FrameNotFound: a name that is neither a link nor a frame of the model.
        ModelError: q, v, a not (N, nq), (N, nv), (N, nv).
    """
    if isinstance(names, (str, bytes)):
        raise ModelError(f"names must be a list of names, got the string {names!r}", path=mechanism.source)
    names = tuple(names)
    model = mechanism.model
    fids = [mechanism.links[n] if n in mechanism.links else mechanism.frame_id(n) for n in names]
    q, v, a = (np.ascontiguousarray(x, dtype=float) for x in (q, v, a))
    n = len(q)
    if q.shape != (n, model.nq) or v.shape != (n, model.nv) or a.shape != (n, model.nv):
        raise ModelError(f"q, v, a must be ({n}, {model.nq}), ({n}, {model.nv}), ({n}, {model.nv}) arrays, got "
                         f"{q.shape}, {v.shape}, {a.shape}", path=mechanism.source)
    data, lock = _data_for(mechanism)
    with lock:  # one Data per mechanism: threads sharing it take turns
        rows = np.empty((n, len(fids), _core.KINEMATICS_COLUMNS))
        _core.frames_along(model, data, q, v, a, np.array(fids, dtype=np.int32), rows)
    return FramePaths(names, rows[..., 0:3], rows[..., 3:12].reshape(n, len(fids), 3, 3), rows[..., 12:15],
                      rows[..., 15:18], rows[..., 18:21], rows[..., 21:24])


def _data_for(mechanism: Mechanism) -> tuple[pin.Data, threading.Lock]:
    """A pin.Data of the mechanism's model kept for frame_paths, and its lock."""
    cached = mechanism.__dict__.get("_paths_data")
    if cached is None or len(cached[0].oMf) != mechanism.model.nframes:  # new, or frames added since
        cached = mechanism.__dict__["_paths_data"] = (mechanism.model.createData(), threading.Lock())
    return cached
