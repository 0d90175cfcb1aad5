"""Synthesis files (`models/synthesis/*.toml`): parsed and validated once into a
`SynthesisSpec`. A path-generation task of a four-bar:

    title = "Four-bar through ten points"
    task = "path"                    # the coupler point through the targets, in order
    topology = "four-bar"
    targets = [["120 mm", "35 mm"], ["110 mm", "52 mm"], ...]
    timing = ["0 deg", "30 deg", ...]   # optional: the crank's turn from the first target
    seed = 1                          # the search's random stream (same seed, same linkage)
    population = 20                   # DE population per parameter; generations: at most
    generations = 400
    keep = 3                          # distinct linkages written, best first

    [bounds]                          # every parameter, [lower, upper] with units
    O2 = { x = ["-60 mm", "60 mm"], y = ["-60 mm", "60 mm"] }    # ground-pivot regions
    O4 = { x = ["40 mm", "160 mm"], y = ["-60 mm", "60 mm"] }
    crank = ["10 mm", "80 mm"]
    coupler = ["40 mm", "200 mm"]
    rocker = ["20 mm", "160 mm"]
    point = { along = ["-150 mm", "150 mm"], across = ["-150 mm", "150 mm"] }

    [constraints]
    grashof = "crank-rocker"          # a Grashof class (grashof.py), or "any" (default)
    transmission = "30 deg"           # least transmission angle over the motion
    ratio = 6                         # longest / shortest link at most
    direction = "either"              # the crank's turn: "ccw", "cw" or "either"

A function-generation task (the rocker's turns a function of the crank's):

    task = "function"
    ground = "100 mm"                 # O2 at (0, 0), O4 at (ground, 0)
    pairs = [["0 deg", "0 deg"], ["10.9 deg", "21.2 deg"], ...]   # [crank turn, rocker turn]
    [bounds]
    crank = ["20 mm", "300 mm"]
    coupler = ["20 mm", "300 mm"]
    rocker = ["20 mm", "300 mm"]

A motion-generation task (the coupler through poses): `task = "motion"`, `poses =
[["x", "y", "angle"], ...]` (the coupler point's place and the coupler's angle) instead
of `targets`, the path's bounds (the angle between the poses' angles and the bar A -> B
is searched as well).

Every mistake is a SceneError naming the synthesis file and the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pinmech.counts import memory_refusal
from pinmech.design.file_where import FileWhere, load_file
from pinmech.design.synthesis.target_checks import refuse_coincident, refuse_collinear
from pinmech.units import to_si

TASKS = ("path", "function", "motion")
SIX_BARS = ("watt", "stephenson")  # drawn linkages with [params], solved by the engine (engine.py)
TOPOLOGIES = ("four-bar", "slider-crank", "inverted-slider-crank", *SIX_BARS)
CLASSES = ("any", "grashof", "crank-rocker", "double-crank", "double-rocker", "triple rocker")
SLIDER_CLASSES = ("any", "crank", "rocker")  # grashof.slider_crank_class: the crank turns fully, or not
DIRECTIONS = ("ccw", "cw", "either")
_TOP = {"title", "task", "topology", "targets", "timing", "seed", "population", "generations", "keep",
        "bounds", "constraints", "pairs", "ground", "poses", "scene", "point", "output", "link", "pair_angles"}
_ONLY = {"targets": "path", "timing": "path", "pairs": "function", "ground": "function", "poses": "motion",
         "pair_angles": "function"}
#: What a four-bar function's pairs hold: turns from the first pair (which is then
#: ["0 deg", "0 deg"]), or the crank's and the rocker's absolute angles from the ground
#: line O2 -> O4 (Freudenstein's theta and phi).
PAIR_ANGLES = ("turns", "absolute")
#: Each (topology, task)'s bounds: the parameters in the order of a candidate's row, each
#: with its axes (none: a length, positive unless it is an offset); "angle" axes are angles.
_BOUNDS = {
    ("four-bar", "path"): (("O2", ("x", "y")), ("O4", ("x", "y")), ("crank", ()), ("coupler", ()), ("rocker", ()),
                           ("point", ("along", "across"))),
    ("four-bar", "function"): (("crank", ()), ("coupler", ()), ("rocker", ())),
    ("slider-crank", "path"): (("O2", ("x", "y")), ("slide", ("angle", "offset")), ("crank", ()), ("rod", ()),
                               ("point", ("along", "across"))),
    ("slider-crank", "function"): (("crank", ()), ("rod", ()), ("offset", ())),
    ("inverted-slider-crank", "path"): (("O2", ("x", "y")), ("O4", ("x", "y")), ("crank", ()), ("offset", ()),
                                        ("point", ("along", "across"))),
    ("inverted-slider-crank", "function"): (("crank", ()), ("offset", ())),
}
#: Crank angles over a turn at which the search samples a candidate's coupler curve to find
#: the angle nearest each target (objective.nearest_angles; 2 deg apart).
SAMPLES = 180
_CONSTRAINTS = {"grashof", "transmission", "ratio", "direction", "pins"}
_LIMITS = {"seed": (0, 2**32 - 1), "population": (5, 1000), "generations": (1, 100_000), "keep": (1, 20)}


@dataclass(frozen=True)
class SynthesisSpec:
    """A validated synthesis file (SI: m, rad).

    Attributes:
        targets: (N, 2) the coupler point's targets in the order of the motion [m]; for a
            function, the pairs (crank turn, rocker turn) from the first pair [rad].
        timing: (N,) the crank's turn from the first target to each [rad], or None
            (then the crank angles are free, their order checked).
        lower, upper: (9,) bounds of (O2x, O2y, O4x, O4y, crank, coupler, rocker, along,
            across) [m] (fourbar.NAMES); for a function (3,) of crank, coupler, rocker [m].
        ground: a function generator's ground O2 -> O4 along x [m] (0 for a path).
        angles: (N,) the coupler's angles at the poses of a motion task [rad] (its
            positions are `targets`), else None.
        grashof: the Grashof class asked ("any": none).
        transmission: the least transmission angle allowed over the motion [rad].
        ratio: the longest link over the shortest, at most.
        direction: the crank's turn from target to target: "ccw", "cw" or "either".
        scene: a six-bar's template, a scene whose drawn linkage has [params]; free: the
            params the search varies (lower, upper: their bounds [m]); point: the coupler
            point of a path or a motion; output: the link whose turns a function gives, or
            the link a motion's poses carry (the file's `link`); pins: the dyads' middle
            pins whose transmission angle is bounded. kernel: the engine's passes (None: the scene's).
    """

    path: Path
    title: str
    task: str
    topology: str
    targets: np.ndarray
    timing: np.ndarray | None
    lower: np.ndarray
    upper: np.ndarray
    grashof: str = "any"
    ground: float = 0.0
    transmission: float = 0.0
    ratio: float = math.inf
    direction: str = "either"
    seed: int = 0
    population: int = 20
    generations: int = 400
    keep: int = 3
    angles: np.ndarray | None = None
    scene: Path | None = None
    free: tuple[str, ...] = ()
    point: str = ""
    output: str = ""
    pins: tuple[str, ...] = ()
    start: tuple[float, float] | None = None
    kernel: str | None = None

    def __hash__(self) -> int:
        return hash((self.path, self.title, self.targets.tobytes(), self.seed))


def load_synthesis(path: str | Path) -> SynthesisSpec:
    """Read and check a synthesis file. Raises SceneError naming the file and the key."""
    return load_file(path, "synthesis", parse_synthesis)


def parse_synthesis(raw: dict[str, Any], path: Path) -> SynthesisSpec:
    """The SynthesisSpec of a synthesis file's TOML content `raw`."""
    w = _Where(path)
    w.known(raw, _TOP, "")
    task = w.choice(raw, "task", TASKS, None)
    topology = w.choice(raw, "topology", TOPOLOGIES, "four-bar")
    for key, only in _ONLY.items():
        timed_motion = key == "timing" and task == "motion" and topology in SIX_BARS  # a six-bar's poses may be timed
        if key in raw and task != only and not timed_motion:
            raise w.error(key, f"{key} is for task = \"{only}\" (this file's task is {task!r})")
    if topology in SIX_BARS:
        return _six_bar(raw, w, path, task, topology)
    for key in ("scene", "point", "output", "link"):
        if key in raw:
            raise w.error(key, f"{key} is for the six-bars (topology = \"watt\" or \"stephenson\")")
    slider = topology == "slider-crank"
    start = None
    if task == "function":
        absolute = w.choice(raw, "pair_angles", PAIR_ANGLES, "turns") == "absolute"
        if absolute and topology != "four-bar":
            raise w.error("pair_angles", "absolute pairs (Freudenstein's crank and rocker angles) are for a "
                          "four-bar's function; give turns from the first pair")
        targets, timing = _pairs(raw, w, "length" if slider else "angle", absolute), None
        if absolute:
            start, targets = (float(targets[0, 0]), float(targets[0, 1])), targets - targets[0]
        lower, upper = _bounds(raw, w, _BOUNDS[topology, "function"])
        ground = 0.0 if slider else w.positive_length(raw, "ground")
        if slider and "ground" in raw:
            raise w.error("ground", "a slider-crank's function has no ground length: its slide is along x, "
                          "`offset` from the crank's pivot (bounds.offset)")
    else:
        targets = _targets(raw, w, "poses" if task == "motion" else "targets")
        refuse_collinear(targets[:, :2], w, "poses" if task == "motion" else "targets", topology)
        timing = _timing(raw, w, len(targets)) if "timing" in raw else None
        lower, upper = _bounds(raw, w, _BOUNDS[topology, "path"])
        ground = 0.0
    c = raw.get("constraints", {})
    w.known(c, _CONSTRAINTS - {"pins"}, "constraints")
    transmission = w.quantity(c, "transmission", "angle", "constraints") if "transmission" in c else 0.0
    if not 0 <= transmission < math.pi / 2:
        raise w.error("constraints.transmission", f"transmission = {c['transmission']!r} must be from 0 to 90 deg")
    ratio = c.get("ratio", math.inf)
    if isinstance(ratio, bool) or not isinstance(ratio, (int, float)) or not ratio > 1:
        raise w.error("constraints.ratio", f"ratio = {ratio!r} must be a number above 1 (longest / shortest link)")
    direction, counts = _direction_and_counts(w, raw, c, task, targets, timing)
    angles = None
    if task == "motion":
        targets, angles = targets[:, :2].copy(), targets[:, 2].copy()
    classes = CLASSES if topology == "four-bar" else SLIDER_CLASSES
    return SynthesisSpec(path, str(raw.get("title", path.stem)), task, topology, targets, timing, lower, upper,
                         w.choice(c, "grashof", classes, "any", "constraints"), ground,
                         transmission, float(ratio), direction, angles=angles, start=start, **counts)


