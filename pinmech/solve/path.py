"""Path mode for arms: a task's rates integrated over time, with the drift measured.

At each instant the task's rate problem (solve_rates.py) gives the joint velocity v and
acceleration a that realise the asked frame motion; the joints then move by one step of
the chosen scheme, on the configuration manifold (`pin.integrate`):

    "euler"   q <- q (+) v dt                        first order: drift ~ dt
    "taylor"  q <- q (+) (v dt + a dt^2 / 2)         second order (default): drift ~ dt^2,
                                                     one rate solve a step
    "rk4"     classical Runge-Kutta on the velocity   fourth order: drift ~ dt^4, four rate
              field v(q, t)                           solves a step

The positions the task asks for are integrated alongside in closed form (x0 + v t +
a t^2 / 2 for world-axis linear rows; the angle about the plane normal for a planar
arm's angular row), and the drift is the distance between asked and achieved [m], or
the angle [rad]. An optional feedback `gain` K [1/s] adds K x (asked - achieved) to the
asked velocity (and -K^2 x error to its acceleration, its time derivative when the
feedback works), so the drift stays bounded instead of growing: closed-loop inverse
kinematics. Rows in a frame's own axes ("local") and spatial angular rows are followed
as asked but not measured for drift.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.directions import cross as _cross
from pinmech.counts import checked_count
from pinmech.exceptions import TaskError
from pinmech.model.mechanism import Mechanism
from pinmech.solve.results import RateSolution
from pinmech.solve.rates import RateSolver, Task

SCHEMES = ("euler", "taylor", "rk4")


@dataclass(frozen=True)
class PathPoint:
    """One instant of a path.

    Attributes:
        time: [s] since the start.
        q, v, a: joint configuration, velocities and accelerations.
        drift: largest distance between the asked and the achieved position of a task
            frame [m] (0 when no linear world row is tracked).
        angular_drift: largest angle between asked and achieved orientation [rad], for
            angular rows about a planar arm's plane normal.
        condition: condition number of the task Jacobian at q (the rates' accuracy).
    """

    time: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    drift: float
    angular_drift: float = 0.0
    condition: float = 1.0


class _Tracker:
    """The asked positions (and plane angles) of the tracked task rows, and the errors."""

    def __init__(self, mechanism: Mechanism, solver: RateSolver, q0: np.ndarray) -> None:
        self.mechanism, self.model = mechanism, mechanism.model
        self.data = self.model.createData()
        normal = mechanism.plane_normal
        self.rows: list[tuple[int, int, int | None]] = []  # (task row, frame, axis; None: plane angle)
        k = 0
        for task, fid in zip(solver.tasks, solver.frames):
            for comp in task.components:
                if task.reference == "world" and comp in ("x", "y", "z"):
                    self.rows.append((k, fid, "xyz".index(comp)))
                elif task.reference == "world" and normal is not None and abs(normal["xyz".index(comp[1])]) > 0.999:
                    self.rows.append((k, fid, None))
                k += 1
        self.task_rows = [k for k, _, _ in self.rows]
        if normal is not None:  # in-plane reference axis for plane angles
            ref = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            ref -= normal * (normal @ ref)
            self.ref, self.normal = ref / np.linalg.norm(ref), normal
        pin.framesForwardKinematics(self.model, self.data, q0)
        self.start = np.array([self._achieved(fid, axis) for _, fid, axis in self.rows])
        self.v0, self.a0 = solver.x_dot.copy(), solver.x_ddot.copy()

    def _achieved(self, fid: int, axis: int | None) -> float:
        M = self.data.oMf[fid]
        if axis is not None:
            return float(M.translation[axis])
        x = M.rotation @ self.ref  # the angle of the frame about the plane normal
        return math.atan2(float(self.normal @ _cross(self.ref, x)), float(self.ref @ x))

    def errors(self, q: np.ndarray, t: float) -> tuple[np.ndarray, float, float]:
        """asked - achieved per tracked row; the largest distance [m] and angle [rad]."""
        pin.framesForwardKinematics(self.model, self.data, q)
        error = np.zeros(len(self.rows))
        squares: dict[int, float] = {}
        angle = 0.0
        for i, (k, fid, axis) in enumerate(self.rows):
            e = self.start[i] + self.v0[k] * t + 0.5 * self.a0[k] * t * t - self._achieved(fid, axis)
            if axis is None:
                e = math.remainder(e, 2 * math.pi)  # the angle may turn past +-pi
                angle = max(angle, abs(e))
            else:
                squares[fid] = squares.get(fid, 0.0) + e * e
            error[i] = e
        return error, math.sqrt(max(squares.values(), default=0.0)), angle


def follow_path(mechanism: Mechanism, tasks: list[Task], q0: np.ndarray, *, duration: float, step: float,
                gain: float = 0.0, scheme: str = "taylor", max_drift: float = 1e-3,
                **solver_options) -> Iterator[PathPoint]:
    """Integrate a task over `duration` [s] with time step `step` [s] (lazy).

    Args:
        gain: feedback on the drift [1/s] (0: open loop).
        scheme: "euler", "taylor" (default) or "rk4" (module docstring).
        max_drift: stop when the drift exceeds this fraction of the mechanism's size (or
            this angle [rad]).
        solver_options: passed to `RateSolver` (method, damping, max_condition).

    Raises:
        TaskError: an unknown scheme, a mechanism with loop cuts (sweep its drivers
            instead), or a path that leaves the asked one by more than `max_drift` (the
            task leaves the workspace, or the step is far too coarse).
        SingularPoseError: the path runs into a singular pose.
    """
    if scheme not in SCHEMES:
        raise TaskError(f"scheme must be one of {', '.join(SCHEMES)}, got {scheme!r}")
    check_timing(duration, step, gain)
    if mechanism.closures:
        raise TaskError(f"{mechanism.source}: the path mode follows arms (open chains); a mechanism "
                        "with loop cuts is swept through its drivers (pinmech sweep)")
    solver = RateSolver(mechanism, tasks, **solver_options)
    tracker = _Tracker(mechanism, solver, q0)
    model = mechanism.model
    q = np.array(q0, dtype=float)
    count = step_count(duration, step)
    for k in range(count + 1):
        t = _time(k, count, duration, step)
        rates, drift, angular = _rates(solver, tracker, q, t, gain)
        if drift > max_drift * mechanism.length_scale or angular > max_drift:
            raise TaskError(
                f"{mechanism.source}: at t = {t:.6g} s the path is {drift:.3g} m (and {angular:.3g} rad) from the "
                f"one asked (more than {max_drift:g} of the mechanism's size): the task leaves the workspace or "
                "passes a singularity; shorten --duration or the --step"
            )
        yield PathPoint(t, q.copy(), rates.v, rates.a, drift, angular, rates.condition)
        if k == count:
            break
        step = _time(k + 1, count, duration, step) - t  # the last step ends at `duration` exactly
        if scheme == "euler":
            q = pin.integrate(model, q, rates.v * step)
        elif scheme == "taylor":
            q = pin.integrate(model, q, rates.v * step + 0.5 * rates.a * step * step)
        else:
            q = _rk4(solver, tracker, q, t, step, gain, rates.v)


def step_count(duration: float, step: float) -> int:
    """Steps of a path over `duration` [s]: whole steps of `step` [s], the last one shorter
    when `step` does not divide `duration` (a path asked for 0.0815 s ends at 0.0815 s)."""
    return max(1, math.ceil(duration / step * (1 - 1e-12)))


def _time(k: int, count: int, duration: float, step: float) -> float:
    return duration if k == count else k * step


def check_timing(duration: float, step: float, gain: float, *, names: tuple[str, str, str] = (
        "duration", "step", "gain")) -> None:
    """A path's duration and step [s] are finite and positive, step <= duration; the gain
    [1/s] is finite, not negative, and at most 1/step (a larger one overshoots in one step).

    Raises:
        TaskError: naming the argument (`names`: as the caller spells them, e.g. "--gain").
    """
    for value, name in ((duration, names[0]), (step, names[1])):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < math.inf:
            raise TaskError(f"{name} must be a positive, finite time [s], got {value!r}")
    if step > duration:
        raise TaskError(f"{names[1]} ({step:g} s) must not be longer than {names[0]} ({duration:g} s)")
    checked_count(duration / step, names[1], f"{duration:g} s of path at a step of {step!r} s")
    if isinstance(gain, bool) or not isinstance(gain, (int, float)) or not 0 <= gain <= 1 / step:
        raise TaskError(f"{names[2]} must be a number from 0 to 1/{names[1]} = {1 / step:.6g} [1/s] "
                        f"(a larger feedback overshoots within one step), got {gain!r}")


def _rates(solver: RateSolver, tracker: _Tracker, q: np.ndarray, t: float,
           gain: float) -> tuple[RateSolution, float, float]:
    """The rate solution at (q, t), with the feedback term, and the drifts there."""
    error, drift, angular = tracker.errors(q, t)
    velocity, acceleration = tracker.v0 + tracker.a0 * t, tracker.a0.copy()
    if gain:
        velocity[tracker.task_rows] += gain * error
        acceleration[tracker.task_rows] -= gain * gain * error
    return solver.solve(q, velocity=velocity, acceleration=acceleration), drift, angular


def _rk4(solver: RateSolver, tracker: _Tracker, q: np.ndarray, t: float, dt: float, gain: float,
         k1: np.ndarray) -> np.ndarray:
    """One classical Runge-Kutta step of q_dot = v(q, t), in the tangent space at q."""
    model = solver.model
    k2 = _rates(solver, tracker, pin.integrate(model, q, 0.5 * dt * k1), t + 0.5 * dt, gain)[0].v
    k3 = _rates(solver, tracker, pin.integrate(model, q, 0.5 * dt * k2), t + 0.5 * dt, gain)[0].v
    k4 = _rates(solver, tracker, pin.integrate(model, q, dt * k3), t + dt, gain)[0].v
    return pin.integrate(model, q, dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4))
