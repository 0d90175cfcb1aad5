"""End-effector rate problems: which joint rates and accelerations give a wanted motion.

A task prescribes, for some frames, components of the velocity and of the CLASSICAL
acceleration (the second time derivative of the frame origin's position, not
Pinocchio's spatial acceleration; angular rows are the angular velocity and
acceleration, the same in both conventions):

    J q_dot = x_dot,        J q_ddot = x_ddot - Jdot q_dot

J stacks the selected rows of each frame's Jacobian (`pin.getFrameJacobian`,
LOCAL_WORLD_ALIGNED: origin velocity and angular velocity in world axes). Jdot q_dot is
the frame's classical acceleration at zero joint acceleration
(`pin.getFrameClassicalAcceleration` after `forwardKinematics(q, q_dot, 0)`), which is
d/dt(J) q_dot of the classical rows without forming Jdot. "local" rows are the same
vectors in the frame's own axes at this instant. On a closed-loop mechanism the
loop-closure rows (J_c q_dot = 0, J_c q_ddot = -drift) are stacked above the task rows
and hold exactly: the loop is closed first (LoopSolver), then the rates are solved.

Methods: "exact" (square, full rank); minimum-norm for redundant tasks (automatic, with
the null-space dimension reported); "least_squares" (opt-in: over-determined or
inconsistent rows, reports asked vs achieved); "damped" (opt-in damped least squares,
(J^T J + lambda^2 I)^-1 J^T, reports asked vs achieved). Without an opt-in, a task whose
rows cannot all hold is a TaskError and a singular pose a SingularPoseError.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.arguments import not_real
from pinmech.exceptions import ModelError, SingularPoseError, TaskError
from pinmech.model.mechanism import Mechanism
from pinmech.solve.results import RateSolution
from pinmech.solve.loops import (
    DEFAULT_MAX_CONDITION,
    DEFAULT_TOL,
    checked_option,
    describe_joint_values,
    is_closed,
    open_loops_error,
    serialized,
)

COMPONENTS = ("x", "y", "z", "wx", "wy", "wz")
METHODS = ("exact", "least_squares", "damped")
#: Accepted damping lambda (dimensionless). Below 1e-5, lambda^2 drowns in the rounding of
#: J J^T (the damped answer is off by about eps / lambda^2: 4e-7 at 1e-5, 8e-5 at 1e-6, and
#: at 1e-9 the damped matrix is singular in float64); above 1e50, the bound on every
#: quantity pinmech takes (README "Scale and speed"), lambda^2 overflows by 1e155 and the
#: rates underflow to denormals before that.
DAMPING_RANGE = (1e-5, 1e50)
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




#: Singular values below this fraction of the largest, at every sampled pose, are zero.
STRUCTURAL_RANK_TOL = 1e-9
_SAMPLES = 3


@dataclass(frozen=True)
class RateBatch:
    """`RateSolution`s of N poses as arrays: v, a (N, nv); method (N,) as `RateSolution`;
    condition, sigma_min, closure residuals (velocity, acceleration, position) (N,);
    achieved task rows (N, rows)."""

    v: np.ndarray
    a: np.ndarray
    method: np.ndarray
    condition: np.ndarray
    sigma_min: np.ndarray
    achieved_velocity: np.ndarray
    achieved_acceleration: np.ndarray
    closure_velocity_residual: np.ndarray
    closure_acceleration_residual: np.ndarray
    closure_residual: np.ndarray


class RateSolver:
    """Solves task-space rate problems pose after pose, keeping one `pin.Data`.

    Args:
        mechanism: the model (its loop closures, if any, are always enforced).
        tasks: the prescribed frame motions.
        method: "exact" (default: square or redundant tasks; redundant ones get the
            minimum-norm solution), "least_squares" (also accepts over-determined or
            inconsistent tasks: the least-squares motion, asked vs achieved reported),
            or "damped" (damped least squares with `damping`, also at singular poses).
        damping: lambda of the damped least squares, dimensionless: rows and columns are
            scaled as for the condition number (lengths in mechanism sizes); in
            DAMPING_RANGE (1e-5 to 1e50).
        max_condition: above this condition number (dimensionless) the pose is singular
            (SingularPoseError) unless the method is "damped".
        tol: how closed the loops of a q must be (dimensionless, as `LoopSolver`'s tol,
            which closed it): a q whose loops are open beyond it is a LoopClosureError.

    Raises:
        TaskError: unknown method, no task, or a damping out of DAMPING_RANGE.
        OptionError: max_condition or tol out of SOLVER_RANGES.
        FrameNotFound: a task names a frame the model lacks.
    """

    def __init__(self, mechanism: Mechanism, tasks: Sequence[Task], *, method: str = "exact",
                 damping: float = 1e-3, max_condition: float = DEFAULT_MAX_CONDITION,
                 tol: float = DEFAULT_TOL) -> None:
        if method not in METHODS:
            raise TaskError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        if not isinstance(tasks, (list, tuple)) or not all(isinstance(t, Task) for t in tasks):
            raise TaskError(f"tasks must be a list of pinmech.Task, got {tasks!r:.80}")
        if not tasks:
            raise TaskError("no task given: add a [[task]] with frame, components, velocity, acceleration")
        low, high = DAMPING_RANGE
        number = damping if isinstance(damping, (int, float, np.number)) and not isinstance(damping, bool) else None
        if number is None or not low <= number <= high:  # NaN is in no range
            raise TaskError(f"damping must be a positive number in [{low:g}, {high:g}] (dimensionless: below, "
                            f"its square drowns in rounding; above, it overflows), got {damping!r}")
        self.mechanism = mechanism
        self.model = mechanism.model
        self.lock = threading.RLock()  # one Data: threads sharing the solver take turns
        self.data = self.model.createData()
        self.tasks = tuple(tasks)
        self.frames = [mechanism.frame_id(t.frame) for t in self.tasks]
        self.method = method
        self.damping = float(damping)
        self.max_condition = checked_option("max_condition", max_condition)  # NaN would turn the check off
        self.tol = checked_option("tol", tol)
        self.x_dot = np.concatenate([t.velocity for t in self.tasks])
        self.x_ddot = np.concatenate([t.acceleration for t in self.tasks])
        self.row_names = [f"{t.frame}.{c}" for t in self.tasks for c in t.components]
        self._row_scale = np.array([1.0 / mechanism.length_scale if c in "xyz" else 1.0
                                    for t in self.tasks for c in t.components])
        self._generic: tuple[int, np.ndarray, list[int]] | None = None  # rank, rows, dependent rows

    # ------------------------------------------------------------------ solve
    @serialized
    def solve(self, q: np.ndarray, velocity: np.ndarray | None = None,
              acceleration: np.ndarray | None = None) -> RateSolution:
        """Joint rates and accelerations at configuration q (loops already closed).

        Args:
            q: configuration of the model (nq finite numbers; quaternions and (cos, sin)
                pairs of unit norm).
            velocity, acceleration: the task rows' values for this call, in task order
                (default: the tasks' own) [m/s, rad/s; m/s^2, rad/s^2].

        Raises:
            ModelError: q is not a configuration of the model (shape, NaN, a quaternion
                whose norm is not 1).
            LoopClosureError: q's loops are open beyond `tol` (how far, in m and deg).
            TaskError: an over-determined task, or rows that cannot hold together at any
                pose (a zero row, a row repeated), unless method is "least_squares".
            SingularPoseError: the stacked Jacobian is singular at q, unless "damped".
        """
        q = self.mechanism.checked_q(q)
        x_dot = self._values(velocity, self.x_dot, "velocity")
        x_ddot = self._values(acceleration, self.x_ddot, "acceleration")
        J, n_c = self._jacobian(self.data, q)
        closure = self._closure_residual(q)
        m, n = J.shape
        rows, columns = self._scales(n_c)
        Jd = rows[:, None] * J * columns
        sigma = np.linalg.svd(Jd, compute_uv=False)
        rank = min(m, n)
        if rank and not sigma[rank - 1] > sigma[0] / self.max_condition:
            rank = min(rank, self._structural_rank()[0])  # only poses that look singular pay
        sigma_min = float(sigma[rank - 1]) if rank else 0.0
        condition = float(sigma[0] / sigma_min) if sigma_min > 0 else float("inf")
        method = self._method(m, n, rank, condition, sigma_min, q)
        v = columns * self._apply(Jd, rows * np.concatenate((np.zeros(n_c), x_dot)), method, rank)
        drift = self._drift(q, v, n_c)
        a = columns * self._apply(Jd, rows * (np.concatenate((np.zeros(n_c), x_ddot)) - drift), method, rank)
        achieved_v, achieved_a = J @ v, J @ a + drift
        return RateSolution(
            v=v, a=a, method=method, condition=condition, sigma_min=sigma_min,
            nullspace_dim=n - rank, rank=rank,
            requested_velocity=x_dot.copy(), achieved_velocity=achieved_v[n_c:],
            requested_acceleration=x_ddot.copy(), achieved_acceleration=achieved_a[n_c:],
            closure_velocity_residual=float(np.max(np.abs(achieved_v[:n_c]), initial=0.0)),
            closure_acceleration_residual=float(np.max(np.abs(achieved_a[:n_c]), initial=0.0)),
            closure_residual=closure,
        )

    @serialized
    def solve_many(self, q: np.ndarray) -> RateBatch:
        """`solve` at every row of q (N, nq), with the tasks' own velocities and
        accelerations, as arrays. The compiled core (core.py) takes the poses of a square
        task ("exact") conditioned under max_condition; `solve` takes the others, and
        raises as it does.

        Raises:
            ModelError: q is not an (N, nq) array of configurations (as `solve`).
            LoopClosureError, TaskError, SingularPoseError: as `solve`, at the first pose
                that has them.
        """
        q = np.ascontiguousarray(self.mechanism.checked_q(q, many=True))
        n, m = len(q), self.x_dot.size
        compiled = self._compiled() if self.method == "exact" else None
        if compiled is not None:
            core, frames, rows, local, row_scale = compiled
            v, a, numbers, achieved_v, achieved_a = core.rates(q, frames, rows, local, self.x_dot, self.x_ddot,
                                                             row_scale, self.max_condition)
            condition, sigma_min, closure_v, closure_a, status, independent, full = numbers.T
            closure = np.maximum(independent, full)  # q's own closure residual, measured by the core
            status[~is_closed(independent, full, self.tol)] = 1  # open poses go to `solve`, named there
        else:
            v, a = np.full((n, self.model.nv), np.nan), np.full((n, self.model.nv), np.nan)
            condition, sigma_min, closure_v, closure_a, closure = (np.full(n, np.nan) for _ in range(5))
            achieved_v, achieved_a, status = np.full((n, m), np.nan), np.full((n, m), np.nan), np.ones(n)
        methods = np.full(n, "exact", dtype=object)
        for i in np.flatnonzero(status != 0):  # the Python path: other methods, singular and open poses named
            r = self.solve(q[i])
            v[i], a[i], condition[i], sigma_min[i] = r.v, r.a, r.condition, r.sigma_min
            closure_v[i], closure_a[i] = r.closure_velocity_residual, r.closure_acceleration_residual
            achieved_v[i], achieved_a[i], methods[i] = r.achieved_velocity, r.achieved_acceleration, r.method
            closure[i] = r.closure_residual
        return RateBatch(v, a, methods, condition, sigma_min, achieved_v, achieved_a, closure_v, closure_a, closure)

    def _closure_residual(self, q: np.ndarray) -> float:
        """q's closure residual (dimensionless, as `LoopSolver`'s; data at q, frames placed).

        Raises:
            LoopClosureError: the loops are open beyond `tol` (`is_closed`)."""
        closures = self.mechanism.closures
        if not closures:
            return 0.0
        independent = max(float(np.max(np.abs(c.residual(self.data)), initial=0.0)) for c in closures)
        full = max(float(np.max(np.abs(c.full_residual(self.data)), initial=0.0)) for c in closures)
        if not is_closed(independent, full, self.tol):
            raise open_loops_error(self.mechanism, self.data, q, max(independent, full), self.tol,
                                   f"the task's rates at {self._pose(q)}")
        return max(independent, full)

    def _compiled(self):
        """The core with this solver's loops and task frames, and the task rows as it takes
        them (built once per model tree: it reads placements changed in the model), or None."""
        from pinmech.solve import core

        cached = self.__dict__.get("_core")
        if cached is None or not cached[0].matches(self.model):
            frames = [f for c in self.mechanism.closures for f in (c.parent_frame, c.child_frame)] + self.frames
            built = core.compile_loops(self.model, self.mechanism.closures, self.mechanism.velocity_scale(),
                                       extra_frames=self.frames)
            value = None
            if built is not None:
                compiled, rebuilt = built
                n_c = sum(c.rows for c in self.mechanism.closures)
                value = (compiled, [rebuilt.frames[f] for f in self.frames],
                         [[int(k) for k in t.rows] for t in self.tasks],
                         [int(t.reference == "local") for t in self.tasks],
                         self._scales(n_c)[0])
            cached = (core.ModelShape(self.model, frames), value)
            self.__dict__["_core"] = cached
        return cached[1]

    def _values(self, given: np.ndarray | None, default: np.ndarray, name: str) -> np.ndarray:
        if given is None:
            return default
        wrong = not_real(given)
        if wrong:
            raise ModelError(f"{name} must be real numbers (SI), got {wrong}: pinmech does not cast them",
                             path=self.mechanism.source)
        values = np.asarray(given, dtype=float)
        if values.shape != default.shape or not np.all(np.isfinite(values)):
            raise TaskError(f"{name} needs {default.size} finite values (rows {', '.join(self.row_names)}), "
                            f"got {given!r}")
        return values

    # ------------------------------------------------------------------ rows
    def _jacobian(self, data: pin.Data, q: np.ndarray) -> tuple[np.ndarray, int]:
        """Closure rows stacked over task rows at q, and the number of closure rows."""
        pin.computeJointJacobians(self.model, data, q)
        pin.updateFramePlacements(self.model, data)
        rows = [c.jacobian(self.model, data) for c in self.mechanism.closures]
        n_c = sum(r.shape[0] for r in rows)
        for task, fid in zip(self.tasks, self.frames):
            J6 = pin.getFrameJacobian(self.model, data, fid, _LWA)
            if task.reference == "local":
                R_T = data.oMf[fid].rotation.T
                J6 = np.vstack([R_T @ J6[:3], R_T @ J6[3:]])
            rows.append(J6[task.rows])
        return np.vstack(rows), n_c

    def _drift(self, q: np.ndarray, v: np.ndarray, n_c: int) -> np.ndarray:
        """Jdot v of every row: closure drift, then the task frames' classical acceleration
        at zero joint acceleration (same q as the Jacobian: data.J stays valid)."""
        pin.forwardKinematics(self.model, self.data, q, v, np.zeros(self.model.nv))
        pin.updateFramePlacements(self.model, self.data)
        parts = [c.drift(self.model, self.data) for c in self.mechanism.closures]
        for task, fid in zip(self.tasks, self.frames):
            acc = pin.getFrameClassicalAcceleration(self.model, self.data, fid, _LWA)
            linear, angular = acc.linear, acc.angular
            if task.reference == "local":
                R_T = self.data.oMf[fid].rotation.T
                linear, angular = R_T @ linear, R_T @ angular
            parts.append(np.concatenate((linear, angular))[task.rows])
        return np.concatenate(parts) if parts else np.zeros(n_c)

    def _dimensionless(self, J: np.ndarray, n_closure: int) -> np.ndarray:
        """J with linear task rows divided by the mechanism's size and prismatic columns
        multiplied by it, so its condition number does not depend on units or size."""
        rows, columns = self._scales(n_closure)
        return rows[:, None] * J * columns

    def _scales(self, n_closure: int) -> tuple[np.ndarray, np.ndarray]:
        """The row and column factors of `_dimensionless` (read from the mechanism afresh:
        a model changed in place changes its size)."""
        return np.concatenate((np.ones(n_closure), self._row_scale)), self.mechanism.velocity_scale()

    def _structural_rank(self) -> tuple[int, np.ndarray, list[int]]:
        """Rank of the stacked Jacobian at random poses (the highest found), its task rows
        there (dimensionless, structural zeros exact) and the task rows that depend on the
        rows before them: a deficiency no pose can cure. Computed once, and only when a
        pose looks singular, so well-posed tasks never pay for it."""
        if self._generic is None:
            data = self.model.createData()
            rng = np.random.default_rng(20261122)
            best = None
            for _ in range(_SAMPLES):
                q = pin.integrate(self.model, pin.neutral(self.model), rng.normal(size=self.model.nv))
                J, n_c = self._jacobian(data, q)
                Jd = self._dimensionless(J, n_c)
                r = _rank(Jd)
                if best is None or r > best[0]:
                    best = (r, Jd, n_c)
            rank, Jd, n_c = best
            kept: list[int] = list(range(n_c))
            dependent = []
            for i in range(n_c, Jd.shape[0]):
                if _rank(Jd[kept + [i]]) > len(kept):
                    kept.append(i)
                else:
                    dependent.append(i - n_c)
            task_rows = Jd[n_c:].copy()
            task_rows[np.abs(task_rows) <= STRUCTURAL_RANK_TOL * np.max(np.abs(Jd))] = 0.0
            self._generic = (rank, task_rows, dependent)
        return self._generic

    # ------------------------------------------------------------------ method
    def _method(self, m: int, n: int, rank: int, condition: float, sigma_min: float, q: np.ndarray) -> str:
        if self.method == "damped":
            return "damped"
        if rank < m and self.method != "least_squares":
            raise self._inconsistent(m, n)
        if condition > self.max_condition:
            raise SingularPoseError(
                f"{self.mechanism.source}: the task Jacobian is singular at {self._pose(q)} (condition number "
                f"{condition:.3g} > {self.max_condition:.3g}, smallest singular value {sigma_min:.3g}); "
                "ask for method = \"damped\" to get the closest achievable motion",
                condition=condition, sigma_min=sigma_min, partial=q,
            )
        if rank < m:
            return "least_squares"
        return "exact" if m == n else "minimum_norm"

    def _inconsistent(self, m: int, n: int) -> TaskError:
        hint = "or ask for method = \"least_squares\" (the closest motion, asked vs achieved reported)"
        if m > n:
            return TaskError(f"{self.mechanism.source}: the task has {m} equations (closures included) for {n} "
                             f"joint freedoms: over-determined; drop components {hint}")
        J, dependent = self._structural_rank()[1:]
        zero = [self.row_names[i] for i in dependent if not np.any(J[i])]
        repeated = [self.row_names[i] for i in dependent if np.any(J[i])]
        said = []
        if zero:
            said.append(f"no joint of the model gives {', '.join(zero)} at any pose")
        if repeated:
            said.append(f"{', '.join(repeated)} repeat{'s' if len(repeated) == 1 else ''} a combination of "
                        "the rows before at every pose")
        return TaskError(f"{self.mechanism.source}: the task cannot be met as asked: {'; '.join(said)}; "
                         f"drop those rows {hint}")

    def _pose(self, q: np.ndarray) -> str:
        names = [name for name, j in self.mechanism.joints.items() if j.nv == 1]
        return describe_joint_values(self.mechanism, names, [self.mechanism.coordinate(q, n) for n in names])

    def _apply(self, J: np.ndarray, rhs: np.ndarray, method: str, rank: int) -> np.ndarray:
        """Solve J x = rhs by `method`, J and rhs dimensionless (see `_dimensionless`: the
        caller scales rows in and columns out), so that the minimum norm, the least squares
        and the damping weigh a turn of one radian like a slide of one mechanism size: the
        same answer at any size, in any unit."""
        if method == "exact":
            return np.linalg.solve(J, rhs)
        if method == "damped":
            return J.T @ np.linalg.solve(J @ J.T + self.damping**2 * np.eye(J.shape[0]), rhs)
        if rank == min(J.shape):
            return np.linalg.lstsq(J, rhs, rcond=None)[0]  # minimum-norm or least-squares
        U, s, Vt = np.linalg.svd(J, full_matrices=False)  # rank-deficient: truncated pseudo-inverse
        return Vt[:rank].T @ ((U[:, :rank].T @ rhs) / s[:rank])


def _rank(J: np.ndarray) -> int:
    s = np.linalg.svd(J, compute_uv=False)
    return int(np.sum(s > STRUCTURAL_RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