def _six_bar(raw: dict[str, Any], w: _Where, path: Path, task: str, topology: str) -> SynthesisSpec:
    """A Watt or Stephenson six-bar's file: `scene` (its drawn linkage's [params] the
    template), `point` (path) or `output` (function), `[bounds]` of the params varied."""
    from pinmech.exceptions import PinmechError
    from pinmech.io.scene import Scene
    from pinmech.model.linkage_spec import read_linkage_spec

    unread = {"path": ("ground", "output", "link"), "function": ("ground", "point", "link"),
              "motion": ("ground", "output")}[task]
    for key in unread:
        if key in raw:
            raise w.error(key, f"{key} is not read by a {topology} six-bar's {task} task: remove it")
    if not isinstance(raw.get("scene"), str):
        raise w.error("scene", "give scene = \"../scenes/watt_params.toml\": a scene whose drawn linkage has [params]")
    scene_path = path.parent / raw["scene"]
    try:
        scene = Scene.load(scene_path)
    except PinmechError as exc:
        raise w.error("scene", f"{raw['scene']} cannot be read: {exc}") from exc
    if scene.model_kind != "linkage":
        raise w.error("scene", f"{raw['scene']} gives its model by '{scene.model_kind}': a six-bar's scene "
                      "names a drawn linkage (linkage = \"...\") with [params]")
    try:
        linkage, _ = read_linkage_spec(scene.model_file("linkage"))
    except PinmechError as exc:
        raise w.error("scene", f"{raw['scene']}'s linkage cannot be read: {exc}") from exc
    name, kind = ("output", "link") if task == "function" else ("point", "joint")
    named = raw.get(name, None if task == "function" else "P")
    known = linkage.links if task == "function" else linkage.joints
    if named not in known:
        raise w.error(name, f"{name} = {named!r} is not a {kind} of {raw['scene']}'s linkage "
                      f"(its {kind}s: {', '.join(known)})")
    carried = _carried(raw, w, linkage, named) if task == "motion" else ""
    table = raw.get("bounds")
    w.known(table, set(linkage.params), "bounds")
    if not table:
        raise w.error("bounds", f"bound at least one of the linkage's [params] ({', '.join(linkage.params)})")
    lower, upper = np.array([w.interval(v, f"bounds.{k}") for k, v in table.items()]).T
    c = raw.get("constraints", {})
    w.known(c, {"transmission", "direction", "pins"}, "constraints")
    pins = c.get("pins", [])
    if not isinstance(pins, list) or any(p not in linkage.joints for p in pins):
        raise w.error("constraints.pins", f"pins = {pins!r} must list joints of the linkage (the dyads' middle pins, "
                      f"e.g. [\"B\", \"D\"]; its joints: {', '.join(linkage.joints)})")
    transmission = w.quantity(c, "transmission", "angle", "constraints") if "transmission" in c else 0.0
    if not 0 <= transmission < math.pi / 2 or (transmission > 0 and not pins):
        raise w.error("constraints.transmission", f"transmission = {c.get('transmission')!r} must be from 0 to 90 deg, "
                      "with pins = [...] naming the dyads it bounds")
    angles = None
    if task == "function":
        targets, timing = _pairs(raw, w), None
    else:
        targets = _targets(raw, w, "poses" if task == "motion" else "targets")
        timing = _timing(raw, w, len(targets)) if "timing" in raw else None
        if task == "motion":
            targets, angles = targets[:, :2].copy(), targets[:, 2].copy()
    direction, counts = _direction_and_counts(w, raw, c, task, targets, timing)
    return SynthesisSpec(path, str(raw.get("title", path.stem)), task, topology, targets, timing, lower, upper,
                         transmission=transmission, direction=direction, scene=scene_path, free=tuple(table),
                         point=named if task != "function" else "", output=named if task == "function" else carried,
                         pins=tuple(pins), angles=angles, **counts)


