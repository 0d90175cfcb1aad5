"""A hand-value file's tables, typed and validated once where the file is read (check.py
then reads each entry's quantity path, kind and unit against the result):

    scene = "r_rtr.toml"               # relative to the hand file's folder
    source = "Problem I.9"             # optional: where the printed values come from
    [[value]]
    label = "v_D (text)"               # optional
    quantity = "points.D.velocity"     # a path into `pinmech solve --json`
    hand = ["0.386", "-0.282"]         # one to three values, as printed (strings)
    unit = "m/s"
    kind = "velocity"                  # optional; needed for a joint's q, v and a
"""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Any

from pinmech.io.scene_errors import scene_error
from pinmech.io.scene_fields import Invalid, Refused, Table

#: The keys a hand file and each of its [[value]] tables may hold: any other is a typo.
FILE_KEYS = ("scene", "source", "value")
ENTRY_KEYS = ("label", "quantity", "hand", "unit", "kind")


def _refuse_unknown(table: dict[str, Any], known: tuple[str, ...], in_entry: bool) -> None:
    """A key not in `known` (a typo would otherwise check nothing), with the closest known key."""
    for key in table:
        if key not in known:
            close = [f"[[{k}]]" if k == "value" else repr(k) for k in difflib.get_close_matches(key, known, n=1)]
            hint = f" (did you mean {close[0]}?)" if close else ""
            holds = "a [[value]] holds " + ", ".join(known) if in_entry else "a hand file holds scene, source and [[value]]"
            raise Refused(f"unknown key {key!r}{hint}: {holds}", at=(key,))


class HandEntry(Table, kw_only=True):
    """One `[[value]]`: where the number lives in the result, and the values as printed."""

    label: str | None = None
    quantity: str
    hand: tuple[str, ...]
    unit: str
    kind: str | None = None

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        _refuse_unknown(data, ENTRY_KEYS, True)
        for key in ("quantity", "hand", "unit"):
            if key not in data:
                raise Refused(f"missing {key}")
        for key in ("label", "quantity", "unit", "kind"):
            if key in data and not isinstance(data[key], str):
                raise Refused(f"must be a string, got {data[key]!r}", at=(key,))
        hand = data["hand"] if isinstance(data["hand"], list) else [data["hand"]]
        if not 1 <= len(hand) <= 3:
            raise Refused(f"hand = {hand!r}: give one to three printed values")
        for printed in hand:
            if not isinstance(printed, str):
                raise Refused(f"hand value {printed!r} must be a string as printed (e.g. \"0.386\")")
        return dict(data, hand=tuple(hand))


class HandTables(Table, kw_only=True):
    """A hand file: its scene (as written, relative to the file), source and entries."""

    scene: str
    source: str = ""
    value: tuple[HandEntry, ...]

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if not isinstance(data.get("scene"), str):
            raise Refused("missing scene = \"scene.toml\"", at=("scene",))
        _refuse_unknown(data, FILE_KEYS, False)
        if "source" in data and not isinstance(data["source"], str):
            raise Refused(f"must be a string, got {data['source']!r}", at=("source",))
        entries = data.get("value", [])
        if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
            raise Refused("values must be tables: [[value]] with quantity, hand and unit", at=("value",))
        if not entries:
            raise Refused("no [[value]] to check: a hand file lists at least one (quantity, hand, unit); "
                          "an empty check would pass", at=("value",))
        return dict(data, value=tuple(entries))

    @classmethod
    def read(cls, tables: dict[str, Any], path: Path) -> HandTables:
        """The hand file's TOML tables, validated.

        Raises:
            SceneError: the first mistake, naming the file and the key.
        """
        try:
            return cls.validate(tables)
        except Invalid as exc:
            raise scene_error(exc, path) from None
