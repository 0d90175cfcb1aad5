"""Quantities as users write them become SI; anything ambiguous is refused."""

from __future__ import annotations

import math

import pytest

from pinmech import UnitError, to_si


@pytest.mark.parametrize(
    "text, kind, si",
    [
        ("30 deg", "angle", math.pi / 6),
        ("0.5 rad", "angle", 0.5),
        ("-50 rpm", "angular_velocity", -50 * math.pi / 30),
        ("2 rev/s", "angular_velocity", 4 * math.pi),
        ("0 rad/s^2", "angular_acceleration", 0.0),
        ("10 deg/s**2", "angular_acceleration", math.radians(10)),
        ("150 mm", "length", 0.15),
        ("1 km", "length", 1000.0),
        ("1 m/s", "velocity", 1.0),
        ("3 mm/s^2", "acceleration", 0.003),
        ("1e6 rad", "angle", 1e6),
        (0, "angle", 0.0),
    ],
)
def test_users_units_become_si(text, kind, si):
    assert to_si(text, kind) == pytest.approx(si, rel=1e-15)


@pytest.mark.parametrize(
    "text, kind, message",
    [
        ("30", "angle", "has no unit"),
        (30, "angle", "has no unit"),
        ("1 Hz", "angular_velocity", "no angle unit"),  # 1 Hz is not 1 rad/s
        ("3 m", "angle", "no angle unit"),
        ("1 deg", "length", "is not a length"),
        ("3 furlongz", "length", "cannot read quantity"),
        ("nan deg", "angle", "not a finite number"),
        ("inf mm", "length", "not a finite number"),
        ("", "angle", "cannot read quantity"),
        ([1, 2], "angle", "expected a quantity"),
        (True, "angle", "expected a quantity"),
    ],
)
def test_ambiguous_or_wrong_quantities_are_refused(text, kind, message):
    with pytest.raises(UnitError, match=message):
        to_si(text, kind, where="drivers.A.angle")