def _carried(raw: dict[str, Any], w: _Where, linkage, point: str) -> str:
    """A six-bar motion's `link`: the link the poses carry, one that holds the point."""
    link = raw.get("link")
    if link not in linkage.links:
        raise w.error("link", f"link = {link!r} is not a link of the scene's linkage: give the link the poses "
                      f"carry (its angle is its x axis, from its first joint to the next; its links: "
                      f"{', '.join(linkage.links)})")
    if point not in linkage.links[link]:
        raise w.error("link", f"link = {link!r} does not carry the point {point!r} (it holds "
                      f"{', '.join(linkage.links[link])}): a pose is a place and an angle of one link")
    return link


def _targets(raw: dict[str, Any], w: _Where, key: str = "targets") -> np.ndarray:
    """Path targets [x, y] [m], or motion poses [x, y, angle] [m, m, rad] (key "poses")."""
    value = raw.get(key)
    width, example = (3, '["120 mm", "35 mm", "30 deg"]') if key == "poses" else (2, '["120 mm", "35 mm"]')
    if not isinstance(value, list) or len(value) < 3:
        raise w.error(key, f"give at least 3 {key}, [{example}, ...], in the order of the motion")
    rows = []
    for i, t in enumerate(value):
        if not isinstance(t, list) or len(t) != width:
            raise w.error(f"{key}[{i}]", f"{t!r} must be {'[x, y, angle]' if width == 3 else '[x, y]'} with units, "
                          f"e.g. {example}")
        kinds = ("length", "length", "angle")[:width]
        rows.append([to_si(x, kind, where=f"{w.path}, {key}[{i}]") for x, kind in zip(t, kinds)])
    out = np.array(rows)
    refuse_coincident(out[:, :2], w, key)
    return out


