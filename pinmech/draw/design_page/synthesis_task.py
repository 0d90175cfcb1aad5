"""The synthesis file a page's request asks for: targets clicked (path), poses clicked and
turned (motion) or input-output pairs typed (function), for a four-bar, a slider-crank or
an inverted slider-crank, with the `[bounds]` the designer edited (or the page's defaults,
set from the targets). The file is checked by the one reader of synthesis files
(`pinmech.design.synthesis.file.parse_synthesis`) before a search starts: a mistake is its
named error, one line naming the key.

The default region: both ground pivots within twice the targets' span of their centre, the
crank up to the page's limit, every other length up to three spans (for a function, spans
of the ground or of the crank's limit).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

from pinmech.draw.design_page.edits import degrees, millimetres
from pinmech.exceptions import SceneError

KINDS = ("four-bar", "slider-crank", "inverted-slider-crank")
TASKS = ("path", "motion", "function")
GENERATIONS = 120  # by default, at most, on each assembly: a page's search answers in seconds


class Request:
    """A page's "synthesise" or "bounds" message, checked.

    Attributes:
        kind, task: the topology and the task (KINDS, TASKS).
        places: (N, 2) targets [m] (path, motion); poses' angles: `angles` (N,) [rad].
        pairs: (N, 2) function pairs: crank turn [rad], output turn [rad] or travel [m].
        ground: a four-bar's or inverted slider-crank's ground for a function [m].
        max_crank: the longest crank the default bounds allow [m].
        generations: the search's generations at most (GENERATIONS unless asked).
        bounds: the `[bounds]` table's text as the designer edited it ("" for defaults).
    """

    def __init__(self, message: dict) -> None:
        self.kind, self.task = str(message.get("kind", "four-bar")), str(message.get("task", "path"))
        if self.kind not in KINDS:
            raise SceneError(f"kind must be one of {', '.join(KINDS)}, got {self.kind!r}", path="<page>")
        if self.task not in TASKS:
            raise SceneError(f"task must be one of {', '.join(TASKS)}, got {self.task!r}", path="<page>")
        self.max_crank = float(message.get("max_crank", 0.2))
        if not self.max_crank > 0:
            raise SceneError(f"the crank's limit must be positive, got {self.max_crank} m", path="<page>")
        self.ground = float(message.get("ground", 0.1))
        self.bounds = str(message.get("bounds") or "").strip()
        self.generations = int(message.get("generations", GENERATIONS))
        if not 1 <= self.generations <= 10 * GENERATIONS:
            raise SceneError(f"generations must be from 1 to {10 * GENERATIONS}, got {self.generations}", path="<page>")
        key = "poses" if self.task == "motion" else "targets"
        poses = _rows(message.get(key, []), 3 if self.task == "motion" else 2, key)
        self.places, self.angles = poses[:, :2], poses[:, 2] if self.task == "motion" else None
        self.pairs = _rows(message.get("pairs", []), 2, "pairs")
        if not (np.all(np.isfinite(poses)) and np.all(np.isfinite(self.pairs))):
            raise SceneError("the targets, poses and pairs must be finite numbers", path="<page>")

    @property
    def count(self) -> int:
        return len(self.pairs) if self.task == "function" else len(self.places)


def _rows(value, width: int, key: str) -> np.ndarray:
    """`value` as rows of `width` numbers, (n, width); anything else (a flat list, rows of
    another length, text) a SceneError naming `key`, never reshaped into other rows."""
    try:
        rows = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        rows = None
    if rows is not None and rows.size == 0:
        return np.zeros((0, width))
    if rows is None or rows.ndim != 2 or rows.shape[1] != width:
        shape = "not numbers in rows" if rows is None else f"of shape {rows.shape}"
        raise SceneError(f"{key} must be rows of {width} numbers, got {shape}", path="<page>")
    return rows


def default_bounds(request: Request) -> str:
    """The `[bounds]` table's body the page proposes for `request` (TOML, with units)."""
    span_text = lambda low, high: f'["{millimetres(low)}", "{millimetres(high)}"]'
    if request.task == "function":
        return _function_bounds(request, span_text)
    places = request.places if len(request.places) else np.zeros((1, 2))
    centre = places.mean(axis=0)
    span = max(float(np.ptp(places, axis=0).max()), 0.02)
    box = f'{{ x = {span_text(centre[0] - 2 * span, centre[0] + 2 * span)}, ' \
          f'y = {span_text(centre[1] - 2 * span, centre[1] + 2 * span)} }}'
    crank = span_text(min(span / 10, request.max_crank / 2), request.max_crank)
    length = span_text(span / 5, 3 * span)
    lines = [f"O2 = {box}"]
    if request.kind == "four-bar":
        lines += [f"O4 = {box}", f"crank = {crank}", f"coupler = {length}", f"rocker = {length}"]
    elif request.kind == "slider-crank":
        lines += [f'slide = {{ angle = ["-90 deg", "90 deg"], offset = {span_text(-2 * span, 2 * span)} }}',
                  f"crank = {crank}", f"rod = {length}"]
    else:
        lines += [f"O4 = {box}", f"crank = {crank}", f"offset = {span_text(-span, span)}"]
    lines.append(f"point = {{ along = {span_text(-2 * span, 2 * span)}, across = {span_text(-2 * span, 2 * span)} }}")
    return "\n".join(lines)


