"""Values checked against a type with msgspec (strict: no "3" for 3, no true for 1), the one
place a file's typed objects (scene, hand and linkage files) meet msgspec: a mistake comes
back as `WrongType`, with the key path down to the wrong value, what was expected and what
was given, for the caller to say in its own words.
"""

from __future__ import annotations

import re
from typing import Any

import msgspec
from msgspec import structs

#: The path msgspec appends to its messages: "... - at `$.from[1]`".
_AT = re.compile(r" - at `\$(.*)`$")
_PART = re.compile(r"\.([^.\[]+)|\[(\d+)\]")


class WrongType(ValueError):
    """A value not of its type: `loc` (keys and indices down to it), the type's name as
    msgspec says it, None left out ("str", "str | int | float", "array", "object"), and the
    value given."""

    def __init__(self, loc: tuple[str | int, ...], expected: str, given: Any) -> None:
        super().__init__(f"expected {expected}, got {given!r}")
        self.loc, self.expected, self.given = loc, expected, given


def typed(value: Any, kind: Any, loc: tuple[str | int, ...] = ()) -> Any:
    """`value` as type `kind` (msgspec.convert, strict); a table (`dict[str, T]`) entry by entry,
    so that the key of a wrong entry is in `loc`.

    Raises:
        WrongType: the first value not of its type, and where it is.
    """
    if getattr(kind, "__origin__", None) is dict and isinstance(value, dict):
        entry = kind.__args__[1]
        return {name: typed(item, entry, (*loc, name)) for name, item in value.items()}
    try:
        return msgspec.convert(value, type=kind, strict=True)
    except msgspec.ValidationError as exc:
        text = str(exc)
        match = _AT.search(text)
        inner = _path(match.group(1)) if match else ()
        expected = re.search(r"Expected `([^`]*)`", text)
        said = " | ".join(arm for arm in expected.group(1).split(" | ") if arm != "null") if expected else text
        raise WrongType((*loc, *inner), said, _at(value, inner)) from None


def given_fields(struct: msgspec.Struct) -> dict[str, Any]:
    """The fields of `struct` that are not None, by their names in the file (`from`)."""
    return {f.encode_name: getattr(struct, f.name) for f in structs.fields(struct)
            if getattr(struct, f.name) is not None}


def _path(text: str) -> tuple[str | int, ...]:
    """".from[1]" -> ("from", 1)."""
    return tuple(int(index) if index else key for key, index in _PART.findall(text))


def _at(value: Any, inner: tuple[str | int, ...]) -> Any:
    """The value found by following `inner` into `value` (as far as it goes)."""
    for part in inner:
        try:
            value = value[part]
        except (KeyError, IndexError, TypeError):
            break
    return value
