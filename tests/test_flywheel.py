"""Energy fluctuation and flywheel sizing (pinmech/solve/flywheel.py) against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from pinmech.solve.flywheel import energy_fluctuation
from tests.tolerance import rounding


def test_a_sine_torque_curve_stores_twice_its_amplitude():
    """T = T0 + T1 sin(theta) over a turn: mean T0; the integral of T1 sin is T1 (1 - cos),
    from 0 (theta = 0, fastest) to 2 T1 (theta = pi, slowest). Trapezoid over 3601 points:
    error ~ h^2 / 12 * T1 ~ 2e-7 T1; tolerance 1e-6 of T1."""
    T0, T1 = 3.0, 40.0
    theta = np.linspace(0.0, 2 * np.pi, 3601)
    e = energy_fluctuation(theta, T0 + T1 * np.sin(theta))
    assert e.mean_torque == pytest.approx(T0, abs=1e-6 * T1)
    assert e.energy_fluctuation == pytest.approx(2 * T1, abs=1e-6 * T1)
    assert e.slowest_angle == pytest.approx(np.pi, abs=2e-3)
    assert e.fastest_angle == pytest.approx(0.0, abs=2e-3)
    inertia, speed = 0.02, 100.0
    assert e.speed_fluctuation(inertia, speed) == pytest.approx(2 * T1 / (inertia * speed**2), rel=1e-6)
    assert e.flywheel_inertia(e.speed_fluctuation(inertia, speed), speed) == pytest.approx(inertia, rel=rounding(1.0))


def test_a_constant_torque_needs_no_flywheel():
    theta = np.linspace(1.0, 7.0, 50)
    e = energy_fluctuation(theta, np.full(50, 2.5))
    assert e.mean_torque == pytest.approx(2.5, rel=rounding(1.0))
    assert e.energy_fluctuation == pytest.approx(0.0, abs=rounding(2.5 * 6.0))


def test_a_range_without_length_is_refused():
    with pytest.raises(ValueError, match="range of angles"):
        energy_fluctuation(np.array([1.0]), np.array([2.0]))
