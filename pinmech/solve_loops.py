"""Close the loops: q, v and a of the dependent joints from the drivers.

Position: Gauss-Newton on the closure residual from frame placements, with a
backtracking safeguard. Velocity: the constraint Jacobian built from frame Jacobians,
J_dep v_dep = -J_drv v_drv. Acceleration: the same Jacobian and the drift term from
classical frame accelerations, J_dep a_dep = -J_drv a_drv - Jdot v.
Nothing here knows which mechanism it solves.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pinocchio as pin

from pinmech.exceptions import LoopClosureError, MobilityError, ModelError, SingularPoseError
from pinmech.mechanism import Mechanism
from pinmech.results import Accuracy, LoopSolution

#: Default closure tolerance (dimensionless: metres per metre of mechanism, or radians).
DEFAULT_TOL = 1e-13
#: A closure residual below this (relative to the size) is rounding, not a loop out of reach.
ROUNDING_LEVEL = 1e-14
#: Largest Newton step of one joint [rad, or mechanism sizes for a prismatic joint].
MAX_STEP = 1.0
#: Default largest condition number accepted before a pose is called singular. Near a
#: singularity accelerations lose accuracy like eps x condition^3 (tests/test_singular.py),
#: so 1e4 keeps every acceleration pinmech gives to about 2e-4 relative or better.
DEFAULT_MAX_CONDITION = 1e4


def _newton_step(J: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Newton step: a plain solve when J is square (cheap), else least squares."""
    if J.shape[0] == J.shape[1]:
        try:
            return np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            return np.full(J.shape[1], np.nan)
    return np.linalg.lstsq(J, -r, rcond=None)[0]


