"""Users' units in, SI out: the only place where "30 deg" or "-50 rpm" becomes a float.

Parsing is done by pint (one shared registry, built on first use). Scene files and the
CLI call `to_si`; everything inside pinmech is SI (m, rad, s).
"""

from __future__ import annotations

import functools
import math
from typing import Any

from pinmech.exceptions import UnitError

#: Kinds of quantity a scene may hold, with their SI unit.
SI_UNITS: dict[str, str] = {
    "angle": "radian",
    "angular_velocity": "radian / second",
    "angular_acceleration": "radian / second ** 2",
    "length": "meter",
    "velocity": "meter / second",
    "acceleration": "meter / second ** 2",
    "time": "second",
    "force": "newton",
    "torque": "newton * meter",
    "moment_of_inertia": "kilogram * meter ** 2",
}

#: For a joint coordinate: the kind of q, v and a for a revolute and a prismatic joint.
JOINT_KINDS: dict[str, tuple[str, str, str]] = {
    "revolute": ("angle", "angular_velocity", "angular_acceleration"),
    "prismatic": ("length", "velocity", "acceleration"),
}


#: Largest magnitude of a quantity in SI units. Kinematics multiplies speeds and lengths
#: (a = omega^2 r) and squares the results (norms), which must stay below 1.8e308.
MAX_MAGNITUDE = 1e50


@functools.lru_cache(maxsize=1)
def _registry() -> Any:
    import pint

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    ureg.define("@alias revolution = rev")  # as in "2 rev/s"; pint knows "rpm" and "turn"
    return ureg


def to_si(value: Any, kind: str, *, where: str = "") -> float:
    """Convert a quantity as a user writes it ("30 deg", "-50 rpm", "150 mm") to SI.

    A bare number is accepted only when it is zero: any other number must carry its unit,
    so that "30" is never silently read as 30 rad.

    Args:
        value: a string with a unit, or the number 0.
        kind: one of `SI_UNITS` ("angle", "angular_velocity", ...).
        where: the file and key, for the error message.

    Returns:
        The value in the SI unit of `kind` (rad, rad/s, rad/s^2, m, m/s, m/s^2, s).

    Raises:
        UnitError: unknown unit, wrong dimension, missing unit, or not finite.
    """
    si = SI_UNITS[kind]
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise UnitError(f"expected a quantity such as '1.5 {_example(kind)}', got {value!r}", key=where)
    if isinstance(value, (int, float)):
        if value == 0:
            return 0.0
        raise UnitError(
            f"{value!r} has no unit: write it as '{value} {_example(kind)}' ({kind.replace('_', ' ')})",
            key=where,
        )
    ureg = _registry()
    try:
        quantity = ureg.Quantity(value.strip())
    except Exception as exc:  # pint raises several unrelated classes here
        raise UnitError(f"cannot read quantity {value!r}: {exc}", key=where) from exc
    if not hasattr(quantity, "to"):
        quantity = ureg.Quantity(float(quantity), "dimensionless")
    if quantity.unitless:
        if float(quantity.magnitude) == 0:
            return 0.0
        raise UnitError(
            f"{value!r} has no unit: write it as '{value} {_example(kind)}' ({kind.replace('_', ' ')})",
            key=where,
        )
    # pint treats the radian as dimensionless: "1 Hz" would pass as 1 rad/s. Insist on an
    # angle unit (rad, deg, rev, rpm, ...) in the expression of an angular quantity.
    if kind.startswith(("angle", "angular")) and "radian" not in str(quantity.to_root_units().units):
        raise UnitError(
            f"{value!r} has no angle unit, so it is not an {kind.replace('_', ' ')} (use e.g. {_example(kind)})",
            key=where,
        )
    try:
        number = float(quantity.to(si).magnitude)
    except Exception as exc:
        raise UnitError(
            f"{value!r} is not {_article(kind)} {kind.replace('_', ' ')} (use e.g. {_example(kind)})",
            key=where,
        ) from exc
    if not math.isfinite(number):
        raise UnitError(f"{value!r} is not a finite number", key=where)
    if abs(number) > MAX_MAGNITUDE:
        raise UnitError(f"{value!r} is {number:.3g} {format_si(number, kind)}, beyond the {MAX_MAGNITUDE:g} (SI) "
                        "pinmech computes with: its squares would overflow", key=where)
    return number


def _article(kind: str) -> str:
    return "an" if kind[0] in "aeiou" else "a"


def _example(kind: str) -> str:
    return {
        "angle": "deg",
        "angular_velocity": "rpm",
        "angular_acceleration": "rad/s^2",
        "length": "mm",
        "velocity": "m/s",
        "acceleration": "m/s^2",
        "time": "s",
        "force": "N",
        "torque": "N*m",
        "moment_of_inertia": "kg*m^2",
    }[kind]


def format_si(value: float, kind: str) -> str:
    """The SI unit symbol used in reports for a kind of quantity."""
    return {
        "angle": "rad",
        "angular_velocity": "rad/s",
        "angular_acceleration": "rad/s^2",
        "length": "m",
        "velocity": "m/s",
        "acceleration": "m/s^2",
        "time": "s",
        "force": "N",
        "torque": "N m",
        "moment_of_inertia": "kg m^2",
    }[kind]
