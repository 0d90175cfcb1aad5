"""Path mode for arms: a task's rates integrated over time, with the drift measured.

Each step solves the task's rate problem at the current pose and moves the joints by
q <- q (+) (v dt + a dt^2 / 2) on the configuration manifold (a second-order Taylor step,
exact for the task's own velocities and accelerations to O(dt^3)). The frame positions the
task asks for are integrated alongside in closed form (x0 + v t + a t^2 / 2, world axes),
and the drift is the distance between asked and achieved. An optional feedback term
(`gain`, 1/s) adds gain * (asked - achieved) to the asked linear velocity, which keeps the
drift bounded instead of growing (closed-loop inverse kinematics).
Only world-frame linear rows are tracked for drift; angular rows are integrated as asked.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.exceptions import TaskError
from pinmech.mechanism import Mechanism
from pinmech.solve_rates import RateSolver, Task


@dataclass(frozen=True)
class PathPoint:
    """One instant of a path: time [s], joint state, and the drift of each task frame [m]."""

    time: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    drift: float


def follow_path(mechanism: Mechanism, tasks: list[Task], q0: np.ndarray, *, duration: float, step: float,
                gain: float = 0.0, max_drift: float = 1e-3, **solver_options) -> Iterator[PathPoint]:
    """Integrate a task over `duration` [s] with time step `step` [s] (lazy).

    Args:
        max_drift: stop when the drift exceeds this fraction of the mechanism's size.

    Raises:
        SingularPoseError: the path runs into a singular pose.
        TaskError: the achieved path leaves the asked one by more than `max_drift`
            (the task runs out of the workspace, or the step is far too coarse).
    """
    model = mechanism.model
    data = model.createData()
    frames = [mechanism.frame_id(t.frame) for t in tasks]
    linear = [[i for i, c in enumerate(t.components) if c in "xyz" and t.reference == "world"] for t in tasks]
    pin.framesForwardKinematics(model, data, q0)
    start = [data.oMf[f].translation.copy() for f in frames]
    q, t = np.array(q0, dtype=float), 0.0
    steps = round(duration / step)
    solver = RateSolver(mechanism, tasks, **solver_options)  # one solver; new task values each step
    for k in range(steps + 1):
        t = k * step
        pin.framesForwardKinematics(model, data, q)
        drift, velocities = 0.0, []
        for task, fid, rows, x0 in zip(tasks, frames, linear, start):
            comps = [("xyz".index(task.components[i]), i) for i in rows]
            target = {c: x0[c] + task.velocity[i] * t + 0.5 * task.acceleration[i] * t * t for c, i in comps}
            error = {c: target[c] - data.oMf[fid].translation[c] for c, _ in comps}
            drift = max(drift, float(np.sqrt(sum(e * e for e in error.values()))))
            velocity = task.velocity + task.acceleration * t
            if gain:
                velocity = velocity.copy()
                for c, i in comps:
                    velocity[i] += gain * error[c]
            velocities.append(velocity)
        if drift > max_drift * mechanism.length_scale:
            raise TaskError(
                f"{mechanism.source}: at t = {t:.6g} s the path is {drift:.3g} m from the one asked "
                f"(more than {max_drift:g} of the mechanism's size): the task leaves the workspace or "
                "passes a singularity; shorten --duration or the --step"
            )
        solution = solver.solve(q, velocity=np.concatenate(velocities),
                                acceleration=np.concatenate([task.acceleration for task in tasks]))
        yield PathPoint(t, q.copy(), solution.v, solution.a, drift)
        q = pin.integrate(model, q, solution.v * step + 0.5 * solution.a * step * step)
