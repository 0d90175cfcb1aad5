"""The pieces every scene table is built from: a strict, frozen msgspec table that names its
unknown keys, quantities checked through `pinmech.units`, and `Refused`, the one way a
validator says no (`scene_errors.py` turns it into a SceneError naming the file and key).
"""

from __future__ import annotations

import functools
import math
import types
from typing import Any, ClassVar, NamedTuple, Union

import msgspec
from msgspec import structs

from pinmech.exceptions import SceneError, UnitError
from pinmech.known_keys import unknown_keys
from pinmech.typed_values import WrongType, typed
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


class Invalid(Exception):
    """A table's first mistake and where it is: `loc` (keys and indices from the file's top),
    with the `Refused` a check raised, or the `WrongType` of a value, or "missing"."""

    def __init__(self, loc: tuple[str | int, ...], refused: Refused | None = None,
                 wrong: WrongType | None = None) -> None:
        super().__init__(loc)
        self.loc, self.refused, self.wrong = loc, refused, wrong


class Table(msgspec.Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """A scene table: strict types, frozen, every key it does not know refused by name.

    Build one from a file's table with `validate`: `_known_keys` checks the raw table,
    `_field` each value given (before its type is checked), `_after` the object built.
    Subclasses set `unknown_hint` for their own wording of the known keys."""

    unknown_hint: ClassVar[str | None] = None

    @classmethod
    def keys(cls) -> list[str]:
        """The table's keys, as the file writes them."""
        return [f.encode_name for f in _fields(cls)]

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            raise Refused(f"must be a table, got {data!r}")
        message = unknown_keys(data, cls.keys(), cls.unknown_hint)
        if message:
            raise Refused(message)
        return data

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        """A value given for field `name`, checked and converted (before its type check)."""
        return value

    def _after(self) -> None:
        """Checks across fields, once every field has its type."""

    @classmethod
    def validate(cls, data: Any, loc: tuple[str | int, ...] = ()) -> Any:
        """The table `data` (as TOML reads it) validated into this class.

        Raises:
            Invalid: the first mistake, with its key path below `loc`.
        """
        try:
            data = cls._known_keys(data)
        except Refused as exc:
            raise Invalid(loc, exc) from None
        values = {}
        for f in _fields(cls):
            here = (*loc, f.encode_name)
            if f.encode_name not in data:
                if f.default is msgspec.NODEFAULT and f.default_factory is msgspec.NODEFAULT:
                    raise Invalid(here)
                continue
            try:
                values[f.name] = _typed(cls._field(f.name, data[f.encode_name]), f.type, here)
            except Refused as exc:
                raise Invalid(here, exc) from None
            except WrongType as exc:
                raise Invalid(exc.loc, wrong=exc) from None
        table = cls(**values)
        try:
            table._after()
        except Refused as exc:
            raise Invalid(loc, exc) from None
        return table


@functools.cache
def _fields(cls: type) -> tuple[structs.FieldInfo, ...]:
    return structs.fields(cls)


def _typed(value: Any, kind: Any, loc: tuple[str | int, ...]) -> Any:
    """`value` of type `kind`: a Table (or a dict or tuple of them, or one or None) validated
    as a table, any other type checked by msgspec."""
    if isinstance(kind, type) and issubclass(kind, Table):
        return kind.validate(value, loc)
    origin, args = getattr(kind, "__origin__", None), getattr(kind, "__args__", ())
    if isinstance(kind, types.UnionType) or origin is Union:
        given = [arm for arm in args if arm is not type(None)]
        if len(given) == 1 and value is not None:  # `X | None`: X, tables in it validated
            return _typed(value, given[0], loc)
    elif origin is dict and _is_table(args[1]) and isinstance(value, dict):
        return {name: args[1].validate(item, (*loc, name)) for name, item in value.items()}
    elif origin is tuple and _is_table(args[0]) and isinstance(value, (list, tuple)):
        return tuple(args[0].validate(item, (*loc, i)) for i, item in enumerate(value))
    return typed(value, kind, loc)


def _is_table(kind: Any) -> bool:
    return isinstance(kind, type) and issubclass(kind, Table)