def _pairs(raw: dict[str, Any], w: _Where, output: str = "angle", absolute: bool = False) -> np.ndarray:
    """[crank turn, output's change] from the first pair [rad, rad or m]: the output a
    rocker's turn (angle) or a slider's travel (length); `absolute`: the crank's and the
    rocker's angles as the file gives them (any first pair)."""
    value = raw.get("pairs")
    what, zero = ("rocker turn", "0 deg") if output == "angle" else ("slider travel", "0 mm")
    if not isinstance(value, list) or len(value) < 3:
        raise w.error("pairs", f"give at least 3 pairs [crank turn, {what}] from the first, e.g. "
                      f"[[\"0 deg\", \"{zero}\"], [\"30 deg\", \"12 {zero.split()[1]}\"], ...]")
    rows = []
    for i, t in enumerate(value):
        if not isinstance(t, list) or len(t) != 2:
            raise w.error(f"pairs[{i}]", f"{t!r} must be [crank turn, {what}] with units")
        rows.append([to_si(x, kind, where=f"{w.path}, pairs[{i}]") for x, kind in zip(t, ("angle", output))])
    out = np.array(rows)
    if np.any(out[0] != 0) and not absolute:
        raise w.error("pairs[0]", f"the first pair is the start: [\"0 deg\", \"{zero}\"] (or give absolute "
                      "angles with pair_angles = \"absolute\")")
    step = np.diff(out[:, 0])
    if not (np.all(step > 0) or np.all(step < 0)) or abs(out[-1, 0] - out[0, 0]) >= 2 * math.pi:
        raise w.error("pairs", "the crank turns must grow (ccw) or fall (cw) strictly, within one turn")
    return out


