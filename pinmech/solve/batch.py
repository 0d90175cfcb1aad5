"""Many poses of one mechanism from close guesses (interpolated ones, as a sweep's):
the batch mode of the compiled core, each pose closed and rated by the core's Newton
and rate solves (pinmech/csrc), with its own accuracy, in one call.
"""

from __future__ import annotations

from dataclasses import dataclass

import math

import numpy as np

from pinmech.arguments import float_array
from pinmech.exceptions import AssemblyError
from pinmech.solve.assembly_check import check_guessed_pose
from pinmech.solve.core import core_for
from pinmech.solve.loops import LoopSolver, serialized
from pinmech.solve.results import Accuracy, LoopSolution

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
        solver: the pose-by-pose solver whose model, drivers, tolerance, iteration cap,
            singular limit and compiled core are shared.
    """

    def __init__(self, solver: LoopSolver) -> None:
        if not solver._cuts:
            raise ValueError("a batch needs a mechanism with loop closures")
        self.solver = solver
        self.model = solver.model
        self.lock = solver.lock  # one core: the solver's
        self.refresh = solver.refresh

    @serialized
    def try_solve(self, guesses: np.ndarray, driver_q: np.ndarray, driver_v: np.ndarray,
                  driver_a: np.ndarray, max_step: float = MAX_BATCH_STEP, *,
                  _on_path: bool = False) -> BatchSolution | None:
        """Solve N poses: guesses (N, nq), drivers' q, v, a (N, number of drivers).

        Returns:
            The solved poses, or None when one of them needs the pose-by-pose solver: a
            guess too far from its solution (Newton steps adding up to over `max_step`,
            dimensionless), a loop that does not close within the iteration cap, a
            singular Jacobian, or a pose on another assembly than the solver's reference
            (branches.py). That solver then says which pose, and why, in its own words.
            Where the signature cannot name every assembly (a block of several loops, a
            spatial loop), each pose is compared with the one continuation reaches from
            the reference (assembly_check.py), unless `_on_path`: the guesses lie between
            poses continuation found, as a sweep's.
        """
        s = self.solver
        guesses = float_array(guesses, "guesses", (None, self.model.nq)).copy()
        n, k = len(guesses), len(s.drivers)
        driver_q, driver_v, driver_a = (float_array(x, name, (n, k)) for x, name in
                                        ((driver_q, "driver_q"), (driver_v, "driver_v"), (driver_a, "driver_a")))
        compiled = core_for(s)
        Q, V, A = guesses, np.zeros((n, self.model.nv)), np.zeros((n, self.model.nv))
        numbers, signs = np.zeros((n, 6)), []
        for i in range(n):
            x = np.ascontiguousarray(driver_q[i])
            q, ok, residual, iterations = compiled.close(s.set_drivers(Q[i], x), x, s.max_iterations, True)
            if not ok or not compiled.moved <= max_step:
                return None
            V[i], A[i], sign, condition, sigma_min, v_res, a_res, _ = compiled.rates_at(
                q, np.ascontiguousarray(driver_v[i]), np.ascontiguousarray(driver_a[i]))
            if condition > s.max_condition or not math.isfinite(sum(V[i].tolist()) + sum(A[i].tolist())):
                return None  # the pose-by-pose solver names the pose (singular, or RateOverflowError)
            Q[i] = q
            numbers[i] = residual, iterations, condition, sigma_min, v_res, a_res
            signs.append(sign)
        out = BatchSolution(Q, V, A, numbers[:, 0], numbers[:, 1].astype(int), *numbers[:, 2:].T, s.drivers,
                            np.array(signs, dtype=int).reshape(n, -1))
        ref = s.reference
        if ref is not None and ref.keep and np.any(out.signs != np.array(ref.signs)):
            return None  # a pose on another assembly than the solver's reference
        if ref is not None and ref.keep and not _on_path \
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
        equations (max |J v| and max |J a + Jdot v|), as `try_solve` reports them."""
        s, n = self.solver, len(q)
        compiled = core_for(s)
        numbers = np.zeros((n, 5))
        zero = np.zeros(len(s.drivers))
        for i in range(n):
            residual = max(float(np.max(np.abs(compiled.residual(q[i])), initial=0.0)), compiled.full_residual())
            J = compiled.jacobian(False)
            drift = compiled.drift(q[i], v[i])
            condition, sigma_min = compiled.rates_at(q[i], zero, zero)[3:5]
            numbers[i] = (residual, condition, sigma_min, float(np.max(np.abs(J @ v[i]), initial=0.0)),
                          float(np.max(np.abs(J @ a[i] + drift), initial=0.0)))
        return BatchSolution(q, v, a, numbers[:, 0], np.zeros(n, dtype=int), *numbers[:, 1:].T, s.drivers)
