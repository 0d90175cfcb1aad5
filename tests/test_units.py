"""Quantities as users write them become SI; anything ambiguous is refused."""

from __future__ import annotations

import math
import re

import pytest

from pinmech import UnitError, to_si
from tests.tolerance import rounding


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
    assert to_si(text, kind) == pytest.approx(si, rel=rounding(1.0))


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


@pytest.mark.parametrize(
    "text, kind, hint",
    [
        ("1,5 deg", "angle", "'1.5 deg'"),
        ("0,5 rad/s", "angular_velocity", "'0.5 rad/s'"),
        ("2,5 rpm", "angular_velocity", "'2.5 rpm'"),
        ("1,5 mm", "length", "'1.5 mm'"),
        ("1,000 mm", "length", "'1.000 mm'"),  # a thousands separator is as ambiguous
        ("1, 5 mm", "length", "one number and one unit"),
    ],
)
def test_a_decimal_comma_is_refused_with_the_point_suggested(text, kind, hint):
    # pint reads "1,5 deg" as 15 deg; pinmech must never guess which the user meant.
    with pytest.raises(UnitError, match=f"comma.*{hint}"):
        to_si(text, kind, where="--angle")


@pytest.mark.parametrize(
    "text, degrees",
    [
        ("30° 20'", 30 + 20 / 60),
        ("30 deg 20 arcmin", 30 + 20 / 60),
        ("30°20′15″", 30 + 20 / 60 + 15 / 3600),
        ("-30° 20' 30\"", -(30 + 20 / 60 + 30 / 3600)),
        ("12 degrees 7.5 arcminutes", 12 + 7.5 / 60),
    ],
)
def test_an_angle_in_degrees_minutes_and_seconds_is_their_sum(text, degrees):
    # the sum d + m/60 + s/3600 is the definition of sexagesimal notation; pint multiplies them.
    assert to_si(text, "angle") == pytest.approx(math.radians(degrees), rel=rounding(1.0))


@pytest.mark.parametrize(
    "text, kind, message",
    [
        ("30° 75'", "angle", "below 60"),
        ("30° 20.5' 10\"", "angle", "only the last part"),
        ("30 deg 20 arcmin", "angular_velocity", "more than one number"),
        ("1/2 deg", "angle", "more than one number"),
        ("2 3 mm", "length", "more than one number"),
        ("1 mm2", "length", "cannot read quantity '1 mm2': no unit is called 'mm2'"),  # a name, not two numbers
        ("10 deg deg", "angle", r"not an angle \(its unit is rad\^2\)"),
        ("1 deg**2", "angle", "not an angle"),
        ("1 sr", "angle", "not an angle"),  # a solid angle is rad^2
        ("2 m m", "length", "not a length"),  # m^2, not 2 mm
        ("1 m*rad", "length", "not a length"),
        ("1 rad*rad/s", "angular_velocity", "not an angular velocity"),
        ("1 deg", "angular_velocity", "not an angular velocity"),
        ("1 rpm", "angle", "not an angle"),
        ("5 mm", "time", "not a time"),
        ("2*pi rad", "angle", "cannot read quantity"),
        ("deg", "angle", "cannot read quantity"),
    ],
)
def test_quantities_of_the_wrong_exact_dimension_or_shape_are_refused(text, kind, message):
    with pytest.raises(UnitError, match=message):
        to_si(text, kind, where="drivers.A.angle")


@pytest.mark.parametrize(
    "text, kind, si",
    [
        ("90deg", "angle", math.pi / 2),
        ("3.5e2mm", "length", 0.35),
        ("\u22125 mm", "length", -0.005),  # a typographic minus
        ("1 turn/s", "angular_velocity", 2 * math.pi),
        ("1 rad / s", "angular_velocity", 1.0),
        ("36 km/h", "velocity", 10.0),  # not in the common table: pint reads it
        ("1 arcmin", "angle", math.radians(1 / 60)),
        ("1 deg*percent", "angle", math.radians(0.01)),
        # a digit inside a unit's name is no second number (before: "holds more than one number")
        ("1 g0", "acceleration", 9.80665),  # pint's standard gravity, as "1 g_n"
        ("2 g0", "acceleration", 2 * 9.80665),
    ],
)
def test_other_spellings_of_one_number_and_one_unit(text, kind, si):
    assert to_si(text, kind) == pytest.approx(si, rel=rounding(1.0))


def test_the_common_units_table_agrees_with_pint():
    # The table spares importing pint (0.4 s); pint is the independent source of its factors.
    from pinmech.units import _COMMON_UNITS, _DIMENSIONS, _registry

    from pinmech.units import SI_UNITS

    for unit, (factor, kind) in _COMMON_UNITS.items():
        quantity = _registry().Quantity(1.0, unit)
        assert dict(quantity.to_root_units().unit_items()) == _DIMENSIONS[kind], unit
        assert factor == pytest.approx(quantity.to(SI_UNITS[kind]).magnitude, rel=rounding(1.0)), unit


