"""The entries of a drawn-linkage file, typed (frozen msgspec Structs): constructions, sliders,
slots and masses as written, and a value of the wrong type said as one line naming the file
and the key.
`pinmech.model.linkage_spec.LinkageSpec` holds them."""

from __future__ import annotations

from typing import Literal, Union

import msgspec

from pinmech.exceptions import ModelError
from pinmech.typed_values import WrongType

#: A quantity as the file writes it: "40 mm", "crank", "2*a + b", "30 deg", or a number.
Written = Union[str, int, float]
#: the file's tables (the other keys: title, ground, balls)
TABLES = ("params", "joints", "links", "sliders", "slots", "colors", "axes", "masses")


class _Entry(msgspec.Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """An entry of a table: strict types, frozen, unknown keys refused."""


class Polar(_Entry):
    """`{from = "O", length = "m", angle = "30 deg"}`: at `length` from a joint, `angle` from x."""

    base: str = msgspec.field(name="from")
    length: Written
    angle: Written


class Compass(_Entry):
    """`{from = ["A", "B"], lengths = [|A..|, |B..|], side = "left"}`: left or right of A -> B."""

    bases: tuple[str, str] = msgspec.field(name="from")
    lengths: tuple[Written, Written]
    side: Literal["left", "right"]


class Bearing(_Entry):
    """`{from = ["A", "B"], length = "p", angle = "gamma"}`: at `length` from A, `angle` from
    the line A -> B (counter-clockwise seen from +z): a coupler point by its distance from
    A and its angle to the coupler's line (Norton's R_PA and delta_3)."""

    bases: tuple[str, str] = msgspec.field(name="from")
    length: Written
    angle: Written


class Slider(_Entry):
    """`{block = LINK, on = LINK, at = JOINT, along = ANGLE or [P, Q]}`: a prismatic pair."""

    block: str | None = None
    on: str | None = None
    at: str | None = None
    along: Written | tuple[str, ...] | None = None


class Slot(_Entry):
    """`{pin = LINK, slot = LINK, along = ANGLE or [P, Q]}`: the pin of the key's name in a slot."""

    pin: str | None = None
    slot: str | None = None
    along: Written | tuple[str, ...] | None = None


class MassSpec(_Entry):
    """`{mass, at, izz}` (planar) or `{mass, at, inertia = [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]}`."""

    mass: Written | None = None
    at: str | tuple[Written, ...] | None = None
    izz: Written | None = None
    inertia: tuple[Written, ...] | None = None


Coordinates = tuple[Written, ...]


#: A joint's place at the drawn pose: coordinates as written, or a construction.
Joint = Union[Coordinates, Polar, Compass, Bearing]
#: The constructions: their type, and the keys each is written with.
CONSTRUCTIONS = {Polar: ("from", "length", "angle"), Compass: ("from", "lengths", "side"),
                 Bearing: ("from", "length", "angle")}


def joint_type(entry: object) -> type:
    """The type a `[joints]` entry takes (its shape is checked before: `linkage_spec._joint`)."""
    if isinstance(entry, (Polar, Compass, Bearing)):
        return type(entry)
    if isinstance(entry, dict):
        if isinstance(entry.get("from"), str):
            return Polar
        return Compass if "lengths" in entry or "side" in entry else Bearing
    return Coordinates


#: msgspec's type names, said as pinmech says them
_SAID = {"str": "must be text", "array": "must be a list", "object": "must be a table", "float": "must be a number",
         "int": "must be a number"}


def as_model_error(exc: WrongType, source: str) -> ModelError:
    """A value of the wrong type as one line: `[table] name`, the key in it, what was wrong."""
    loc = [str(part) for part in exc.loc]
    if loc and loc[0] in TABLES and len(loc) > 1:
        element, inner = f"[{loc[0]}] {loc[1]}", loc[2:]
        if loc[0] == "joints" and len(inner) == 1 and inner[0] in "012":
            inner = ["xyz"[int(inner[0])]]
    else:
        element, inner = (loc[0] if loc else None), loc[1:]
    key = f"{' '.join(inner)}: " if inner else ""
    message = _SAID.get(exc.expected, f"must be {exc.expected}")
    if " | " in exc.expected:  # a quantity's (str | int | float) or a centre of mass's (str | array)
        message = 'must be a quantity as text ("40 mm", "30 deg") or a number'
        if inner and inner[0] == "at":
            message = "the centre of mass is a joint's name or [x, y] (or [x, y, z]) with units"
    got = exc.given
    shown = "" if isinstance(got, dict) else f", got {got!r:.60}"
    return ModelError(f"{key}{message}{shown}", path=source, element=element)
