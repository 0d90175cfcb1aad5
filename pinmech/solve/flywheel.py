"""Energy fluctuation over a cycle and flywheel sizing (Norton, Design of Machinery, 11.11).

A motor giving the mean torque T_m drives a mechanism that needs T(theta). Between two
crank angles the flywheel takes up E(theta) = integral of (T_m - T) dtheta; the energy
fluctuation is Delta E = max E - min E, and with a flywheel of inertia I at mean speed
omega the coefficient of speed fluctuation is C_s = (omega_max - omega_min) / omega
= Delta E / (I omega^2) (the mechanism's own varying inertia neglected: the flywheel
dominates).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class EnergyFluctuation:
    """The torque curve's mean and the energy the flywheel must store.

    Attributes:
        mean_torque: T_m over the range [N m].
        energy_fluctuation: Delta E = max - min of the integral of (T - T_m) dtheta [J].
        slowest_angle, fastest_angle: where the integral of (T - T_m) peaks (the flywheel
            has given the most: slowest) and bottoms (fastest) [rad].
        span: the range of crank angle integrated over [rad].
    """

    mean_torque: float
    energy_fluctuation: float
    slowest_angle: float
    fastest_angle: float
    span: float

    def speed_fluctuation(self, inertia: float, speed: float) -> float:
        """C_s = Delta E / (I omega^2) for a flywheel of `inertia` [kg m^2] at `speed` [rad/s]."""
        return self.energy_fluctuation / (inertia * speed**2)

    def flywheel_inertia(self, coefficient: float, speed: float) -> float:
        """The inertia [kg m^2] that keeps the speed fluctuation to `coefficient` at `speed` [rad/s]."""
        return self.energy_fluctuation / (coefficient * speed**2)


def energy_curve(angles: np.ndarray, torques: np.ndarray) -> tuple[float, np.ndarray]:
    """The mean torque T_m [N m] and E(theta) = integral from the first angle of (T - T_m) dtheta [J]
    at each angle (trapezoids; 0 at both ends of the range): the energy the flywheel gives up.

    Raises:
        ValueError: fewer than two samples, or a zero span.
    """
    angles, torques = np.asarray(angles, float), np.asarray(torques, float)
    if angles.size < 2 or angles[-1] == angles[0]:
        raise ValueError("the energy fluctuation needs a torque curve over a range of angles")
    work = np.concatenate(([0.0], np.cumsum(0.5 * (torques[1:] + torques[:-1]) * np.diff(angles))))
    mean = float(work[-1] / (angles[-1] - angles[0]))
    return mean, work - mean * (angles - angles[0])


def energy_fluctuation(angles: np.ndarray, torques: np.ndarray) -> EnergyFluctuation:
    """Trapezoidal integral of a torque curve [N m] over crank angles [rad] (increasing or not).

    Raises:
        ValueError: fewer than two samples, or a zero span.
    """
    angles = np.asarray(angles, float)
    mean, energy = energy_curve(angles, torques)
    span = float(angles[-1] - angles[0])
    return EnergyFluctuation(mean, float(energy.max() - energy.min()), float(angles[int(np.argmax(energy))]),
                             float(angles[int(np.argmin(energy))]), span)
