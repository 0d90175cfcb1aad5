"""A scene's `[sweep]` table, typed and validated once (what `pinmech sweep`, `path` and
`animate` read when no flag overrides it):

    [sweep]
    links = ["link3"]         # what --plot draws (default: every moving link ...)
    points = ["D"]            # ... and every moving point)
    steps = 361               # poses, both ends included (at least 2)
    from = "0 deg"            # first value (default: the scene's)
    to = "360 deg"            # last value (default: one turn on, or one mechanism size)
    start = "predictor"       # or "warm", "cold" (see solve/cycle.py)
    batch = true              # batched poses between exact ones on dense sweeps
    interpolate = 1           # > 1: every n-th pose solved, the others interpolated
    duration = "0.08 s"       # a task scene followed in time: how long,
    step = "1 ms"             # its time step,
    scheme = "taylor"         # its integration scheme (euler, taylor, rk4)
    gain = 0                  # and its feedback on the drift [1/s]
    targets = {P = [["20 mm", "20 mm"], ["20 mm", "25 mm"]]}   # places drawn on P's path
                              # (a synthesis writes its task's targets here), world x, y
"""

from __future__ import annotations

import math
from typing import Any

import msgspec

from pinmech.io.scene_fields import Refused, Table, names, positive_quantity, quantity, written_value
from pinmech.typed_values import given_fields

#: The `[sweep]` keys and their types.
SWEEP_KEYS = {"links": list, "points": list, "steps": int, "from": str, "to": str, "start": str,
              "batch": bool, "interpolate": int, "duration": str, "step": str, "scheme": str, "gain": (int, float),
              "targets": dict}
#: The most target places a scene may draw (a synthesis has a few dozen at most).
MAX_TARGETS = 10_000
#: The `[sweep]` numbers' ranges: the least value, and what it counts.
_LEAST = {"steps": (2, "poses, both ends included"), "interpolate": (1, "(1: every pose solved)")}


class SweepSpec(Table):
    """`[sweep]`: each key None where the scene does not give it (the command's default then).

    Driver values (`from`, `to`) stay as written: their unit is the swept joint's."""

    links: list[str] | None = None
    points: list[str] | None = None
    steps: int | None = None
    first: str | None = msgspec.field(default=None, name="from")
    last: str | None = msgspec.field(default=None, name="to")
    start: str | None = None
    batch: bool | None = None
    interpolate: int | None = None
    duration: str | None = None
    step: str | None = None
    scheme: str | None = None
    gain: float | None = None
    targets: dict[str, list[tuple[float, float]]] | None = None  # point -> places (x, y) [m]

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            raise Refused(f"[sweep] must be a table, got {data!r}")
        for key, value in data.items():
            kind = SWEEP_KEYS.get(key)
            if kind is None:
                raise Refused(f"unknown key {key}; known: {', '.join(SWEEP_KEYS)}", at=(key,))
            if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
                raise Refused(f"must be {getattr(kind, '__name__', 'a number')}, got {value!r}", at=(key,))
            if key in _LEAST and value < _LEAST[key][0]:
                raise Refused(f"must be at least {_LEAST[key][0]} {_LEAST[key][1]}, got {value}", at=(key,))
        return {k: (float(v) if k == "gain" else v) for k, v in data.items()}

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        """Each value's type is checked already (`_known_keys`): here, what it may be."""
        if name in ("links", "points"):
            return names(value)
        if name in ("start", "scheme"):
            return cls._one_of(name, value)
        if name == "gain" and not 0 <= value < math.inf:
            raise Refused(f"must be a number from 0 (open loop) up, in 1/s, got {value!r}")
        if name in ("first", "last"):
            return written_value(value)
        if name in ("duration", "step"):
            positive_quantity(value, "time", "a positive time")
        if name == "targets":
            return _targets(value)
        return value

    @staticmethod
    def _one_of(name: str, value: str) -> str:
        from pinmech.solve.cycle import STARTS
        from pinmech.solve.path import SCHEMES  # here: sweeping needs no path integration

        choices = STARTS if name == "start" else SCHEMES
        if value not in choices:
            raise Refused(f"must be one of {', '.join(choices)}, got {value!r}")
        return value

    def given(self) -> dict[str, Any]:
        """The keys the scene gives, by their names in the file ("from", "steps", ...)."""
        return given_fields(self)


def _targets(value: dict) -> dict[str, list[tuple[float, float]]]:
    """`targets = {P = [["x", "y"], ...]}`: each point's places, lengths, in SI."""
    out, count = {}, 0
    for point, places in value.items():
        if not isinstance(places, list) or not all(isinstance(p, list) and len(p) == 2 for p in places):
            raise Refused(f"must be a list of [x, y] places such as [\"20 mm\", \"45 mm\"], got {places!r}",
                          at=(point,))
        count += len(places)
        if count > MAX_TARGETS:
            raise Refused(f"more than {MAX_TARGETS} target places", at=(point,))
        out[point] = [tuple(quantity(c, "length", at=(point, k)).si for c in p)
                      for k, p in enumerate(places)]
    return out