def _timing(raw: dict[str, Any], w: _Where, n: int) -> np.ndarray:
    value = raw["timing"]
    if not isinstance(value, list) or len(value) != n:
        raise w.error("timing", f"give one crank turn per target ({n}), from \"0 deg\" at the first")
    t = np.array([to_si(x, "angle", where=f"{w.path}, timing[{i}]") for i, x in enumerate(value)])
    step = np.diff(t)
    if t[0] != 0 or not (np.all(step > 0) or np.all(step < 0)) or abs(t[-1]) >= 2 * math.pi:
        raise w.error("timing", "the crank's turns must start at 0 deg and grow (ccw) or fall (cw) strictly, "
                      "within one turn")
    return t


def _bounds(raw: dict[str, Any], w: _Where, layout: tuple) -> tuple[np.ndarray, np.ndarray]:
    """The bounds of each parameter of `layout` (_BOUNDS), in its order [m, rad]."""
    table = raw.get("bounds")
    names = [name for name, _ in layout]
    w.known(table, set(names), "bounds")
    missing = [k for k in names if k not in table]
    if missing:
        raise w.error("bounds", f"missing {', '.join(missing)}: every parameter needs [lower, upper]")
    pairs = []
    for name, axes in layout:
        entry = table[name]
        if axes:
            w.known(entry, set(axes), f"bounds.{name}")
            pairs += [w.interval(entry.get(a), f"bounds.{name}.{a}", kind="angle" if a == "angle" else "length")
                      for a in axes]
        else:
            pairs.append(w.interval(entry, f"bounds.{name}", positive=name != "offset"))
    lower, upper = np.array(pairs).T
    return lower, upper


