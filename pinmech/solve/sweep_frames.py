"""Named points and links along a sweep: positions, rotations, velocities and accelerations
at every pose of a chunk, as arrays, in one call.

The numbers are those of `evaluate_motion` (Pinocchio's forward kinematics, frame
velocities and classical accelerations in world axes); the compiled core computes them
for a whole chunk where it rebuilds the model (core.py), Pinocchio pose by pose elsewhere.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.solve import core
from pinmech.exceptions import ModelError
from pinmech.model.mechanism import Mechanism

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


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
    compiled = _core_for(mechanism, fids)
    if compiled is not None:
        kinematics, lock = compiled
        with lock:  # one core per mechanism and frames: threads sharing it take turns
            out = kinematics.frame_motion(q, v, a, list(range(len(fids))))
        shapes = ((n, len(fids), 3), (n, len(fids), 3, 3)) + ((n, len(fids), 3),) * 4
        return FramePaths(names, *(x.reshape(s) for x, s in zip(out, shapes)))
    return _pose_by_pose(model, names, fids, q, v, a)


def _pose_by_pose(model: pin.Model, names: tuple[str, ...], fids: list[int], q: np.ndarray, v: np.ndarray,
                  a: np.ndarray) -> FramePaths:
    n, f = len(q), len(fids)
    arrays = [np.empty((n, f, 3)), np.empty((n, f, 3, 3))] + [np.empty((n, f, 3)) for _ in range(4)]
    data = model.createData()
    for i in range(n):
        pin.forwardKinematics(model, data, q[i], v[i], a[i])
        for k, fid in enumerate(fids):
            M = pin.updateFramePlacement(model, data, fid)
            vel = pin.getFrameVelocity(model, data, fid, _LWA)
            acc = pin.getFrameClassicalAcceleration(model, data, fid, _LWA)
            for array, value in zip(arrays, (M.translation, M.rotation, vel.linear, vel.angular, acc.linear,
                                             acc.angular)):
                array[i, k] = value
    return FramePaths(names, *arrays)


def _core_for(mechanism: Mechanism, fids: list[int]):
    """A core on the mechanism's model with these frames and its lock (built once per set of
    frames and per model tree: placements changed in the model are read at every call)."""
    model = mechanism.model
    cache = mechanism.__dict__.setdefault("_frame_cores", {})
    cached = cache.get(tuple(fids))
    if cached is None or not cached[0].matches(model):
        try:
            built = core.CompiledModel(model, fids).kinematics(model)
        except KeyError:
            built = None
        cached = (core.ModelShape(model, fids), None if built is None else (built, threading.Lock()))
        cache[tuple(fids)] = cached
    return cached[1]
