"""Result objects that carry their own accuracy, so a caller can tell when not to trust them."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

_T = TypeVar("_T")
_new, _set_attribute = object.__new__, object.__setattr__

#: Machine epsilon of float64, the rounding of every number pinmech computes.
EPS = float(np.finfo(float).eps)
#: Constants of the position, velocity and acceleration bounds (`Accuracy.error_bounds`).
BOUND_FACTORS = (4.0, 4.0, 16.0)


def frozen(cls: type[_T], fields: dict[str, Any]) -> _T:
    """An instance of the frozen dataclass `cls` holding `fields` (every field by name, in
    its order): what `cls(**fields)` builds, without the generated __init__, which sets each
    field through object.__setattr__ (about 0.1 us a field: most of a one-pose result's
    cost). For classes without __post_init__; tests/test_pose_results.py checks each use."""
    instance = _new(cls)
    _set_attribute(instance, "__dict__", fields)
    return instance


@dataclass(frozen=True)
class Accuracy:
    """How well a solution satisfies its equations.

    Attributes:
        residual: largest closure (or task) position error, dimensionless: position rows
            are divided by the mechanism's length scale [m], orientation rows are [rad].
        iterations: Newton iterations spent on the position (0 when none were needed).
        condition: 2-norm condition number of the Jacobian solved for the rates; NaN at a
            pose the certification dial left uncertified (`certified` False: certify.py).
        sigma_min: smallest singular value of that Jacobian (dimensionless rows); NaN
            where `condition` is.
        velocity_residual: max |J q_dot| of the velocity equations, per second.
        acceleration_residual: max |J q_ddot + Jdot q_dot| of the acceleration equations.
        interpolation: for a pose interpolated between solved ones (a sweep's
            `interpolate`), the relative errors of its positions, velocities and
            accelerations that interpolation adds, measured against poses solved where
            the interpolation error peaks (solve_cycle.py); (0, 0, 0) for a solved pose.
    """

    residual: float
    iterations: int
    condition: float
    sigma_min: float
    velocity_residual: float = 0.0
    acceleration_residual: float = 0.0
    interpolation: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def certified(self) -> bool:
        """Whether this pose has its exact condition number: False at a pose the certification
        dial (`certify`, certify.py) left to its residuals and assembly check."""
        return self.condition == self.condition  # not NaN

    @property
    def error_bounds(self) -> tuple[float, float, float]:
        """Relative errors to expect of positions, velocities and accelerations.

        With m = max(residual, eps) (what the loop closure left, or rounding) and k the
        condition number: positions 4 k m (the residual left along the Jacobian's soft
        direction), velocities 4 k^2 m, accelerations 16 k^3 m. Accelerations reach k^3 m
        where the rates stay finite while k grows (an R-RTR whose guide passes through its
        pivot: 3.1 k^3 m, the worst measured); where the rates grow with k (a four-bar's
        toggle or dead centres) they do better, about k^2 m, and an open arm's rate problem
        gives k eps for both. An interpolated pose adds its `interpolation` errors. The
        factors are margins of 2 to 5 over the worst ratios measured against
        extended-precision closed forms (tests/test_singular.py, scripts/singular_accuracy.py):
        k depends on how lengths are made dimensionless (by the loops' sizes), which no law
        fixes to better than a small factor. NaN at a pose not `certified`: without its
        condition number no bound is stated.
        """
        m = max(self.residual, EPS)
        k = self.condition
        p, v, a = self.interpolation
        return (BOUND_FACTORS[0] * k * m + p, BOUND_FACTORS[1] * k**2 * m + v, BOUND_FACTORS[2] * k**3 * m + a)

    @property
    def error_estimate(self) -> float:
        """The acceleration bound of `error_bounds`, the largest of the three."""
        return self.error_bounds[2]

    def is_accurate(self, tol: float = 1e-9, max_condition: float = 1e8) -> bool:
        """True when the position residual is below `tol` and the Jacobian is well conditioned
        (False at a pose not `certified`: its conditioning is not known)."""
        return self.residual <= tol and self.condition <= max_condition

    def as_dict(self) -> dict[str, float | int | bool | None]:
        """The numbers by name, for JSON; at a pose not `certified` the condition number,
        sigma_min and the bounds that need them are None (never NaN: JSON has none) and
        "certified" is False."""
        certified = self.certified
        bounds = self.error_bounds if certified else (None, None, None)
        return {
            "closure_residual": self.residual,
            "newton_iterations": self.iterations,
            "certified": certified,
            "condition_number": self.condition if certified else None,
            "sigma_min": self.sigma_min if certified else None,
            "velocity_residual": self.velocity_residual,
            "acceleration_residual": self.acceleration_residual,
            "estimated_relative_error": bounds[2],
            "relative_error_bound_position": bounds[0],
            "relative_error_bound_velocity": bounds[1],
            "relative_error_bound_acceleration": bounds[2],
        }


@dataclass(frozen=True)
class LoopSolution:
    """Joint positions, velocities and accelerations of a closed mechanism (SI units).

    Attributes:
        q: configuration vector of the Pinocchio model (continuous joints as cos/sin).
        v: joint velocities [rad/s or m/s], one per degree of freedom.
        a: joint accelerations [rad/s^2 or m/s^2].
        accuracy: residuals, iterations and conditioning of this solve.
        assembly: the assembly the pose is on (`branches.Assembly`: a sign and a label
            per loop block), None for a mechanism without loops.
        route: how the pose was reached (`continuation.Route`: from which driver values,
            in how many continuation steps, change points and folds passed), None for a
            Newton solve from a guess.
    """

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    accuracy: Accuracy
    drivers: tuple[str, ...] = field(default=())
    assembly: Any = None
    route: Any = None

    def is_closed(self, tol: float = 1e-9) -> bool:
        """True when every loop closes to `tol` (relative to each loop's size)."""
        return self.accuracy.residual <= tol


@dataclass(frozen=True)
class RateSolution:
    """Joint rates and accelerations that realise a task, with their own accuracy.

    The velocity rows are J q_dot = x_dot and the acceleration rows J q_ddot + Jdot q_dot
    = x_ddot, where x_ddot is the CLASSICAL acceleration (d^2 p/dt^2 of a frame origin;
    angular rows: the angular acceleration). Loop-closure rows, if any, hold on top.

    Attributes:
        v: joint velocities [rad/s or m/s], all of the model's freedoms.
        a: joint accelerations [rad/s^2 or m/s^2].
        method: "exact" (square, full rank), "minimum_norm" (more joints than rows: the
            smallest |q_dot| that does the task), "least_squares" (asked for: rows that
            cannot all hold, the closest motion in the least-squares sense) or "damped"
            (asked for: damped least squares, the motion achieved may differ from the asked).
        condition: condition number of the stacked Jacobian (closure + task rows), rows
            and columns made dimensionless by the mechanism's size; over its rank.
        sigma_min: its smallest singular value (over its rank), dimensionless.
        nullspace_dim: joint freedoms the task leaves free (0 for a square task).
        rank: rank of the stacked Jacobian (closure rows included).
        requested_velocity, achieved_velocity: task rows, asked and obtained (J v)
            [m/s or rad/s].
        requested_acceleration, achieved_acceleration: task rows, asked and obtained
            (J a + Jdot v) [m/s^2 or rad/s^2].
        closure_velocity_residual, closure_acceleration_residual: largest |row| of the
            loop-closure equations at the solution (0 on an open chain).
        closure_residual: the closure residual of the q solved at, dimensionless as
            `Accuracy.residual` (0 on an open chain; a q open beyond the solver's tol is
            refused, never solved).
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
    rank: int = -1
    closure_residual: float = 0.0

    @property
    def velocity_error(self) -> float:
        """Largest |asked - achieved| over the velocity rows [m/s or rad/s]."""
        return float(np.max(np.abs(self.requested_velocity - self.achieved_velocity), initial=0.0))

    @property
    def acceleration_error(self) -> float:
        """Largest |asked - achieved| over the acceleration rows [m/s^2 or rad/s^2]."""
        return float(np.max(np.abs(self.requested_acceleration - self.achieved_acceleration), initial=0.0))

    def is_exact(self, tol: float = 1e-9) -> bool:
        """True when the achieved motion equals the asked one to `tol` (relative, floor 1)."""
        scale_v = max(1.0, float(np.max(np.abs(self.requested_velocity), initial=0.0)))
        scale_a = max(1.0, float(np.max(np.abs(self.requested_acceleration), initial=0.0)))
        return self.velocity_error <= tol * scale_v and self.acceleration_error <= tol * scale_a