class _Where(FileWhere):
    """The synthesis file, for errors naming it and the key."""

    limits = _LIMITS
    dotted = True

    def choice(self, table: dict, key: str, allowed: tuple[str, ...], default: str | None, under: str = "") -> str:
        full = f"{under}.{key}" if under else key
        value = table.get(key, default)
        if value not in allowed:
            raise self.error(full, f"{key} = {value!r} is not one of {', '.join(allowed)}")
        return value

    def positive_length(self, raw: dict, key: str) -> float:
        if key not in raw:
            raise self.error(key, f"give {key} = \"100 mm\" (the ground O2 -> O4)")
        value = to_si(raw[key], "length", where=f"{self.path}, {key}")
        if not value > 0:
            raise self.error(key, f"{key} = {raw[key]!r} must be a positive length")
        return value

    def quantity(self, table: dict, name: str, kind: str, under: str) -> float:
        return to_si(table[name], kind, where=f"{self.path}, {under}.{name}")

    def interval(self, value: Any, key: str, positive: bool = False, kind: str = "length") -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            example = '["-10 deg", "10 deg"]' if kind == "angle" else '["10 mm", "80 mm"]'
            raise self.error(key, f"{value!r} must be [lower, upper] with units, e.g. {example}")
        lo, hi = (to_si(v, kind, where=f"{self.path}, {key}") for v in value)
        if not lo < hi:
            raise self.error(key, f"lower {value[0]} is not below upper {value[1]}")
        if positive and not lo > 0:
            raise self.error(key, f"lower {value[0]} must be a positive length")
        return lo, hi


def _direction_and_counts(w, raw: dict, c: dict, task: str, targets: np.ndarray, timing) -> tuple[str, dict]:
    """The crank's direction (checked against the turns given: the timing, or a function's
    input angles) and the search's seed, population, generations and keep."""
    direction = w.choice(c, "direction", DIRECTIONS, "either", "constraints")
    turns = timing if timing is not None else targets[:, 0] if task == "function" else None
    if turns is not None and direction != "either" and (turns[-1] > 0) != (direction == "ccw"):
        raise w.error("constraints.direction", f"direction = {direction!r}, but the crank's turns given go "
                      f"{'ccw' if turns[-1] > 0 else 'cw'}")
    counts = {k: w.whole(raw, k, d) for k, d in (("seed", 0), ("population", 20), ("generations", 400), ("keep", 3))}
    _refuse_memory(w, counts["population"], len(targets), task)
    return direction, counts


#: Arrays of (candidates, targets, crank angles) alive at once in the nearest-angle search
#: (objective.nearest_angles: dx, dy, d2 and its masked copies).
_COPIES = 5


def _refuse_memory(w: _Where, population: int, targets: int, task: str) -> None:
    """Refuse a search whose arrays would pass counts.MAX_BYTES: a generation's candidates
    (population x at most 10 parameters) x targets x objective.SAMPLES x 8 bytes x _COPIES."""
    candidates = population * 10
    said = memory_refusal(float(candidates) * targets * SAMPLES * 8 * _COPIES,
                          f"{candidates} candidates a generation x {targets} {task} targets x {SAMPLES} crank angles",
                          "population or the targets")
    if said:
        raise w.error("population", said)
