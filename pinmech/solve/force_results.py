"""What a force solve gives: loads, reactions, the power balance and the solution that
carries them, with the mechanical advantage read from it (SI, world frame)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Load:
    """An external load, constant in the world frame.

    Attributes:
        name: a label for reports.
        frame: Pinocchio frame id of the point the force acts at (the link's frame for a
            pure torque).
        force: force [N], world frame, applied at the frame's origin.
        torque: torque [N m], world frame, applied to the frame's link.
    """

    name: str
    frame: int
    force: np.ndarray
    torque: np.ndarray


@dataclass(frozen=True)
class Reaction:
    """The wrench one link exerts on another at a joint or a loop cut, world frame.

    Attributes:
        joint: the joint (or `<constraint>`) name.
        kind: its type ("revolute", "continuous", "prismatic", "spherical", "fixed", ...).
        by, on: the link that exerts the wrench, the link it acts on.
        point: where it acts [m]: the joint's origin; for a cut, the origin of its cut
            frame on `on` (a slide's two cut frames part along its axis).
        force: F_by,on [N].
        moment: moment about `point` [N m].
        axis: the joint's axis, world frame (zero for joints without one).
        is_cut: True for a loop cut (a `<constraint>`), False for a tree joint.
    """

    joint: str
    kind: str
    by: str
    on: str
    point: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    axis: np.ndarray
    is_cut: bool

    @property
    def magnitude(self) -> float:
        """|F| [N]."""
        return float(np.linalg.norm(self.force))

    @property
    def axial_force(self) -> float:
        """Component of the force along the axis [N] (a slider's driving force, else carried by the pin)."""
        return float(self.force @ self.axis)

    @property
    def normal_force(self) -> np.ndarray:
        """The force across the axis [N]: a slider's normal force."""
        return self.force - self.axial_force * self.axis

    @property
    def axial_moment(self) -> float:
        """Moment about the axis [N m]: a pin's driving torque (zero on a free pin)."""
        return float(self.moment @ self.axis)

    def angle(self, plane_normal: np.ndarray | None) -> float | None:
        """Direction of the force in the mechanism's plane [rad], from the world x axis
        (None for a spatial mechanism or a zero force)."""
        if plane_normal is None or self.magnitude == 0.0:
            return None
        ref = np.array([1.0, 0.0, 0.0]) if abs(plane_normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        ref = ref - plane_normal * (plane_normal @ ref)
        ref /= np.linalg.norm(ref)
        return math.atan2(float(plane_normal @ np.cross(ref, self.force)), float(ref @ self.force))


@dataclass(frozen=True)
class PowerBalance:
    """sum tau q_dot + P_gravity + P_loads = dT/dt, each term [W], along one velocity field.

    Attributes:
        velocity: "actual" (the pose's own q_dot) or "virtual" (at rest: a kinematically
            admissible motion with every driver at unit rate, where dT/dt is the virtual
            power of the inertial forces, zero in statics).
        kinetic_rate: dT/dt, or the virtual power of the inertial wrenches.
    """

    driver_power: float
    gravity_power: float
    load_power: float
    kinetic_rate: float
    velocity: str

    @property
    def residual(self) -> float:
        """|driver + gravity + loads - kinetic| over the largest of the four terms (0 when all are 0)."""
        terms = (self.driver_power, self.gravity_power, self.load_power, self.kinetic_rate)
        scale = max(abs(t) for t in terms)
        miss = abs(self.driver_power + self.gravity_power + self.load_power - self.kinetic_rate)
        return miss / scale if scale > 0 else 0.0


@dataclass(frozen=True)
class ForceSolution:
    """Driver efforts, reactions and their checks at one pose (SI, world frame).

    Attributes:
        drivers: the driven joints.
        effort: per driver, the torque [N m] (revolute) or force [N] (prismatic) it must give.
        reactions: joint or cut name -> Reaction, tree joints first, then the cuts.
        cut_multipliers: lambda, per independent cut row (dimensionless rows: [N m] for
            position rows, which are divided by the mechanism's size).
        power: the power balance (virtual power check).
        gravity: the gravity acceleration used [m/s^2], world frame.
        condition: condition number of the dimensionless force equations.
        equation_residual: largest |rnea(q, v, a, loads + cut wrenches) - S^T tau| over the
            largest generalized force, dimensionless.
        method: "exact" or "minimum_norm" (asked for: redundant loops).
    """

    drivers: tuple[str, ...]
    effort: np.ndarray
    reactions: dict[str, Reaction]
    cut_multipliers: np.ndarray
    power: PowerBalance
    gravity: np.ndarray
    condition: float
    equation_residual: float
    method: str = "exact"

    def is_balanced(self, tol: float = 1e-9) -> bool:
        """True when both the equations and the power balance hold to `tol` (relative)."""
        return self.equation_residual <= tol and self.power.residual <= tol


def mechanical_advantage(solution: ForceSolution, loads: Sequence[Load]) -> float | None:
    """Output load over input effort for one driver and one load: |F| / |tau| for a force
    load ([1/m] on a turning driver, [1] on a slider), |T_load| / |tau| for a torque load
    ([1] on a turning driver, [m] on a slider); inf at a toggle (zero effort), None when it
    does not apply. Meaningful in statics, where it is the inverse velocity ratio."""
    if len(solution.drivers) != 1 or len(loads) != 1:
        return None
    load = loads[0]
    has_force, has_torque = bool(np.any(load.force != 0)), bool(np.any(load.torque != 0))
    if has_force == has_torque:
        return None
    size = float(np.linalg.norm(load.force if has_force else load.torque))
    effort = abs(float(solution.effort[0]))
    return size / effort if effort > 0 else math.inf


def advantage_unit(driver_angular: bool, load: Load) -> str:
    """The unit of `mechanical_advantage`: 1/m, 1 or m."""
    force = bool(np.any(load.force != 0))
    if force == driver_angular:
        return "1/m" if force else "m"
    return "1"
