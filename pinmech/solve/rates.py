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
from pinmech.seeded import Seeded
from pinmech.solve import core
from pinmech.solve.core import _core
from pinmech.solve.kernels import kept
from pinmech.solve.results import RateSolution, frozen
from pinmech.solve.solver_options import SolverOptions
from pinmech.solve.loops import (
    DEFAULT_MAX_CONDITION,
    DEFAULT_TOL,
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
#: quantity pinmech takes (docs/explanation/accuracy.md), lambda^2 overflows by 1e155 and the
#: rates underflow to denormals before that.
DAMPING_RANGE = (1e-5, 1e50)
#: The methods the compiled solve is asked for (csrc/rates.cpp), and the ones it reports.
_ASKED = {"exact": 0, "least_squares": 1, "damped": 2}
_USED = ("exact", "minimum_norm", "least_squares", "damped")
_USED_NAMES = np.array(_USED, dtype=object)  # solve_many's methods, indexed by the core's codes (copied out)
#: Its status per pose: solved; looks singular (asked again with the structural rank);
#: rows that cannot all hold; singular beyond max_condition.
_SOLVED, _NEEDS_RANK, _INCONSISTENT, _SINGULAR = 0, 1, 2, 3


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


class RateSolver(SolverOptions):
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
        kernel: the kinematic passes, as `LoopSolver`'s ("generic" or "generated").
        certify: the certification dial, as `LoopSolver`'s: of the poses of one `solve_many`
            call, which get the exact condition number (the others, regular by their
            factorization, report NaN); certify.py.

    Raises:
        TaskError: unknown method, no task, or a damping out of DAMPING_RANGE.
        OptionError: max_condition or tol out of SOLVER_RANGES.
        FrameNotFound: a task names a frame the model lacks.
    """

    def __init__(self, mechanism: Mechanism, tasks: Sequence[Task], *, method: str = "exact",
                 damping: float = 1e-3, max_condition: float = DEFAULT_MAX_CONDITION,
                 tol: float = DEFAULT_TOL, kernel: str = "generic", certify: str = "every-pose") -> None:
        self.method = method  # checked first: a TaskError before anything is built
        if not isinstance(tasks, (list, tuple)) or not all(isinstance(t, Task) for t in tasks):
            raise TaskError(f"tasks must be a list of pinmech.Task, got {tasks!r:.80}")
        if not tasks:
            raise TaskError("no task given: add a [[task]] with frame, components, velocity, acceleration")
        self.damping = damping
        self.mechanism = mechanism
        self.model = mechanism.model
        self.lock = threading.RLock()  # one Data: threads sharing the solver take turns
        self.data = self.model.createData()
        self.tasks = tuple(tasks)
        self.frames = [mechanism.frame_id(t.frame) for t in self.tasks]
        self.max_condition = max_condition  # checked when set, also later (SolverOptions): NaN would turn the check off
        self.tol = tol
        self.kernel = kernel
        self.certify = certify
        self.x_dot = np.concatenate([t.velocity for t in self.tasks])
        self.x_ddot = np.concatenate([t.acceleration for t in self.tasks])
        self.row_names = [f"{t.frame}.{c}" for t in self.tasks for c in t.components]
        self._row_scale = np.array([1.0 / mechanism.length_scale if c in "xyz" else 1.0
                                    for t in self.tasks for c in t.components])
        self._generic: tuple[int, np.ndarray, list[int]] | None = None  # rank, rows, dependent rows
        #: Where a row of the compiled answer splits (set with the core): nv, the first
        #: achieved task row, the number of task rows.
        self._columns = (0, 0, 0)

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
        x_dot = self.x_dot if velocity is None else self._values(velocity, self.x_dot, "velocity")
        x_ddot = self.x_ddot if acceleration is None else self._values(acceleration, self.x_ddot, "acceleration")
        row = self._rates(q[None], x_dot, x_ddot)[0]
        nv, first, m = self._columns
        condition, sigma_min, closure_v, closure_a, _, independent, full, rank, used = self._checked(
            q, row[2 * nv:first])
        rank = int(rank)
        return frozen(RateSolution, {  # RateSolution(**these), built at a tenth of the cost
            "v": row[:nv], "a": row[nv:2 * nv], "method": _USED[int(used)], "condition": condition,
            "sigma_min": sigma_min, "nullspace_dim": nv - rank,
            "requested_velocity": x_dot.copy(), "achieved_velocity": row[first:first + m],
            "requested_acceleration": x_ddot.copy(), "achieved_acceleration": row[first + m:],
            "closure_velocity_residual": closure_v, "closure_acceleration_residual": closure_a,
            "rank": rank, "closure_residual": max(independent, full)})

    @serialized
    def solve_many(self, q: np.ndarray) -> RateBatch:
        """`solve` at every row of q (N, nq), with the tasks' own velocities and
        accelerations, as arrays (the same compiled solve, one call for every pose).

        Raises:
            ModelError: q is not an (N, nq) array of configurations (as `solve`).
            LoopClosureError, TaskError, SingularPoseError: as `solve`, at the first pose
                that has them.
        """
        q = np.ascontiguousarray(self.mechanism.checked_q(q, many=True))
        out = self._rates(q, self.x_dot, self.x_ddot)
        nv, m = self.model.nv, self.x_dot.size
        first = 2 * nv + _core.RATE_NUMBERS
        v, a, numbers = out[:, :nv], out[:, nv:2 * nv], out[:, 2 * nv:first]
        achieved_v, achieved_a = out[:, first:first + m], out[:, first + m:]
        condition, sigma_min, closure_v, closure_a, status, independent, full, _, used = numbers.T
        bad = (status != _SOLVED) | ~is_closed(independent, full, self.tol)
        for i in np.flatnonzero(bad)[:1]:  # the first pose that has an error raises it, named
            self._checked(q[i], numbers[i])
        methods = _USED_NAMES[used.astype(np.intp)]
        return RateBatch(v, a, methods, condition, sigma_min, achieved_v, achieved_a, closure_v, closure_a,
                         np.maximum(independent, full))

    def _rates(self, q: np.ndarray, x_dot: np.ndarray, x_ddot: np.ndarray) -> np.ndarray:
        """The compiled rate solve at every row of q (csrc/rates.cpp), a row a pose: v, a
        (nv each), RATE_NUMBERS numbers (condition, sigma_min, closure velocity and
        acceleration residuals, status, q's independent and full closure residuals, rank,
        method code), the achieved task rows' velocities and accelerations. Poses that look
        singular are solved again with the task's structural rank."""
        core = self._compiled()
        out = np.empty((len(q), core.rate_columns))
        core.rates(q, x_dot, x_ddot, self._generic[0] if self._generic is not None else -1, out)
        status = 2 * self._columns[0] + 4  # nv as the core has it
        # only poses that look singular pay for the structural rank (one pose, as `solve`
        # asks: a float compare, where numpy's compare and reduction took 2 of its 10 us)
        if len(q) == 1:
            again = [0] if out[0, status] == _NEEDS_RANK else []
        else:
            again = np.flatnonzero(out[:, status] == _NEEDS_RANK)
        if len(again):
            more = np.empty((len(again), out.shape[1]))
            core.rates(np.ascontiguousarray(q[again]), x_dot, x_ddot, self._structural_rank()[0], more)
            out[again] = more
        return out

    def _checked(self, q: np.ndarray, numbers: np.ndarray) -> list[float]:
        """One pose's numbers as floats, or its error: open loops first (how far, in m and
        deg), then a task that cannot hold, then a singular pose."""
        values = numbers.tolist()
        condition, sigma_min, _, _, status, independent, full, rank, _ = values
        if self.mechanism.closures and not is_closed(independent, full, self.tol):
            pin.forwardKinematics(self.model, self.data, q)
            raise open_loops_error(self.mechanism, q, max(independent, full), self.tol,
                                   f"the task's rates at {self._pose(q)}")
        if status == _INCONSISTENT:
            raise self._inconsistent(int(self.x_dot.size + self._closure_rows), self.model.nv)
        if status == _SINGULAR:
            raise SingularPoseError(
                f"{self.mechanism.source}: the task Jacobian is singular at {self._pose(q)} (condition number "
                f"{condition:.3g} > {self.max_condition:.3g}, smallest singular value {sigma_min:.3g}); "
                "ask for method = \"damped\" to get the closest achievable motion",
                condition=condition, sigma_min=sigma_min, partial=q,
            )
        return values

    @property
    def method(self) -> str:
        """"exact", "least_squares" or "damped" (checked when set, also later)."""
        return self._method

    @method.setter
    def method(self, value: str) -> None:  # an unknown one set later was a KeyError at the next solve
        if value not in METHODS:
            raise TaskError(f"method must be one of {', '.join(METHODS)}, got {value!r}")
        self._method = value

    @property
    def damping(self) -> float:
        """Lambda of the damped least squares (dimensionless), in DAMPING_RANGE (checked when set, also later)."""
        return self._damping

    @damping.setter
    def damping(self, value: float) -> None:  # NaN set later gave NaN rates
        low, high = DAMPING_RANGE
        number = value if isinstance(value, (int, float, np.number)) and not isinstance(value, bool) else None
        if number is None or not low <= number <= high:  # NaN is in no range
            raise TaskError(f"damping must be a positive number in [{low:g}, {high:g}] (dimensionless: below, "
                            f"its square drowns in rounding; above, it overflows), got {value!r}")
        self._damping = float(value)

    def _compiled(self):
        """The core with this solver's loops, task and options (built once per model tree:
        it reads placements changed in the model; the scales, which a model changed in place
        changes, and the options are read afresh)."""
        cached = self.__dict__.get("_core")
        closures = self.mechanism.closures
        options = (self.mechanism.length_scale, self.method, self.damping, self.max_condition,
                   [c.length_scale for c in closures] if closures else None)
        if cached is None or cached[0].model is not self.model or not cached[0].same_structure:
            built = core.compile_loops(self.model, self.mechanism.closures, self.mechanism.velocity_scale(),
                                       extra_frames=self.frames)
            compiled, rebuilt = built
            compiled.set_task([rebuilt.frames[f] for f in self.frames], [[int(k) for k in t.rows] for t in self.tasks],
                              [int(t.reference == "local") for t in self.tasks])
            cached = (compiled, None)
            nv = self.model.nv
            self._columns = (nv, 2 * nv + _core.RATE_NUMBERS, self.x_dot.size)
        kept(self.__dict__, cached[0], self.model, self.kernel)
        core.set_certify(cached[0], self.certify)
        if cached[1] != options:
            rows, columns = self._scales(self._closure_rows)
            cached[0].set_rate_options(rows, columns, _ASKED[self.method], self.damping, self.max_condition)
            self.__dict__["_core"] = cached = (cached[0], options)
        return cached[0]

    @property
    def _closure_rows(self) -> int:
        return sum(c.rows for c in self.mechanism.closures)

    def _values(self, given: np.ndarray, default: np.ndarray, name: str) -> np.ndarray:
        """Task rows given for one call, checked against the tasks' own (`default`)."""
        wrong = not_real(given)
        if wrong:
            raise ModelError(f"{name} must be real numbers (SI), got {wrong}: pinmech does not cast them",
                             path=self.mechanism.source)
        values = np.ascontiguousarray(given, dtype=float)
        if values.shape != default.shape or not np.all(np.isfinite(values)):
            raise TaskError(f"{name} needs {default.size} finite values (rows {', '.join(self.row_names)}), "
                            f"got {given!r}")
        return values

    # ------------------------------------------------------------------ rows
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
            compiled = self._compiled()
            n_c = self._closure_rows
            rng = Seeded(20261122)
            best = None
            for _ in range(_SAMPLES):
                q = pin.integrate(self.model, pin.neutral(self.model), rng.normal(size=self.model.nv))
                Jd = self._dimensionless(compiled.stacked_jacobian(q), n_c)
                r = _rank(Jd)
                if best is None or r > best[0]:
                    best = (r, Jd)
            rank, Jd = best
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

    # ------------------------------------------------------------------ errors
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


def _rank(J: np.ndarray) -> int:
    s = np.linalg.svd(J, compute_uv=False)
    return int(np.sum(s > STRUCTURAL_RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
