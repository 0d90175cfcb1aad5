"""Changes a designer makes on the page, as new linkage specs: a joint dragged to a point,
a `[params]` value set. The drawing's constraints stay what the file wrote: a compass
joint stays a compass (its two lengths and its side follow the point), a polar joint stays
polar (its length and angle follow), a coordinate written as a parameter's name moves the
parameter. Every new spec is validated again by the linkage reader (`linkage_spec`).
"""

from __future__ import annotations

import math

import msgspec
import numpy as np

from pinmech.exceptions import ModelError
from pinmech.model.linkage_entries import Compass, Polar
from pinmech.model.linkage_spec import LinkageSpec, linkage_spec

#: Dragged places are written to this many decimals of a millimetre (1e-6 m): a saved file
#: reads as drawn by hand, and the page solves exactly what it saves.
DECIMALS = 3


def millimetres(value_m: float) -> str:
    """A length [m] as the file's text, e.g. "87.345 mm" (DECIMALS decimals, zeros dropped)."""
    text = f"{value_m * 1e3:.{DECIMALS}f}".rstrip("0").rstrip(".")
    return f"{'0' if text in ('-0', '') else text} mm"


def degrees(value_rad: float) -> str:
    """An angle [rad] as the file's text, e.g. "30.25 deg" (1e-6 deg)."""
    text = f"{math.degrees(value_rad):.6f}".rstrip("0").rstrip(".")
    return f"{'0' if text in ('-0', '') else text} deg"


def move_joint(spec: LinkageSpec, name: str, to: np.ndarray, points: dict[str, np.ndarray],
               source: str = "<linkage>") -> LinkageSpec:
    """The spec with joint `name` drawn at `to` [m] (x, y), its construction kept.

    Args:
        spec: the linkage.
        name: a joint of `spec.joints`.
        to: where it is dragged [m], world frame.
        points: every joint's place at the drawn pose [m] (the bases of a construction).
        source: the file, for messages.

    Raises:
        ModelError: an unknown joint, a spatial joint, a dragged point on top of a base.
    """
    if name not in spec.joints:
        raise ModelError(f"'{name}' is not a joint of the drawing", path=source, element="[joints]")
    entry, to = spec.joints[name], np.asarray(to, dtype=float)[:2]
    if isinstance(entry, Polar):
        offset = to - points[entry.base][:2]
        new = msgspec.structs.replace(entry, length=millimetres(float(np.hypot(*offset))),
                                      angle=degrees(math.atan2(offset[1], offset[0])))
        return with_joint(spec, name, new, source)
    if isinstance(entry, Compass):
        return with_joint(spec, name, compass_to(entry, to, points, name, source), source)
    if len(entry) != 2:
        raise ModelError("a spatial joint cannot be dragged on the page (planar linkages only)", path=source,
                         element=f"[joints] {name}")
    params = dict(spec.params)
    written = []
    for value, coordinate in zip(entry, to):
        if isinstance(value, str) and value.strip() in params:  # the coordinate is a parameter: move it
            params[value.strip()] = millimetres(float(coordinate))
            written.append(value)
        else:
            written.append(millimetres(float(coordinate)))
    raw = msgspec.to_builtins(spec)
    raw["params"], raw["joints"] = params, {**raw["joints"], name: written}
    return linkage_spec(raw, source)


def compass_to(entry: Compass, to: np.ndarray, points: dict[str, np.ndarray], name: str, source: str) -> Compass:
    """The compass construction that draws its joint at `to`: both lengths and the side."""
    a, b = (points[base][:2] for base in entry.bases)
    r1, r2 = float(np.hypot(*(to - a))), float(np.hypot(*(to - b)))
    cross = (b[0] - a[0]) * (to[1] - a[1]) - (b[1] - a[1]) * (to[0] - a[0])
    if r1 == 0.0 or r2 == 0.0:
        raise ModelError(f"dragged onto its base {entry.bases[0] if r1 == 0.0 else entry.bases[1]}", path=source,
                         element=f"[joints] {name}")
    side = entry.side if cross == 0.0 else ("left" if cross > 0 else "right")
    return msgspec.structs.replace(entry, lengths=(millimetres(r1), millimetres(r2)), side=side)


def with_joint(spec: LinkageSpec, name: str, entry: Polar | Compass, source: str) -> LinkageSpec:
    """The spec with joint `name` built by `entry`; a length or angle the file wrote as a
    parameter used by this joint only stays the parameter's name, the parameter set to the
    new value (a parameter shared with other joints is not moved: the number is written)."""
    raw = msgspec.to_builtins(spec)
    old, new = raw["joints"][name], msgspec.to_builtins(entry)
    once = {p for p in raw["params"] if _uses(raw["joints"], p) == 1}
    for key, value in new.items():
        before = old.get(key)
        if isinstance(value, (list, tuple)) and isinstance(before, (list, tuple)):
            new[key] = [_kept(b, v, once, raw["params"]) for b, v in zip(before, value)]
        else:
            new[key] = _kept(before, value, once, raw["params"])
    raw["joints"][name] = new
    return linkage_spec(raw, source)


def _kept(before, value, once: set[str], params: dict):
    """`before` (a parameter's name, the parameter set to `value`) or `value`."""
    if isinstance(before, str) and before.strip() in once and before != value:
        params[before.strip()] = value
        return before
    return value


def _uses(joints: dict, param: str) -> int:
    """How many times the joints' entries name `param`."""
    def count(value) -> int:
        if isinstance(value, str):
            return int(value.strip() == param)
        if isinstance(value, (list, tuple)):
            return sum(count(v) for v in value)
        if isinstance(value, dict):
            return sum(count(v) for v in value.values())
        return 0

    return sum(count(v) for v in joints.values())


def set_param(spec: LinkageSpec, name: str, value_m: float, source: str = "<linkage>") -> LinkageSpec:
    """The spec with parameter `name` set to a length [m] (written in mm, DECIMALS decimals).

    Raises:
        ModelError: a name that is not one of `[params]`, a value that is not a finite number.
    """
    if name not in spec.params:
        raise ModelError(f"'{name}' is not a parameter (params: {', '.join(spec.params) or 'none'})",
                         path=source, element="[params]")
    if not math.isfinite(value_m):
        raise ModelError(f"must be a finite length, got {value_m!r}", path=source, element=f"[params] {name}")
    raw = msgspec.to_builtins(spec)
    raw["params"] = {**raw["params"], name: millimetres(value_m)}
    return linkage_spec(raw, source)