class LoopSolver:
    """Solves one mechanism pose after pose, keeping Pinocchio `Data` and buffers alive.

    Args:
        mechanism: the model with its loop closures.
        drivers: names of the joints whose motion is given (as many as the mobility).
        tol: closure tolerance, relative to the mechanism's length scale.
        max_iterations: Newton iteration cap.
        max_condition: a constraint Jacobian worse conditioned than this is singular.

    Raises:
        FrameNotFound: a driver that is not a joint of the model.
        MobilityError: more or fewer drivers than the mechanism's mobility.
    """

    def __init__(
        self,
        mechanism: Mechanism,
        drivers: Sequence[str],
        *,
        tol: float = DEFAULT_TOL,
        max_iterations: int = 50,
        max_condition: float = DEFAULT_MAX_CONDITION,
    ) -> None:
        self.mechanism = mechanism
        self.model = mechanism.model
        self.data = self.model.createData()
        self.drivers = tuple(drivers)
        self.tol = tol
        self.max_iterations = max_iterations
        self.max_condition = max_condition
        self._drv_v = np.array([self._driver_index(n) for n in self.drivers], dtype=int)
        self._dep_v = np.setdiff1d(np.arange(self.model.nv), self._drv_v)
        self._check_mobility()
        self._step = np.zeros(self.model.nv)
        self._dep_scale = mechanism.velocity_scale()[self._dep_v]  # dimensionless columns
        self._zero_a = np.zeros(self.model.nv)

    # ------------------------------------------------------------------ set-up
    def _driver_index(self, name: str) -> int:
        joint = self.mechanism.joint(name)
        if joint.nv != 1:
            raise ModelError(f"driver '{name}' has {joint.nv} degrees of freedom; drive one-dof joints",
                             path=self.mechanism.source)
        return joint.idx_v

    def _check_mobility(self) -> None:
        if len(set(self.drivers)) != len(self.drivers):
            raise MobilityError(f"a joint is driven twice: {', '.join(self.drivers)}",
                                mobility=self.mechanism.mobility, drivers=len(self.drivers))
        mobility = self.mechanism.mobility
        if mobility != len(self.drivers):
            rows = self.mechanism.constraint_rows
            raise MobilityError(
                f"{self.mechanism.source}: the mechanism has {self.model.nv} joint freedoms and "
                f"{rows} independent closure equations, so mobility {mobility}; "
                f"{len(self.drivers)} driver(s) given ({', '.join(self.drivers) or 'none'})",
                mobility=mobility,
                drivers=len(self.drivers),
            )

    # ------------------------------------------------------------------ pieces
    def _residual(self, q: np.ndarray) -> np.ndarray:
        """Independent closure rows at q; leaves placements and Jacobians in self.data."""
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        closures = self.mechanism.closures
        if not closures:
            return np.zeros(0)
        return np.concatenate([c.residual(self.data) for c in closures])

    def _full_residual(self) -> float:
        closures = self.mechanism.closures
        if not closures:
            return 0.0
        return float(max(np.max(np.abs(c.full_residual(self.data)), initial=0.0) for c in closures))

    def _jacobian(self) -> np.ndarray:
        closures = self.mechanism.closures
        if not closures:
            return np.zeros((0, self.model.nv))
        return np.vstack([c.jacobian(self.model, self.data) for c in closures])

    def _residual_jacobian(self) -> np.ndarray:
        return np.vstack([c.residual_jacobian(self.model, self.data) for c in self.mechanism.closures])

    def _drift(self) -> np.ndarray:
        closures = self.mechanism.closures
        if not closures:
            return np.zeros(0)
        return np.concatenate([c.drift(self.model, self.data) for c in closures])

    def set_drivers(self, q: np.ndarray, driver_q: Sequence[float]) -> np.ndarray:
        """A copy of q with the drivers' coordinates written in."""
        q = np.array(q, dtype=float, copy=True)
        for name, value in zip(self.drivers, driver_q):
            self.mechanism.set_coordinate(q, name, float(value))
        return q

    # ------------------------------------------------------------------ solves
    def close(self, q_guess: np.ndarray, driver_q: Sequence[float]) -> tuple[np.ndarray, int, float]:
        """Newton on the closure residual with the drivers held.

        Returns:
            (q, iterations, residual): the closed configuration, iterations spent, and the
            largest closure error left (dimensionless).

        Raises:
            LoopClosureError: the loops do not close from this guess (out of reach, or a
                residual that stops decreasing).
        """
        q = self.set_drivers(q_guess, driver_q)
        r = self._residual(q)
        norm = np.max(np.abs(r), initial=0.0)
        iterations = 0
        while norm > self.tol:
            if iterations >= self.max_iterations:
                break
            J_dep = self._residual_jacobian()[:, self._dep_v]
            q, r, norm, ok = self._newton_update(q, J_dep, r, norm)
            iterations += 1
            if not ok:
                break
        full = self._full_residual()
        if norm > self.tol or full > max(self.tol, 1e-12) * 10:
            self._raise_not_closed(q, max(norm, full), iterations, driver_q)
        return q, iterations, max(norm, full)

    def _newton_update(self, q: np.ndarray, J_dep: np.ndarray, r: np.ndarray,
                       norm: float) -> tuple[np.ndarray, np.ndarray, float, bool]:
        """A full Newton step when it lowers the residual (the usual case near a solution);
        else a minimum-norm least-squares step, halved until the residual decreases."""
        step = _newton_step(J_dep, r)
        if np.all(np.isfinite(step)):
            trial = self._move(q, step)
            r_trial = self._residual(trial)
            trial_norm = float(np.max(np.abs(r_trial), initial=0.0))
            if trial_norm < norm:
                return trial, r_trial, trial_norm, True
            self._residual(q)
        step = np.linalg.lstsq(J_dep, -r, rcond=None)[0]
        return self._line_search(q, step, norm)

    def _move(self, q: np.ndarray, step: np.ndarray) -> np.ndarray:
        """q moved by a step of the dependent joints, shortened to at most MAX_STEP.

        From a guess where the Jacobian is singular a solve returns steps of 1e16 rad,
        after which no step can move those joints (a unit in the last place of 1e16 is 2).
        """
        size = np.max(np.abs(step / self._dep_scale), initial=0.0)  # rad, or sizes of the mechanism
        if size > MAX_STEP:
            step = step * (MAX_STEP / size)
        self._step[:] = 0.0
        self._step[self._dep_v] = step
        return pin.integrate(self.model, q, self._step)

    def _line_search(self, q: np.ndarray, step: np.ndarray, norm: float) -> tuple[np.ndarray, np.ndarray, float, bool]:
        """Backtracking: halve the Newton step until the residual decreases."""
        alpha = 1.0
        for _ in range(30):
            trial = self._move(q, alpha * step)
            r = self._residual(trial)
            trial_norm = np.max(np.abs(r), initial=0.0)
            if trial_norm < norm:
                return trial, r, float(trial_norm), True
            alpha *= 0.5
        return q, self._residual(q), norm, False  # data back at q

    def _raise_not_closed(self, q: np.ndarray, norm: float, iterations: int, driver_q: Sequence[float]) -> None:
        drivers = ", ".join(f"{n} = {v:.6g}" for n, v in zip(self.drivers, driver_q))
        names = ", ".join(c.name for c in self.mechanism.closures)
        solved = float(np.max(np.abs(self._residual(q)), initial=0.0))  # the rows Newton solves
        if norm <= ROUNDING_LEVEL:
            why = f"that is rounding level: the tolerance {self.tol:g} is tighter than floating point allows"
        elif solved <= self.tol:
            why = ("the rows dropped as out of the mechanism's plane do not close: the two sides of the cut "
                   "are not in one plane (check the z of the origins and the axes)")
        else:
            why = "the pose is out of reach for these dimensions, or the guess is on no branch"
        raise LoopClosureError(
            f"{self.mechanism.source}: loop(s) {names} cannot be closed at {drivers} "
            f"(residual {norm:.3g} of the mechanism size after {iterations} Newton iterations): {why}",
            residual=float(norm),
            iterations=iterations,
            partial=q,
        )

    def rates(self, q: np.ndarray, driver_v: Sequence[float], driver_a: Sequence[float], *,
              at_q: bool = False) -> tuple[np.ndarray, np.ndarray, Accuracy]:
        """Velocities and accelerations at a closed configuration q.

        Args:
            at_q: the solver's data already holds q's placements and Jacobians (as `close`
                leaves them), so they are not computed again.

        Raises:
            SingularPoseError: the dependent-joint constraint Jacobian is singular.
        """
        if not at_q:
            self._residual(q)
        J = self._jacobian()
        J_dep = J[:, self._dep_v]
        sigma = np.linalg.svd(J_dep * self._dep_scale, compute_uv=False) if J_dep.size else np.ones(1)
        condition = float(sigma[0] / sigma[-1]) if sigma[-1] > 0 else float("inf")
        if condition > self.max_condition:
            raise SingularPoseError(
                f"{self.mechanism.source}: the loop constraint Jacobian is singular at this pose "
                f"(condition number {condition:.3g} > {self.max_condition:.3g}, smallest singular "
                f"value {sigma[-1]:.3g}): the dependent joints' rates are undefined",
                condition=condition,
                sigma_min=float(sigma[-1]),
                partial=q,
            )
        v = np.zeros(self.model.nv)
        v[self._drv_v] = driver_v
        if J_dep.size:
            v[self._dep_v] = np.linalg.solve(J_dep, -J[:, self._drv_v] @ v[self._drv_v])
        pin.forwardKinematics(self.model, self.data, q, v, self._zero_a)
        drift = self._drift()
        a = np.zeros(self.model.nv)
        a[self._drv_v] = driver_a
        if J_dep.size:
            a[self._dep_v] = np.linalg.solve(J_dep, -J[:, self._drv_v] @ a[self._drv_v] - drift)
        accuracy = Accuracy(
            residual=0.0,
            iterations=0,
            condition=condition,
            sigma_min=float(sigma[-1]),
            velocity_residual=float(np.max(np.abs(J @ v), initial=0.0)),
            acceleration_residual=float(np.max(np.abs(J @ a + drift), initial=0.0)),
        )
        return v, a, accuracy

    def solve(
        self,
        driver_q: Sequence[float] | Mapping[str, float],
        driver_v: Sequence[float] | Mapping[str, float] | None = None,
        driver_a: Sequence[float] | Mapping[str, float] | None = None,
        guess: np.ndarray | None = None,
    ) -> LoopSolution:
        """Close the loops and solve the rates for one pose.

        Args:
            driver_q: driver coordinates [rad or m], in the order of `drivers` or by name.
            driver_v: driver velocities [rad/s or m/s] (zero when omitted).
            driver_a: driver accelerations [rad/s^2 or m/s^2] (zero when omitted).
            guess: starting configuration; it picks the assembly branch (default: neutral).
        """
        dq, dv, da = (self._ordered(x) for x in (driver_q, driver_v, driver_a))
        q0 = self.mechanism.neutral() if guess is None else np.asarray(guess, dtype=float)
        if q0.shape != (self.model.nq,) or not np.all(np.isfinite(q0)):
            raise ModelError(f"guess must be {self.model.nq} finite numbers, got shape {q0.shape}",
                             path=self.mechanism.source)
        q, iterations, residual = self.close(q0, dq)
        v, a, acc = self.rates(q, dv, da, at_q=True)
        accuracy = Accuracy(residual, iterations, acc.condition, acc.sigma_min,
                            acc.velocity_residual, acc.acceleration_residual)
        return LoopSolution(q=q, v=v, a=a, accuracy=accuracy, drivers=self.drivers)

    def _ordered(self, values: Sequence[float] | Mapping[str, float] | None) -> np.ndarray:
        if values is None:
            return np.zeros(len(self.drivers))
        if isinstance(values, Mapping):
            unknown = set(values) - set(self.drivers)
            if unknown:
                raise MobilityError(f"{', '.join(sorted(unknown))} is not a driver ({', '.join(self.drivers)})",
                                    mobility=self.mechanism.mobility, drivers=len(self.drivers))
            values = [values.get(n, 0.0) for n in self.drivers]
        out = np.asarray(values, dtype=float).reshape(-1)
        if out.shape != (len(self.drivers),) or not np.all(np.isfinite(out)):
            raise MobilityError(f"expected {len(self.drivers)} finite driver value(s), got {values!r}",
                                mobility=self.mechanism.mobility, drivers=len(self.drivers))
        return out