def test_common_units_are_read_without_importing_pint():
    import subprocess
    import sys

    code = ("import sys; from pinmech.units import to_si; "
            "[to_si(t, k) for t, k in (('30 deg', 'angle'), ('-50 rpm', 'angular_velocity'), ('150 mm', 'length'))]; "
            "sys.exit('pint' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


@pytest.mark.parametrize("text, kind, si", [("1 rad/s²", "angular_acceleration", 1.0),
                                            ("2 m·s^-2", "acceleration", 2.0),
                                            ("5 \u03bcm", "length", 5e-6),  # Greek mu, as keyboards type it
                                            ("5 \u00b5m", "length", 5e-6)])  # the micro sign
def test_typographic_spellings_of_units(text, kind, si):
    assert to_si(text, kind) == pytest.approx(si, rel=rounding(1.0))


@pytest.mark.parametrize("text, kind, si", [("2 kN", "force", 2000.0), ("3 lbf", "force", 3 * 4.4482216152605),
                                            ("5 N*cm", "torque", 0.05), ("2 g*cm^2", "moment_of_inertia", 2e-7),
                                            ("1 kg*m^2", "moment_of_inertia", 1.0)])
def test_forces_torques_and_inertias_in_si_with_kilograms(text, kind, si):
    # lbf = 4.4482216152605 N exactly (NIST); pint's root mass unit is the gram, SI's the kilogram.
    assert to_si(text, kind) == pytest.approx(si, rel=rounding(1.0))


@pytest.mark.parametrize("text, kind", [("1 N", "torque"), ("1 N*m", "force"), ("1 kg", "moment_of_inertia")])
def test_forces_torques_and_inertias_of_the_wrong_dimension_are_refused(text, kind):
    with pytest.raises(UnitError, match="is not a"):
        to_si(text, kind)


@pytest.mark.parametrize("text, same", [("1e15 deg", "-80 deg"), ("1e9 turn", "0 turn"), ("-5e8 deg", "40 deg"),
                                        ("-1e40 deg", "-112 deg")])
def test_angles_in_degrees_or_turns_beyond_float64s_pose_are_refused_naming_the_same_pose(text, same):
    """1e15 deg times pi/180 in float64 is -80.05 deg modulo a turn, not -80: beyond 4e6 rad
    (the product's rounding above 1e-9 rad) such an angle is refused, and the message names
    the same pose, reduced exactly in the unit written; radians are the number itself."""
    with pytest.raises(UnitError, match=f"the same pose: '{same}'"):
        to_si(text, "angle")
    assert to_si("1e6 deg", "angle") == pytest.approx(1e6 * math.pi / 180, rel=rounding(1.0))
    assert to_si("1e15 rad", "angle") == 1e15


@pytest.mark.parametrize("text, arcmin", [("1.5 '", 1.5), ("2 \u2032", 2.0), ('30 "', 0.5), ("30 ''", 0.5),
                                          ("45 \u2033", 0.75)])
def test_minutes_and_seconds_of_arc_by_their_marks_alone(text, arcmin):
    """The marks ' and " (and the primes) with no degrees before them: an internal pint
    AssertionError before; now the arc minute (pi/10800 rad) and second (1/60 of it)."""
    assert to_si(text, "angle") == pytest.approx(arcmin * math.pi / 10800, rel=rounding(1.0))


@pytest.mark.parametrize("value", [float("nan"), float("inf"), "nan", "-inf"])
def test_a_bare_non_finite_number_is_called_so_not_told_to_take_a_unit(value):
    """'nan' was told to be written 'nan rpm', which is refused in turn."""
    with pytest.raises(UnitError, match="is not a finite number"):
        to_si(value, "angular_velocity")


@pytest.mark.parametrize("text, kind, written", [("0.5 Nm", "torque", "0.5 N*m"), ("2 kNm", "torque", "2 kN*m"),
                                                 ("3 Nmm", "torque", "3 N*mm"), ("1.5 mNm", "torque", "1.5 mN*m")])
def test_a_newton_metre_glued_as_nm_is_refused_with_the_spelling_that_works(text, kind, written):
    """People write "Nm" for N·m; pint reads it as a "number meter" (dimension m/kg), which
    was reported as "not a torque (its unit is meter^1 gram^-1)". The message now gives the
    spelling pinmech reads, and no root unit of pint's (the gram)."""
    with pytest.raises(UnitError, match=re.escape(f"write '{written}'")) as caught:
        to_si(text, kind, where="load[0].torque")
    assert "gram" not in str(caught.value) and "^1" not in str(caught.value)
    assert to_si(written, kind) > 0  # the advice is itself read


@pytest.mark.parametrize("text, kind", [("2 a", "time"), ("2 rad/a", "angular_velocity"), ("2 a", "length"),
                                        ("3 deg/a", "angular_velocity")])
def test_a_is_refused_as_a_unit_not_read_as_a_year(text, kind):
    """pint reads "a" as a year (annum): "2 rad/a" was taken as 6.3e-8 rad/s in silence, and
    "2 a" as a length was refused in pint's words (second^1)."""
    with pytest.raises(UnitError, match="year") as caught:
        to_si(text, kind)
    assert "second^1" not in str(caught.value)
    assert to_si("1 year", "time") == pytest.approx(365.25 * 86400, rel=rounding(1.0))  # Julian year, pint's "year"


@pytest.mark.parametrize("text, kind, said", [("1 kgf", "torque", "is a force"), ("1 N*m", "force", "is a torque"),
                                              ("1 kg", "moment_of_inertia", "kg"),
                                              ("1 m/kg", "length", "m/kg")])
def test_a_unit_of_another_dimension_is_named_in_si_terms(text, kind, said):
    """The dimension is said as a kind of quantity, or in SI units (kg, not pint's gram)."""
    with pytest.raises(UnitError, match=re.escape(said)) as caught:
        to_si(text, kind)
    assert "gram" not in str(caught.value) and "^1" not in str(caught.value)
