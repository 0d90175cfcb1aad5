"""End-effector rate problems: which joint rates and accelerations give a wanted motion.

A task prescribes, for some frames, components of the velocity and the CLASSICAL
acceleration (the second time derivative of the frame origin's position; angular rows
are the angular velocity and acceleration, the same in both conventions):

    J q_dot = x_dot,        J q_ddot = x_ddot - Jdot q_dot

where J stacks the selected rows of each frame's Jacobian (`pin.getFrameJacobian`,
LOCAL_WORLD_ALIGNED: origin velocity in world axes), and Jdot q_dot is the frame's
classical acceleration at zero joint acceleration (`pin.getFrameClassicalAcceleration`).
"local" rows are the same vectors expressed in the frame's own axes at this instant.
On a closed-loop mechanism the loop-closure rows (J_c q_dot = 0, J_c q_ddot = -drift)
are stacked above the task rows and always hold exactly.

Methods: "exact" (square, full rank), minimum-norm for redundant tasks (automatic, with
the null-space dimension reported), "least_squares" (opt-in, for over-determined tasks,
reports the residual), "damped" (opt-in damped least squares, reports asked vs achieved).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.exceptions import SingularPoseError, TaskError
from pinmech.mechanism import Mechanism
from pinmech.solve_loops import DEFAULT_MAX_CONDITION

COMPONENTS = ("x", "y", "z", "wx", "wy", "wz")
METHODS = ("exact", "least_squares", "damped")
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class Task:
    """Prescribed motion of one frame.

    Attributes:
        frame: a point, link or frame name of the model.
        components: subset of "x", "y", "z" (linear) and "wx", "wy", "wz" (angular).
        velocity: one value per component [m/s or rad/s].
        acceleration: one value per component [m/s^2 or rad/s^2], classical.
        reference: "world" (world axes) or "local" (the frame's own axes, now).
    """

    frame: str
    components: tuple[str, ...]
    velocity: np.ndarray
    acceleration: np.ndarray
    reference: str = "world"

    def __post_init__(self) -> None:
        bad = [c for c in self.components if c not in COMPONENTS]
        if bad or len(set(self.components)) != len(self.components) or not self.components:
            raise TaskError(f"task on '{self.frame}': components {list(self.components)} must be distinct "
                            f"names among {', '.join(COMPONENTS)}")
        for name, values in (("velocity", self.velocity), ("acceleration", self.acceleration)):
            if np.shape(values) != (len(self.components),) or not np.all(np.isfinite(values)):
                raise TaskError(f"task on '{self.frame}': {name} needs {len(self.components)} finite values, "
                                f"got {values!r}")
        if self.reference not in ("world", "local"):
            raise TaskError(f"task on '{self.frame}': reference must be 'world' or 'local', got {self.reference!r}")

    @property
    def rows(self) -> np.ndarray:
        return np.array([COMPONENTS.index(c) for c in self.components])


@dataclass(frozen=True)
class RateSolution:
    """Joint rates and accelerations that realise a task, with their accuracy.

    Attributes:
        v, a: joint velocities and accelerations (all of the model's freedoms).
        method: "exact", "minimum_norm", "least_squares" or "damped".
        condition: condition number of the stacked Jacobian (closure + task rows).
        sigma_min: its smallest singular value.
        nullspace_dim: freedoms the task leaves free (0 for a square task).
        requested_velocity, achieved_velocity, requested_acceleration,
        achieved_acceleration: the task rows, asked and obtained (J v, J a + Jdot v).
    """

    v: np.ndarray
    a: np.ndarray
    method: str
    condition: float
    sigma_min: float
    nullspace_dim: int
    requested_velocity: np.ndarray
    achieved_velocity: np.ndarray
    requested_acceleration: np.ndarray
    achieved_acceleration: np.ndarray
    closure_velocity_residual: float = 0.0
    closure_acceleration_residual: float = 0.0

    @property
    def velocity_error(self) -> float:
        """Largest |asked - achieved| over the velocity rows."""
        return float(np.max(np.abs(self.requested_velocity - self.achieved_velocity), initial=0.0))

    @property
    def acceleration_error(self) -> float:
        """Largest |asked - achieved| over the acceleration rows."""
        return float(np.max(np.abs(self.requested_acceleration - self.achieved_acceleration), initial=0.0))

    def is_exact(self, tol: float = 1e-9) -> bool:
        """True when the achieved motion equals the asked one to `tol` (relative)."""
        scale_v = max(1.0, float(np.max(np.abs(self.requested_velocity), initial=0.0)))
        scale_a = max(1.0, float(np.max(np.abs(self.requested_acceleration), initial=0.0)))
        return self.velocity_error <= tol * scale_v and self.acceleration_error <= tol * scale_a


class RateSolver:
    """Solves task-space rate problems pose after pose, keeping one `pin.Data`.

    Args:
        mechanism: the model (its loop closures, if any, are always enforced).
        tasks: the prescribed frame motions.
        method: "exact" (default: square or redundant tasks; redundant ones get the
            minimum-norm solution), "least_squares" (also accepts over-determined
            tasks), or "damped" (damped least squares with `damping`).
        damping: lambda of the damped least squares, in the Jacobian's units.
        max_condition: above this the pose is singular (SingularPoseError) unless damped.
    """

    def __init__(self, mechanism: Mechanism, tasks: Sequence[Task], *, method: str = "exact",
                 damping: float = 1e-3, max_condition: float = DEFAULT_MAX_CONDITION) -> None:
        if method not in METHODS:
            raise TaskError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        if not tasks:
            raise TaskError("no task given: add a [[task]] with frame, components, velocity, acceleration")
        self.mechanism = mechanism
        self.model = mechanism.model
        self.data = self.model.createData()
        self.tasks = tuple(tasks)
        self.frames = [mechanism.frame_id(t.frame) for t in self.tasks]
        self.method = method
        self.damping = float(damping)
        self.max_condition = max_condition
        self.x_dot = np.concatenate([t.velocity for t in self.tasks])
        self.x_ddot = np.concatenate([t.acceleration for t in self.tasks])

    # ------------------------------------------------------------------ rows
    def _task_rows(self) -> tuple[np.ndarray, np.ndarray]:
        """Stacked task Jacobian and its drift Jdot v (needs kinematics at (q, v, 0))."""
        J_rows, drift_rows = [], []
        for task, fid in zip(self.tasks, self.frames):
            J6 = pin.getFrameJacobian(self.model, self.data, fid, _LWA)
            acc = pin.getFrameClassicalAcceleration(self.model, self.data, fid, _LWA)
            d6 = np.r_[acc.linear, acc.angular]
            if task.reference == "local":
                R_T = self.data.oMf[fid].rotation.T
                J6 = np.vstack([R_T @ J6[:3], R_T @ J6[3:]])
                d6 = np.r_[R_T @ d6[:3], R_T @ d6[3:]]
            J_rows.append(J6[task.rows])
            drift_rows.append(d6[task.rows])
        return np.vstack(J_rows), np.concatenate(drift_rows)

    def _closure_rows(self) -> tuple[np.ndarray, np.ndarray]:
        closures = self.mechanism.closures
        if not closures:
            return np.zeros((0, self.model.nv)), np.zeros(0)
        J = np.vstack([c.jacobian(self.model, self.data) for c in closures])
        drift = np.concatenate([c.drift(self.model, self.data) for c in closures])
        return J, drift

    def _stack(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
        pin.computeJointJacobians(self.model, self.data, q)
        pin.forwardKinematics(self.model, self.data, q, v, np.zeros(self.model.nv))
        pin.updateFramePlacements(self.model, self.data)
        J_c, d_c = self._closure_rows()
        J_t, d_t = self._task_rows()
        return np.vstack([J_c, J_t]), np.concatenate([d_c, d_t]), J_c.shape[0]

    # ------------------------------------------------------------------ solve
    def solve(self, q: np.ndarray) -> RateSolution:
        """Joint rates and accelerations at configuration q (loops already closed).

        Raises:
            TaskError: an over-determined or inconsistent task without method "least_squares".
            SingularPoseError: a singular stacked Jacobian, unless method is "damped".
        """
        zero = np.zeros(self.model.nv)
        J, _, n_c = self._stack(q, zero)
        m, n = J.shape
        rhs_v = np.r_[np.zeros(n_c), self.x_dot]
        sigma = np.linalg.svd(self._dimensionless(J, n_c), compute_uv=False)
        rank_sigma = sigma[: min(m, n)]
        condition = float(rank_sigma[0] / rank_sigma[-1]) if rank_sigma[-1] > 0 else float("inf")
        method = self._method(m, n, condition, q, rank_sigma)
        v = self._apply(J, rhs_v, method)
        J, drift, _ = self._stack(q, v)
        a = self._apply(J, np.r_[np.zeros(n_c), self.x_ddot] - drift, method)
        achieved_v = J @ v
        achieved_a = J @ a + drift
        return RateSolution(
            v=v, a=a, method=method, condition=condition, sigma_min=float(rank_sigma[-1]),
            nullspace_dim=max(n - m, 0),
            requested_velocity=self.x_dot.copy(), achieved_velocity=achieved_v[n_c:],
            requested_acceleration=self.x_ddot.copy(), achieved_acceleration=achieved_a[n_c:],
            closure_velocity_residual=float(np.max(np.abs(achieved_v[:n_c]), initial=0.0)),
            closure_acceleration_residual=float(np.max(np.abs(achieved_a[:n_c]), initial=0.0)),
        )

    def _dimensionless(self, J: np.ndarray, n_closure: int) -> np.ndarray:
        """J with linear task rows divided by the mechanism's size and prismatic columns
        multiplied by it, so its condition number does not depend on units or size."""
        rows = [1.0] * n_closure
        for task in self.tasks:
            rows += [1.0 / self.mechanism.length_scale if c in "xyz" else 1.0 for c in task.components]
        return np.asarray(rows)[:, None] * J * self.mechanism.velocity_scale()

    def _method(self, m: int, n: int, condition: float, q: np.ndarray, sigma: np.ndarray) -> str:
        if self.method == "damped":
            return "damped"
        if m > n and self.method != "least_squares":
            raise TaskError(
                f"{self.mechanism.source}: the task has {m} equations (closures included) for {n} joint "
                "freedoms: over-determined; drop components or ask for method = \"least_squares\""
            )
        if condition > self.max_condition:
            pose = ", ".join(f"{name} = {self.mechanism.coordinate(q, name):.6g}"
                             for name, j in self.mechanism.joints.items() if j.nv == 1)
            raise SingularPoseError(
                f"{self.mechanism.source}: the task Jacobian is singular at {pose} (condition number "
                f"{condition:.3g} > {self.max_condition:.3g}, smallest singular value {sigma[-1]:.3g}); "
                "ask for method = \"damped\" to get the closest achievable motion",
                condition=condition, sigma_min=float(sigma[-1]), partial=q,
            )
        if m > n:
            return "least_squares"
        return "exact" if m == n else "minimum_norm"

    def _apply(self, J: np.ndarray, rhs: np.ndarray, method: str) -> np.ndarray:
        if method == "exact":
            return np.linalg.solve(J, rhs)
        if method == "damped":
            lam2 = self.damping**2
            return J.T @ np.linalg.solve(J @ J.T + lam2 * np.eye(J.shape[0]), rhs)
        x, *_ = np.linalg.lstsq(J, rhs, rcond=None)  # minimum-norm or least-squares
        return x