def _function_bounds(request: Request, span_text) -> str:
    """A function's bounds: lengths from a fifth to three times the ground (or the crank's limit)."""
    scale = request.ground if request.kind != "slider-crank" else request.max_crank
    length = span_text(scale / 5, 3 * scale)
    if request.kind == "four-bar":
        return "\n".join([f"crank = {length}", f"coupler = {length}", f"rocker = {length}"])
    if request.kind == "slider-crank":
        return "\n".join([f"crank = {span_text(scale / 10, scale)}", f"rod = {length}",
                          f"offset = {span_text(-scale, scale)}"])
    return "\n".join([f"crank = {length}", f"offset = {span_text(-scale, scale)}"])


def synthesis_toml(request: Request) -> str:
    """The synthesis file of `request` (its edited bounds, or the defaults)."""
    lines = ['title = "Designed on the design page"', f'task = "{request.task}"',
             f'topology = "{request.kind}"', "seed = 1", "population = 15", f"generations = {request.generations}",
             "keep = 3"]
    if request.task == "function":
        output = millimetres if request.kind == "slider-crank" else degrees
        if request.kind != "slider-crank":
            lines.append(f'ground = "{millimetres(request.ground)}"')
        lines += ["pairs = ["] + [f'  ["{degrees(a)}", "{output(b)}"],' for a, b in request.pairs] + ["]"]
    elif request.task == "motion":
        lines += ["poses = ["] + [f'  ["{millimetres(x)}", "{millimetres(y)}", "{degrees(t)}"],'
                                  for (x, y), t in zip(request.places, request.angles)] + ["]"]
    else:
        lines += ["targets = ["] + [f'  ["{millimetres(x)}", "{millimetres(y)}"],' for x, y in request.places] + ["]"]
    lines += ["", "[bounds]", request.bounds or default_bounds(request), "", "[constraints]",
              'transmission = "25 deg"']
    if request.task != "function":
        lines.append('direction = "either"')
    return "\n".join(lines) + "\n"


def checked_toml(request: Request, path: Path) -> str:
    """`synthesis_toml(request)`, read by the synthesis reader as if it were `path`.

    Raises:
        SceneError: what the reader refuses (too few targets, bounds missing or inverted, ...),
            naming the key; bounds text that is no TOML, named as such.
    """
    from pinmech.design.synthesis.file import parse_synthesis

    if request.count < 3:
        said = "type at least 3 pairs" if request.task == "function" else f"click at least 3 {_noun(request)}"
        raise SceneError(f"{said} (now {request.count})", path="<page>")
    text = synthesis_toml(request)
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"the bounds are not TOML ({exc})", path="<page>", key="bounds") from exc
    parse_synthesis(raw, path)
    return text


def _noun(request: Request) -> str:
    return "poses" if request.task == "motion" else "targets"


def describe(request: Request) -> str:
    """A short line for the page's progress: what is searched for."""
    what = {"path": "targets", "motion": "poses", "function": "pairs"}[request.task]
    return f"{request.kind} {request.task}, {request.count} {what}"

