"""Many poses of one mechanism at once: the batched twin of `LoopSolver`.

A sweep knows its poses in advance and has close guesses for them (solve_cycle.py
interpolates between exactly solved poses). Solved one `LoopSolver.solve` at a time,
a pose costs some thirty microseconds, nearly all of it numpy's per-call overhead on
2x2 arrays. Here Pinocchio is still called pose by pose (a quarter of a microsecond a
call), but only to store raw frame quantities (cut-frame placements, frame Jacobians,
classical accelerations); the algebra (cut rows, Newton steps, rates, condition
numbers) runs once on whole arrays.

How each cut stores and evaluates its rows: cut_arrays.py.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.arguments import float_array
from pinmech.solve.assembly_check import check_guessed_pose
from pinmech.solve.cut_arrays import ArrayCut, RowCut
from pinmech.exceptions import AssemblyError
from pinmech.solve.results import Accuracy, LoopSolution
from pinmech.solve.loops import DEFAULT_TOL, POLISH, LoopSolver, serialized

#: A guess needing a Newton step larger than this (dimensionless: of the mechanism's size,
#: or radians) is not "close": the batch hands the poses back to the pose-by-pose solver.
MAX_BATCH_STEP = 1e-4


@dataclass(frozen=True)
class BatchSolution:
    """Solved poses as arrays, one row per pose, each with its own accuracy.

    Attributes:
        q, v, a: (N, nq), (N, nv), (N, nv) configurations, velocities [rad/s or m/s] and
            accelerations [rad/s^2 or m/s^2].
        residual, iterations, condition, sigma_min, velocity_residual,
        acceleration_residual: (N,) the fields of `Accuracy`, per pose.
        interpolation: (N, 3) `Accuracy.interpolation` per pose, or None (every pose solved).
    """

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    condition: np.ndarray
    sigma_min: np.ndarray
    velocity_residual: np.ndarray
    acceleration_residual: np.ndarray
    drivers: tuple[str, ...] = ()
    signs: np.ndarray | None = None  # (N, blocks) assembly signatures (branches.py), where computed
    interpolation: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.q)

    def accuracy(self, i: int) -> Accuracy:
        added = (0.0, 0.0, 0.0) if self.interpolation is None else tuple(map(float, self.interpolation[i]))
        return Accuracy(float(self.residual[i]), int(self.iterations[i]), float(self.condition[i]),
                        float(self.sigma_min[i]), float(self.velocity_residual[i]),
                        float(self.acceleration_residual[i]), added)

    def solution(self, i: int) -> LoopSolution:
        """Pose i as the `LoopSolution` that `LoopSolver.solve` returns."""
        return LoopSolution(q=self.q[i], v=self.v[i], a=self.a[i], accuracy=self.accuracy(i), drivers=self.drivers)


class BatchSolver:
    """Closes and rates many poses at once, from guesses close to their solutions.

    Args:
        solver: the pose-by-pose solver whose model, `pin.Data`, drivers, tolerance,
            iteration cap and singular limit are shared.
    """

    def __init__(self, solver: LoopSolver) -> None:
        if not solver._cuts:
            raise ValueError("a batch needs a mechanism with loop closures")
        self.solver = solver
        self.model = solver.model
        self._cuts = [(ArrayCut if not ev._has_angular else RowCut)(ev) for ev in solver._cuts]
        self._zero = np.zeros(self.model.nv)
        self.lock = solver.lock  # one Pinocchio Data: the solver's
        self.refresh = solver.refresh

    @serialized
    def try_solve(self, guesses: np.ndarray, driver_q: np.ndarray, driver_v: np.ndarray,
                  driver_a: np.ndarray, max_step: float = MAX_BATCH_STEP, *,
                  _on_path: bool = False) -> BatchSolution | None:
        """Solve N poses: guesses (N, nq), drivers' q, v, a (N, number of drivers).

        Returns:
            The solved poses, or None when one of them needs the pose-by-pose solver: a
            guess too far from its solution (a Newton step over `max_step`), a loop
            that does not close within the iteration cap, a singular Jacobian, or a pose
            on another assembly than the solver's reference (branches.py). That solver
            then says which pose, and why, in its own words. Where the signature cannot
            name every assembly (a block of several loops, a spatial loop), each pose is
            compared with the one continuation reaches from the reference
            (assembly_check.py), unless `_on_path`: the guesses lie between poses
            continuation found, as a sweep's.
        """
        s = self.solver
        guesses = float_array(guesses, "guesses", (None, self.model.nq)).copy()
        n, k = len(guesses), len(s.drivers)
        driver_q, driver_v, driver_a = (float_array(x, name, (n, k)) for x, name in
                                        ((driver_q, "driver_q"), (driver_v, "driver_v"), (driver_a, "driver_a")))
        Q = self._set_drivers(guesses, driver_q)
        for cut in self._cuts:
            cut.allocate(n, self.model.nv)
        self._read_positions(Q, range(n))
        iterations = np.zeros(n, dtype=int)
        r = self._rows("residual")
        error = np.abs(r).max(axis=1, initial=0.0)
        while True:
            bad = np.flatnonzero(error > s.tol)
            if not bad.size:
                break
            if iterations.max(initial=0) >= s.max_iterations or not self._newton(Q, bad, r, max_step):
                return None
            iterations[bad] += 1
            r = self._rows("residual")
            error = np.abs(r).max(axis=1, initial=0.0)
        polish = np.flatnonzero(error > POLISH) if s.tol <= DEFAULT_TOL else ()  # as LoopSolver.close
        if len(polish) and self._newton(Q, polish, r, max_step):
            iterations[polish] += 1
            error = np.abs(self._rows("residual")).max(axis=1, initial=0.0)
            if np.any(error > s.tol):
                return None
        full = np.max([c.full_residual() for c in self._cuts], axis=0)
        if np.any(full > max(s.tol, 1e-12) * 10):
            return None
        out = self._rates(Q, driver_v, driver_a, np.maximum(error, full), iterations)
        ref = s.reference
        if out is not None and ref is not None and ref.keep and np.any(out.signs != np.array(ref.signs)):
            return None  # a pose on another assembly than the solver's reference
        if out is not None and ref is not None and ref.keep and not _on_path \
                and not s.structure.signs_name_every_assembly and not self._on_reference(out.q, driver_q):
            return None
        return out

    def _on_reference(self, Q: np.ndarray, driver_q: np.ndarray) -> bool:
        """Whether every pose is the one continuation reaches from the reference."""
        try:
            for q, x in zip(Q, driver_q):
                check_guessed_pose(self.solver, q, np.array(x, dtype=float))
        except AssemblyError:
            return False
        return True

    @serialized
    def measure(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> BatchSolution:
        """The accuracy of given poses (N rows of q, v, a), e.g. interpolated ones: closure
        residual, condition number, and the residuals of the velocity and acceleration
        equations, as `try_solve` reports them for the poses it solves."""
        n = len(q)
        for cut in self._cuts:
            cut.allocate(n, self.model.nv)
        self._read_positions(q, range(n))
        residual = np.maximum(np.abs(self._rows("residual")).max(axis=1),
                              np.max([c.full_residual() for c in self._cuts], axis=0))
        J = self._rows("jacobian")
        condition, sigma_min = condition_batch(J[:, :, self.solver._dep] * self.solver._dep_scale)
        drift = self._drift(q, v)
        return BatchSolution(q, v, a, residual, np.zeros(n, dtype=int), condition, sigma_min,
                             *self._equation_residuals(J, v, a, drift), self.solver.drivers)

    def _drift(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        model, data, zero = self.model, self.solver.data, self._zero
        for i in range(len(Q)):
            pin.forwardKinematics(model, data, Q[i], V[i], zero)
            for cut in self._cuts:
                cut.read_rates(data, i)
        return self._rows("drift")

    @staticmethod
    def _equation_residuals(J: np.ndarray, V: np.ndarray, A: np.ndarray,
                            drift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """max |J v| and max |J a + Jdot v| per pose."""
        return (np.abs(np.einsum("nkj,nj->nk", J, V)).max(axis=1),
                np.abs(np.einsum("nkj,nj->nk", J, A) + drift).max(axis=1))

    # ------------------------------------------------------------------ positions
    def _set_drivers(self, Q: np.ndarray, driver_q: np.ndarray) -> np.ndarray:
        for k, (i, continuous) in enumerate(self.solver._drv_q):
            if continuous:
                Q[:, i], Q[:, i + 1] = np.cos(driver_q[:, k]), np.sin(driver_q[:, k])
            else:
                Q[:, i] = driver_q[:, k]
        return Q

    def _read_positions(self, Q: np.ndarray, poses) -> None:
        model, data, cuts = self.model, self.solver.data, self._cuts
        for i in poses:
            pin.computeJointJacobians(model, data, Q[i])
            for cut in cuts:
                cut.read_positions(data, i)

    def _rows(self, name: str) -> np.ndarray:
        parts = [getattr(c, name)() for c in self._cuts]
        return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=1)

    def _newton(self, Q: np.ndarray, bad: np.ndarray, r: np.ndarray, max_step: float = MAX_BATCH_STEP) -> bool:
        """One Newton step on the poses `bad`; False when a step is not small or finite."""
        s = self.solver
        J_dep = self._rows("newton_jacobian")[bad][:, :, s._dep]
        step = solve_batch(J_dep, -r[bad])
        size = np.abs(step * s._dep_scale).max(initial=0.0)
        if not np.isfinite(size) or size > max_step:
            return False
        full = np.zeros((len(bad), self.model.nv))
        full[:, s._dep] = step
        Q[bad] = integrate_many(self.model, Q[bad], full)
        self._read_positions(Q, bad)
        return True

    # ------------------------------------------------------------------ rates
    def _rates(self, Q: np.ndarray, driver_v: np.ndarray, driver_a: np.ndarray, residual: np.ndarray,
               iterations: np.ndarray) -> BatchSolution | None:
        s, n, nv = self.solver, len(Q), self.model.nv
        J = self._rows("jacobian")
        J_dep, J_drv = J[:, :, s._dep], J[:, :, s._drv]
        condition, sigma_min = condition_batch(J_dep * s._dep_scale)
        if np.any(condition > s.max_condition):
            return None
        V, A = np.zeros((n, nv)), np.zeros((n, nv))
        V[:, s._drv], A[:, s._drv] = driver_v, driver_a
        V[:, s._dep] = solve_batch(J_dep, -np.einsum("nkj,nj->nk", J_drv, driver_v))
        drift = self._drift(Q, V)
        A[:, s._dep] = solve_batch(J_dep, -np.einsum("nkj,nj->nk", J_drv, driver_a) - drift)
        if not (np.isfinite(V).all() and np.isfinite(A).all()):
            return None  # the pose-by-pose solver names the pose (RateOverflowError)
        return BatchSolution(Q, V, A, residual, iterations, condition, sigma_min,
                             *self._equation_residuals(J, V, A, drift), s.drivers, s.structure.signs_many(J_dep))


# ---------------------------------------------------------------------- manifold
def integrate_many(model: pin.Model, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """`pin.integrate` of each row of q (N, nq) by the row of dq (N, nv): on arrays for
    one-dof joints (prismatic, revolute, continuous stored as cos/sin), row by row through
    Pinocchio for any other joint."""
    out = np.empty_like(q)
    for joint in model.joints[1:]:
        iq, iv = joint.idx_q, joint.idx_v
        if joint.nq == joint.nv == 1:
            out[:, iq] = q[:, iq] + dq[:, iv]
        elif joint.nq == 2 and joint.nv == 1:
            c, s, w = q[:, iq], q[:, iq + 1], dq[:, iv]
            cw, sw = np.cos(w), np.sin(w)  # a rotation keeps (c, s) unit to rounding
            out[:, iq], out[:, iq + 1] = cw * c - sw * s, sw * c + cw * s
        else:
            return np.array([pin.integrate(model, a, b) for a, b in zip(q, dq)])
    return out


def difference_many(model: pin.Model, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """`pin.difference(q0[i], q1[i])` for each row: on arrays for one-dof joints."""
    out = np.empty((len(q0), model.nv))
    for joint in model.joints[1:]:
        iq, iv = joint.idx_q, joint.idx_v
        if joint.nq == joint.nv == 1:
            out[:, iv] = q1[:, iq] - q0[:, iq]
        elif joint.nq == 2 and joint.nv == 1:
            c0, s0, c1, s1 = q0[:, iq], q0[:, iq + 1], q1[:, iq], q1[:, iq + 1]
            out[:, iv] = np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
        else:
            return np.array([pin.difference(model, a, b) for a, b in zip(q0, q1)])
    return out


# ---------------------------------------------------------------------- linear algebra
def solve_batch(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with A[i] x[i] = b[i] for a stack of small square A (N, k, k): closed form for
    k <= 2, LU above. inf or NaN rows where A[i] is singular."""
    k = A.shape[-1]
    if k == 0:
        return np.zeros(b.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        if k == 1:
            return b / A[:, 0]
        if k == 2:
            a, c, d, e = A[:, 0, 0], A[:, 0, 1], A[:, 1, 0], A[:, 1, 1]
            det = a * e - c * d
            return np.stack(((e * b[:, 0] - c * b[:, 1]) / det, (a * b[:, 1] - d * b[:, 0]) / det), axis=1)
    try:
        return np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.full(b.shape, np.nan)


def condition_batch(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """2-norm condition numbers and smallest singular values of a stack of square A, as
    `solve_loops._condition` (closed form up to 2x2, SVD above)."""
    n, k = A.shape[0], A.shape[-1]
    if k == 0:
        return np.ones(n), np.ones(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        if k == 1:
            s = np.abs(A[:, 0, 0])
            return np.where(s > 0, 1.0, np.inf), s
        if k == 2:
            a, c, d, e = A[:, 0, 0], A[:, 0, 1], A[:, 1, 0], A[:, 1, 1]
            frob2, det = a * a + c * c + d * d + e * e, np.abs(a * e - c * d)
            s_max2 = 0.5 * (frob2 + np.sqrt(np.maximum(frob2 * frob2 - 4.0 * det * det, 0.0)))
            s_min = np.where(s_max2 > 0, det / np.sqrt(s_max2), 0.0)
            return np.where(det > 0, s_max2 / det, np.inf), s_min
        sigma = np.linalg.svd(A, compute_uv=False)
        return np.where(sigma[:, -1] > 0, sigma[:, 0] / sigma[:, -1], np.inf), sigma[:, -1]
