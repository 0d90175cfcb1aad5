"""Users' units in, SI out: the only place where "30 deg" or "-50 rpm" becomes a float.

A quantity is one number and one unit ("1.5 mm", "-50 rpm", "10 deg/s^2"), or an angle
in degrees, minutes and seconds ("30° 20' 15\""). The number is read here (a decimal
point, never a comma); the unit is looked up in a small table of the units users write
most, else parsed by pint (imported only then: it costs about 0.4 s). The unit must have
exactly the dimension asked for, radians counted: "1 deg**2" is not an angle and "1 Hz"
is not an angular velocity. Scene files and the CLI call `to_si`; everything inside
pinmech is SI (m, rad, s).
"""

from __future__ import annotations

import functools
import math
import re
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
    "mass": "kilogram",
}

#: For a joint coordinate: the kind of q, v and a for a revolute and a prismatic joint.
JOINT_KINDS: dict[str, tuple[str, str, str]] = {
    "revolute": ("angle", "angular_velocity", "angular_acceleration"),
    "prismatic": ("length", "velocity", "acceleration"),
}

#: Each kind as powers of pint's root units: the exact dimension a unit must have.
_DIMENSIONS: dict[str, dict[str, int]] = {
    "angle": {"radian": 1},
    "angular_velocity": {"radian": 1, "second": -1},
    "angular_acceleration": {"radian": 1, "second": -2},
    "length": {"meter": 1},
    "velocity": {"meter": 1, "second": -1},
    "acceleration": {"meter": 1, "second": -2},
    "time": {"second": 1},
    "force": {"gram": 1, "meter": 1, "second": -2},  # pint's root unit of mass is the gram
    "torque": {"gram": 1, "meter": 2, "second": -2},
    "moment_of_inertia": {"gram": 1, "meter": 2},
    "mass": {"gram": 1},
}

_DEG = math.pi / 180
_REV = 2 * math.pi
#: The units users write most, with their SI factor and kind (checked against pint by the
#: tests), so that a scene is read without importing pint. Anything else goes to pint.
_COMMON_UNITS: dict[str, tuple[float, str]] = {
    **{u: (1.0, "angle") for u in ("rad", "radian", "radians")},
    **{u: (_DEG, "angle") for u in ("deg", "degree", "degrees", "°")},
    **{u: (_REV, "angle") for u in ("rev", "revolution", "revolutions", "turn", "turns")},
    **{u: (1.0, "angular_velocity") for u in ("rad/s", "radian/second")},
    "deg/s": (_DEG, "angular_velocity"),
    "rpm": (_REV / 60, "angular_velocity"),
    "rev/s": (_REV, "angular_velocity"),
    "turn/s": (_REV, "angular_velocity"),
    **{u: (1.0, "angular_acceleration") for u in ("rad/s^2", "rad/s**2")},
    **{u: (_DEG, "angular_acceleration") for u in ("deg/s^2", "deg/s**2")},
    **{u: (1.0, "length") for u in ("m", "meter", "meters", "metre", "metres")},
    "mm": (1e-3, "length"),
    "cm": (1e-2, "length"),
    "km": (1e3, "length"),
    "um": (1e-6, "length"),
    "µm": (1e-6, "length"),
    "m/s": (1.0, "velocity"),
    "mm/s": (1e-3, "velocity"),
    "cm/s": (1e-2, "velocity"),
    **{u: (1.0, "acceleration") for u in ("m/s^2", "m/s**2")},
    **{u: (1e-3, "acceleration") for u in ("mm/s^2", "mm/s**2")},
    **{u: (1.0, "time") for u in ("s", "second", "seconds")},
    "ms": (1e-3, "time"),
    "N": (1.0, "force"),
    "kN": (1e3, "force"),
    "N*m": (1.0, "torque"),
    **{u: (1.0, "moment_of_inertia") for u in ("kg*m^2", "kg*m**2")},
    "kg": (1.0, "mass"),
    "g": (1e-3, "mass"),
}

