"""The pieces every scene table is built from: a strict pydantic table that names its
unknown keys, quantities checked through `pinmech.units`, and `Refused`, the one way a
validator says no (`scene_errors.py` turns it into a SceneError naming the file and key).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, NamedTuple

from pydantic import BaseModel, ConfigDict, model_validator

from pinmech.exceptions import SceneError, UnitError
from pinmech.units import JOINT_KINDS, to_si


class Refused(ValueError):
    """A scene value refused by a validator: the message, the error class to raise, and
    where below the validated value the mistake is (`at`, appended to its key path)."""

    def __init__(self, message: str, *, at: tuple[str | int, ...] = (), error: type[SceneError] = SceneError,
                 key: str | None = None) -> None:
        super().__init__(message)
        self.message, self.at, self.error, self.key = message, at, error, key


class Quantity(NamedTuple):
    """A quantity as the user wrote it ("30 deg", 0) and its value in SI."""

    written: Any
    si: float


def quantity(value: Any, kind: str, *, at: tuple[str | int, ...] = ()) -> Quantity:
    """`value` read as a quantity of `kind` (units.py); a UnitError becomes a Refused."""
    try:
        return Quantity(value, to_si(value, kind))
    except SceneError as exc:
        raise Refused(str(exc), at=at, error=type(exc)) from None


def positive_quantity(value: Any, kind: str, what: str) -> Quantity:
    """A quantity of `kind` above zero (`what`: "a positive time" for the message)."""
    q = quantity(value, kind)
    if not q.si > 0:
        raise Refused(f"must be {what}, got {value!r}")
    return q


def written_value(value: Any, order: int = 0) -> Any:
    """A joint's coordinate (order 0), rate (1) or acceleration (2) as written: a quantity
    of a revolute or of a prismatic joint's kind (which one, the model decides: it is
    converted once the joint is known, `Scene.joint_quantity`)."""
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise Refused(f"must be a quantity such as \"30 deg\" or \"12 mm\", got {value!r}", error=UnitError)
    if isinstance(value, float) and not math.isfinite(value):
        raise Refused(f"{value!r} is not a finite number", error=UnitError)
    revolute, prismatic = (JOINT_KINDS[kind][order] for kind in ("revolute", "prismatic"))
    try:
        to_si(value, revolute)
    except SceneError as exc:
        try:
            to_si(value, prismatic)
        except SceneError:
            said = prismatic.replace("_", " ")
            raise Refused(f"{exc}; nor is it a {said}, as a prismatic joint's would be", error=type(exc)) from None
    return value


def names(value: Any) -> list[str] | None:
    """A list of names (["D", "E"]), or None when absent."""
    if value is None:
        return None
    if not isinstance(value, list) or not all(isinstance(n, str) for n in value):
        raise Refused(f"must be a list of names, e.g. [\"D\"], got {value!r}")
    return value


def positive_number(value: Any, key: str, low: float, high: float) -> float:
    """A number in [low, high], refused with the key in the message (`solver.tol = ...`)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise Refused(f"{key} must be a positive number, got {value!r}")
    if not low <= value <= high:
        raise Refused(f"{key} = {value!r} is outside [{low:g}, {high:g}]")
    return float(value)


def table_of(value: Any, what: str) -> dict[str, Any]:
    """`value` if it is a TOML table, else a Refused saying `[what] must be a table`."""
    if not isinstance(value, dict):
        raise Refused(f"[{what}] must be a table, got {value!r}")
    return value


class Table(BaseModel):
    """A scene table: strict types, frozen, every key it does not know refused by name.

    Subclasses set `unknown_hint` for their own wording of the known keys."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, populate_by_name=True,
                              arbitrary_types_allowed=True)
    unknown_hint: ClassVar[str | None] = None

    @model_validator(mode="before")
    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            raise Refused(f"must be a table, got {data!r}")
        known = [f.alias or name for name, f in cls.model_fields.items()]
        unknown = sorted(set(data) - set(known))
        if unknown:
            hint = cls.unknown_hint or f"known: {', '.join(known)}"
            raise Refused(f"unknown key(s) {', '.join(unknown)}; {hint}")
        return data
