"""The entries of a drawn-linkage file, typed (pydantic v2): constructions, sliders, slots and
masses as written, and pydantic's errors said as one line naming the file and the key.
`pinmech.model.linkage_spec.LinkageSpec` holds them."""

from __future__ import annotations

from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Discriminator, Field, StrictFloat, StrictInt, StrictStr, Tag
from pydantic import ValidationError

from pinmech.exceptions import ModelError

#: A quantity as the file writes it: "40 mm", "crank", "2*a + b", "30 deg", or a number.
Written = StrictStr | StrictInt | StrictFloat
#: the file's tables (the other keys: title, ground, balls)
TABLES = ("params", "joints", "links", "sliders", "slots", "colors", "axes", "masses")


class _Entry(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


class Polar(_Entry):
    """`{from = "O", length = "m", angle = "30 deg"}`: at `length` from a joint, `angle` from x."""

    base: StrictStr = Field(alias="from")
    length: Written
    angle: Written


class Compass(_Entry):
    """`{from = ["A", "B"], lengths = [|A..|, |B..|], side = "left"}`: left or right of A -> B."""

    bases: tuple[StrictStr, StrictStr] = Field(alias="from")
    lengths: tuple[Written, Written]
    side: Literal["left", "right"]


class Slider(_Entry):
    """`{block = LINK, on = LINK, at = JOINT, along = ANGLE or [P, Q]}`: a prismatic pair."""

    block: StrictStr | None = None
    on: StrictStr | None = None
    at: StrictStr | None = None
    along: Written | tuple[StrictStr, ...] | None = None


class Slot(_Entry):
    """`{pin = LINK, slot = LINK, along = ANGLE or [P, Q]}`: the pin of the key's name in a slot."""

    pin: StrictStr | None = None
    slot: StrictStr | None = None
    along: Written | tuple[StrictStr, ...] | None = None


class MassSpec(_Entry):
    """`{mass, at, izz}` (planar) or `{mass, at, inertia = [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]}`."""

    mass: Written | None = None
    at: StrictStr | tuple[Written, ...] | None = None
    izz: Written | None = None
    inertia: tuple[Written, ...] | None = None


Coordinates = tuple[Written, ...]


def _joint_kind(entry: Any) -> str:
    """Which form a `[joints]` entry takes (its shape is checked before: `_joint`)."""
    if isinstance(entry, (Polar, Compass)):
        return type(entry).__name__
    if isinstance(entry, dict):
        return "Polar" if isinstance(entry.get("from"), str) else "Compass"
    return "coordinates"


#: A joint's place at the drawn pose: coordinates as written, or a construction.
Joint = Annotated[Union[Annotated[Coordinates, Tag("coordinates")], Annotated[Polar, Tag("Polar")],
                        Annotated[Compass, Tag("Compass")]], Discriminator(_joint_kind)]


#: pydantic's error types, said as pinmech says them
_SAID = {"string_type": "must be text", "tuple_type": "must be a list", "dict_type": "must be a table",
         "float_type": "must be a number", "float_parsing": "must be a number", "finite_number": "must be finite"}


def as_model_error(exc: ValidationError, source: str) -> ModelError:
    """pydantic's first error as one line: `[table] name`, the key in it, what was wrong."""
    error = exc.errors(include_url=False)[0]
    raw = [str(part) for part in error["loc"]]
    union = any(part in ("str", "int", "float") for part in raw)
    loc = [part for part in raw if part not in ("str", "int", "float", "coordinates", "Polar", "Compass")
           and not part.startswith(("tuple[", "function-"))]
    if loc and loc[0] in TABLES and len(loc) > 1:
        element, inner = f"[{loc[0]}] {loc[1]}", loc[2:]
        if loc[0] == "joints" and len(inner) == 1 and inner[0] in "012":
            inner = ["xyz"[int(inner[0])]]
    else:
        element, inner = (loc[0] if loc else None), loc[1:]
    key = f"{' '.join(inner)}: " if inner else ""
    message = _SAID.get(error["type"], error["msg"])
    if union:
        message = 'must be a quantity as text ("40 mm", "30 deg") or a number'
        if inner and inner[0] == "at":
            message = "the centre of mass is a joint's name or [x, y] (or [x, y, z]) with units"
    got = error.get("input")
    shown = "" if isinstance(got, dict) else f", got {got!r:.60}"
    return ModelError(f"{key}{message}{shown}", path=source, element=element)