#: Largest magnitude of a quantity in SI units. Kinematics multiplies speeds and lengths
#: (a = omega^2 r) and squares the results (norms), which must stay below 1.8e308.
MAX_MAGNITUDE = 1e50
#: Smallest magnitude of a non-zero quantity in SI units: below, its squares underflow to
#: zero (1e-50 squared is 1e-100; 1e-300 squared is 0), so a length of "1e-300 mm" would be
#: no length at all to the solver. The range is the one model files are held to (loop_size).
MIN_MAGNITUDE = 1e-50
#: Largest power of a unit written ("m^3", "kg*m^2"): pint would compute "mm**9**9**9"
#: (a number of 369 million digits) before any check; no quantity pinmech reads needs more.
MAX_UNIT_POWER = 4
#: Angles written in another unit than the radian (degrees, turns) convert exactly up to
#: this [rad]: the product's rounding (2.3e-16 of it) stays below 1e-9 rad. Beyond, the
#: pose of "1e15 deg" would be -80.05 deg, not -80: refused, naming the same pose.
MAX_CONVERTED_ANGLE = 4e6

_NUMBER = re.compile(r"([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:infinity|inf|nan)\b)\s*(.*)",
                     re.IGNORECASE | re.DOTALL)
#: Typographic spellings of a unit: s² is s^2, m·s is m*s, μ (Greek mu) is µ (micro sign).
_TYPOGRAPHY = str.maketrans({"²": "^2", "³": "^3", "·": "*", "⋅": "*", "\u03bc": "\u00b5"})
_EXPONENT = re.compile(r"(\^|\*\*)\s*[+-]?\d+")
_DMS = re.compile(
    r"([+-]?)\s*(\d+)\s*(?:°|deg|degrees?)\s*"
    r"(?:(\d+(?:\.\d*)?)\s*(?:'|′|arcmin|arcminutes?)\s*)"
    r"(?:(\d+(?:\.\d*)?)\s*(?:\"|″|''|arcsec|arcseconds?))?",
    re.IGNORECASE,
)


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
        UnitError: unknown unit, wrong dimension, missing unit, a decimal comma, two
            numbers, or not finite.
    """
    if not isinstance(kind, str) or kind not in SI_UNITS:
        raise UnitError(f"unknown kind of quantity {kind!r}; one of {', '.join(SI_UNITS)}", key=where)
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise UnitError(f"expected a quantity such as '1.5 {_example(kind)}', got {value!r}", key=where)
    if isinstance(value, (int, float)):
        if value == 0:
            return 0.0
        raise UnitError(_no_unit(value, kind), key=where)
    number, unit = _split(value, kind, where)
    if not unit:
        if number == 0:
            return 0.0
        raise UnitError(_no_unit(value, kind), key=where)
    result = number * _factor(value, unit, kind, where)
    if not math.isfinite(result):
        raise UnitError(f"{value!r} is not a finite number", key=where)
    if abs(result) > MAX_MAGNITUDE:
        raise UnitError(f"{value!r} is {result:.3g} {format_si(result, kind)}, beyond the {MAX_MAGNITUDE:g} (SI) "
                        "pinmech computes with: its squares would overflow", key=where)
    if 0 < abs(result) < MIN_MAGNITUDE:
        raise UnitError(f"{value!r} is {result:.3g} {format_si(result, kind)}, below the {MIN_MAGNITUDE:g} (SI) "
                        "pinmech computes with: its squares would underflow to 0 (write 0 for none)", key=where)
    factor = result / number if number else 1.0
    if kind == "angle" and factor != 1.0 and abs(result) > MAX_CONVERTED_ANGLE:
        turn = 2 * math.pi / factor  # one turn in the unit written (360 for degrees, 1 for turns)
        off = abs(result) * 2.3e-16
        lost = f"is off by up to {off:.1g} rad" if off < 1 else "is lost"
        raise UnitError(f"{value!r} is {result:.4g} rad: converted to radians in float64 its pose {lost}; write "
                        f"the angle within {MAX_CONVERTED_ANGLE / (2 * math.pi):.0f}"
                        f" turns (the same pose: '{math.remainder(number, turn):.17g} {unit}'), or in radians",
                        key=where)
    return result


def _split(text: str, kind: str, where: str) -> tuple[float, str]:
    """The number and the unit expression of "1.5 mm" (an angle in degrees, minutes and
    seconds becomes degrees); a decimal comma or a second number is refused."""
    stripped = text.strip().replace("\u2212", "-")  # a typographic minus sign is a minus sign
    if "," in stripped:
        hint = re.sub(r"(\d),(\d)", r"\1.\2", stripped)
        said = f"write '{hint}' (a decimal point)" if hint != stripped else "write one number and one unit"
        raise UnitError(f"{text!r} has a comma, which pinmech does not read as a decimal mark: {said}", key=where)
    if kind == "angle" and (dms := _DMS.fullmatch(stripped)):
        return _degrees(text, dms, where), "deg"
    match = _NUMBER.fullmatch(stripped)
    if match is None:
        raise UnitError(f"cannot read quantity {text!r}: expected a number then a unit, e.g. "
                        f"'1.5 {_example(kind)}'", key=where)
    unit = match.group(2).strip().translate(_TYPOGRAPHY)
    unit = re.sub(r"\s*(\*\*|[/*^])\s*", r"\1", unit)
    _refuse_powers(text, unit, where)
    if re.search(r"\b\d", _EXPONENT.sub("", unit)):  # a digit that starts a word; "g0" is a unit's name
        angles = " (an angle may be written 30° 20' 15\")" if kind.startswith(("angle", "angular")) else ""
        raise UnitError(f"{text!r} holds more than one number: write one number and one unit, e.g. "
                        f"'1.5 {_example(kind)}'{angles}", key=where)
    return float(match.group(1)), _ARC_MARKS.get(unit, unit)


#: A power of a power ("mm**9**9", "m^2^3"): pint evaluates it right to left, digit by digit.
_TOWER = re.compile(r"(\^|\*\*)[+-]?\d+(\^|\*\*)")


def _refuse_powers(text: str, unit: str, where: str) -> None:
    """A unit's powers are whole numbers up to MAX_UNIT_POWER, one a factor: checked before
    pint reads the unit (which would compute "mm**9**9**9" for hours)."""
    powers = [abs(int(p)) for p in re.findall(r"(?:\^|\*\*)\s*([+-]?\d+)", unit)]
    if _TOWER.search(unit) or any(p > MAX_UNIT_POWER for p in powers):
        raise UnitError(f"{text!r}: a unit's power is a whole number up to {MAX_UNIT_POWER} (as in 'kg*m^2'), "
                        "one a factor, not a power of a power", key=where)


#: minutes and seconds of arc written with their marks alone ("1.5 '"): pint knows no mark
_ARC_MARKS = {"'": "arcmin", "\u2032": "arcmin", '"': "arcsec", "''": "arcsec", "\u2033": "arcsec"}


def _degrees(text: str, dms: re.Match, where: str) -> float:
    """Degrees of an angle written as degrees, minutes and optional seconds."""
    sign = -1.0 if dms.group(1) == "-" else 1.0
    degrees, minutes = float(dms.group(2)), float(dms.group(3))
    seconds = float(dms.group(4) or 0.0)
    if not (minutes < 60 and seconds < 60) or (dms.group(4) and not minutes.is_integer()):
        raise UnitError(f"{text!r}: minutes and seconds of arc must be below 60, and only the last part may "
                        "have decimals", key=where)
    return sign * (degrees + minutes / 60 + seconds / 3600)


def _factor(text: str, unit: str, kind: str, where: str) -> float:
    """SI value of one `unit`, which must have the dimension of `kind` exactly."""
    if unit in _COMMON_UNITS:
        factor, unit_kind = _COMMON_UNITS[unit]
        if unit_kind != kind:
            raise UnitError(_wrong_kind(text, kind, unit_kind.startswith(("angle", "angular")),
                                        _DIMENSIONS[unit_kind]), key=where)
        return factor
    _refuse_misread(text, unit, kind, where)
    try:
        quantity = _registry().Quantity(1.0, unit)
        root = quantity.to_root_units()
    except Exception as exc:  # pint raises several unrelated classes here
        names = getattr(exc, "unit_names", None)  # pint's UndefinedUnitError
        said = (f"no unit is called {', '.join(map(repr, names))}" if names else f"{type(exc).__name__} {exc}")
        raise UnitError(f"cannot read quantity {text!r}: {said} (write e.g. '1.5 {_example(kind)}')".rstrip(),
                        key=where) from exc
    powers = {name: int(p) if float(p).is_integer() else float(p) for name, p in root.unit_items()}
    if powers != _DIMENSIONS[kind]:
        raise UnitError(_wrong_kind(text, kind, powers.get("radian", 0) != 0, powers), key=where)
    return float(quantity.to(SI_UNITS[kind]).magnitude)  # SI, with kilograms (not pint's root grams)


#: Newton-metres written glued ("Nm", "kNm", "Nmm"): pint reads "Nm" as a "number meter"
#: (dimension m/kg), never what is meant.
_GLUED_TORQUE = re.compile(r"([kmMµu]?)N(m|mm|cm)")
#: Unit names pint reads otherwise than people mean, refused with what pint would read.
_MISREAD = {"a": "a year (annum): write 'year' if a year is meant"}


def _refuse_misread(text: str, unit: str, kind: str, where: str) -> None:
    """A unit name pint would read in another sense than a user means: refused, saying how
    to write what is meant ("0.5 Nm": write '0.5 N*m')."""
    for token in re.split(r"\*\*|[*/^()\s]+", unit):
        glued = _GLUED_TORQUE.fullmatch(token)
        if glued and kind == "torque":
            fixed = text.replace(token, f"{glued.group(1)}N*{glued.group(2)}", 1).strip()
            raise UnitError(f"{text!r}: write '{fixed}' (a torque in newton-metres is written N*m; pint reads "
                            "'Nm' as a count times a metre)", key=where)
        if token in _MISREAD:
            raise UnitError(f"{text!r}: pint reads '{token}' as {_MISREAD[token]}", key=where)


#: SI symbols of pint's root units; a mass is said in kilograms, not pint's grams.
_SI_SYMBOLS = {"meter": "m", "gram": "kg", "second": "s", "radian": "rad", "ampere": "A", "kelvin": "K",
               "mole": "mol", "candela": "cd", "bit": "bit", "count": "count"}


def _dimension_words(powers: dict[str, Any]) -> str:
    """A dimension as people write it: "a force", or its SI units ("m/kg", "rad^2")."""
    for kind, dims in _DIMENSIONS.items():
        if dims == powers:
            return f"it is {_article(kind)} {kind.replace('_', ' ')}"
    up = [f"{_SI_SYMBOLS.get(n, n)}" + (f"^{p}" if p != 1 else "") for n, p in powers.items() if p > 0]
    down = [f"{_SI_SYMBOLS.get(n, n)}" + (f"^{-p}" if p != -1 else "") for n, p in powers.items() if p < 0]
    units = "*".join(up) or "1"
    if down:
        units += "/" + ("*".join(down) if len(down) == 1 else "(" + "*".join(down) + ")")
    return "it is a pure number" if not powers else f"its unit is {units}"


def _wrong_kind(text: str, kind: str, has_angle: bool, powers: dict[str, Any] | None = None) -> str:
    name = kind.replace("_", " ")
    if kind.startswith(("angle", "angular")) and not has_angle:
        return f"{text!r} has no angle unit, so it is not an {name} (use e.g. {_example(kind)})"
    dimension = "" if powers is None else f" ({_dimension_words(powers)})"
    return f"{text!r} is not {_article(kind)} {name}{dimension} (use e.g. {_example(kind)})"


def _no_unit(value: Any, kind: str) -> str:
    number = value if isinstance(value, (int, float)) else _leading_number(value)
    if isinstance(number, int) and abs(number) > 1e308:  # an int beyond float64
        number = math.inf
    if number is not None and not math.isfinite(number):  # "nan rpm" is refused too: say what is wrong
        return f"{value!r} is not a finite number ({kind.replace('_', ' ')})"
    return f"{value!r} has no unit: write it as '{value} {_example(kind)}' ({kind.replace('_', ' ')})"


def _leading_number(text: str) -> float | None:
    try:
        return float(str(text).split()[0])
    except (ValueError, IndexError):
        return None


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
        "mass": "kg",
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
        "mass": "kg",
    }[kind]
