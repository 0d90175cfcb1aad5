"""A `LinkageSpec` written as a drawn-linkage TOML file: `linkage_spec(tomllib.loads(
linkage_toml(spec))) == spec` for every valid spec (tests/test_linkage_write.py).

Quantities are written as the spec holds them (the user's text, `"40 mm"`), names quoted
where TOML needs it, tables in the order the spec keeps. A synthesis writes its linkages
with it; `pinmech solve` and `sweep` read them back as any drawn linkage.
"""

from __future__ import annotations

import re

from pinmech.model.linkage_entries import Bearing, Compass, MassSpec, Polar, Slider, Slot
from pinmech.model.linkage_spec import LinkageSpec
from pinmech.typed_values import given_fields

_BARE = re.compile(r"[A-Za-z0-9_-]+")


def linkage_toml(spec: LinkageSpec, header: str = "") -> str:
    """The TOML text of a drawn linkage.

    Args:
        spec: the linkage.
        header: comment lines put first (each written after "# ").
    """
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    if spec.title is not None:
        lines.append(f"title = {_string(spec.title)}")
    for key in ("ground", "balls"):
        if getattr(spec, key):
            lines.append(f"{key} = {_array(getattr(spec, key))}")
    tables = {
        "params": {n: value_toml(v) for n, v in spec.params.items()},
        "joints": {n: joint_toml(j) for n, j in spec.joints.items()},
        "links": {n: _array(names) for n, names in spec.links.items()},
        "sliders": {n: _entry(s) for n, s in spec.sliders.items()},
        "slots": {n: _entry(s) for n, s in spec.slots.items()},
        "axes": {n: _array(axis) for n, axis in spec.axes.items()},
        "masses": {n: _entry(m) for n, m in spec.masses.items()},
        "colors": {n: _string(c) for n, c in spec.colors.items()},
    }
    for table, entries in tables.items():
        if entries:
            lines += ["", f"[{table}]", *(f"{_key(name)} = {text}" for name, text in entries.items())]
    return "\n".join(lines) + "\n"


def joint_toml(joint: tuple | Polar | Compass | Bearing) -> str:
    """A drawn joint's TOML value: an array of coordinates, or an inline table of its construction."""
    if isinstance(joint, (Polar, Compass, Bearing)):
        return _entry(joint)
    return _array(joint)


def _entry(entry: Polar | Compass | Bearing | Slider | Slot | MassSpec) -> str:
    """An inline table of the entry's given fields, by their file names (`from`)."""
    fields = given_fields(entry)
    return "{ " + ", ".join(f"{_key(k)} = {value_toml(v)}" for k, v in fields.items()) + " }"


def value_toml(value: str | int | float | tuple | list) -> str:
    """A TOML value: a basic string, a number, or an array of them."""
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, (tuple, list)):
        return _array(value)
    if isinstance(value, bool):  # never in a valid spec; a TOML boolean if it were
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else str(value)


def _array(values: tuple | list) -> str:
    return "[" + ", ".join(value_toml(v) for v in values) + "]"


def _key(name: str) -> str:
    return name if _BARE.fullmatch(name) else _string(name)


def _string(text: str) -> str:
    """A TOML basic string: quote and backslash escaped, control characters as \\uXXXX."""
    out = []
    for ch in text:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'
