"""Study files (`models/studies/*.toml`): parsed and validated once into a `StudySpec`.

    title = "Four-bar: how the tolerances move the rocker"
    scene = "../scenes/four_bar.toml"   # the mechanism, its drivers and assembly
    kind = "tolerance"                   # or "sensitivity"
    steps = 73                           # poses over the scene's [sweep] from..to, else one turn of its first driver
    samples = 400                        # tolerance: Monte Carlo variants
    seed = 2025                          # tolerance: the random stream's seed

    [params.crank]                       # a joint origin component [length]
    joint = "A"
    component = "x"
    tolerance = "0.1 mm"                 # +-0.1 mm at k sigma (k = 3 unless given)
    distribution = "normal"              # or "uniform" (+-tolerance), "fixed"

    [params.coupler]                     # a cut frame's origin component
    cut = "B"
    side = "parent"
    component = "x"
    sigma = "0.02 mm"
    bounds = ["119.9 mm", "120.1 mm"]

    [params.P_x]                         # a named point's place on its link (a scene's [points],
    point = "P"                          # a URDF fixed link, an MJCF site, a robot.yaml loop frame)
    component = "x"                      # (or body = "coupler": an MJCF body's pos)

    [params.crank_drawn]                 # a drawn linkage's [params] entry (a scene with linkage = ...):
    param = "crank"                      # the linkage is redrawn for each variant; no component

    [params.gamma]                       # a drawn angle param (gamma = "26.57 deg" in the linkage):
    param = "gamma"                      # its values in deg
    tolerance = "0.5 deg"

    [spec]                               # tolerance: limits on an output's deviation from the nominal
    "P.y" = "0.3 mm"                     # +-0.3 mm (or { lower = "-0.2 mm", upper = "0.3 mm" }):
                                         # Cp, Cpk and parts per million out (capability.py)

    [outputs]
    points = ["P"]                       # world x, y, z of these points [m]
    links = ["rocker"]                   # angle of these links about the plane normal [rad]
    sliders = ["slide"]                  # a prismatic joint's s [m] and s_dot [m/s]
    omega = ["rocker"]                   # angular speed about the plane normal [rad/s]
    transmission = ["B"]                 # the transmission angle of the dyad with middle pin B [rad]
    alpha = ["rocker"]                   # angular acceleration about the plane normal [rad/s^2]
    strokes = ["slide"]                  # a prismatic joint's max - min of s over the cycle [m]
    torque = ["O2"]                      # a driver's torque [N m] or force [N] (the scene's masses, loads)

    # kind = "grid": 1 to 3 of the parameters over evenly spaced values (the others at nominal)
    [grid.crank]
    from = "20 mm"
    to = "70 mm"
    count = 11

A component is read and written in the frame the file writes it in (a URDF origin in its
parent link's, an MJCF pos in its body's), whatever frames Pinocchio merged it into.

Every mistake is a SceneError naming the study file, the key and the value as written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pinmech.design.file_where import FileWhere, load_file
from pinmech.counts import memory_refusal
from pinmech.design.study.params import AXES, DISTRIBUTIONS, Parameter
from pinmech.io.scene import Scene
from pinmech.model.linkage_expr import is_angle
from pinmech.units import to_si


KINDS = ("sensitivity", "tolerance", "grid", "workspace")
_TOP = {"title", "scene", "kind", "steps", "samples", "seed", "params", "outputs", "batch", "grid", "spec"}
_GRID_KEYS = {"from", "to", "count"}
_GRID_MAX = 1_000_000  # grid points in all
_TARGETS = ("joint", "cut", "point", "body", "param")
_PARAM_KEYS = {"joint", "cut", "point", "body", "param", "side", "component", "nominal", "bounds", "tolerance", "k", "sigma", "distribution"}
_OUTPUT_KEYS = {"points", "links", "sliders", "omega", "transmission", "alpha", "strokes", "torque"}
_LIMITS = {"steps": (1, 100_000), "samples": (1, 10_000_000), "seed": (0, 2**63 - 1), "batch": (1, 1_000_000)}
#: Keys only some kinds use: any other kind refuses them (a key read by nobody would be a
#: silent no-op). Top-level keys, then [params.NAME] keys.
_TOP_USED_BY = {"samples": ("tolerance",), "seed": ("tolerance",), "batch": ("tolerance", "grid"),
                "spec": ("tolerance",)}
_PARAM_USED_BY = {k: ("tolerance",) for k in ("tolerance", "sigma", "k", "distribution")}


@dataclass(frozen=True)
class GridAxis:
    """One axis of a grid study: parameter `name` (index `param`) at `count` evenly spaced
    values from `start` to `stop` [m], both ends included."""

    name: str
    param: int
    start: float
    stop: float
    count: int
    kind: str = "length"  # the parameter's: "angle" for a drawn angle param (values in rad)

    @property
    def values(self) -> tuple[float, ...]:
        """The axis's values [m]."""
        if self.count == 1:
            return (self.start,)
        step = (self.stop - self.start) / (self.count - 1)
        return tuple(self.start + i * step for i in range(self.count))


@dataclass(frozen=True)
class StudySpec:
    """A validated study file (lengths in m).

    Attributes:
        path: the study file; scene: the scene file it names.
        kind: "sensitivity" or "tolerance".
        steps: poses over the scene's [sweep] from .. to, else one turn of its first driver,
            both ends included.
        samples, seed: Monte Carlo variants and the seed of their random stream.
        batch: variants per batch (a Dask task); results do not depend on it.
        params: the parameters, in the file's order.
        points, links: the outputs (point positions, link angles).
        sliders, omega: prismatic joints (s and s_dot), links' angular speeds (outputs.py).
        transmission: dyads by their middle pin, for their transmission angle.
        alpha: links' angular accelerations; strokes: prismatic joints' max - min of s.
        torque: drivers whose torque (force) the scene's masses and loads need.
        limits: a tolerance study's `[spec]`: (output name, "0.3 mm" or ((lower, text),
            (upper, text))) as written (read in the output's own quantity by
            capability.limits once the outputs are known).
        grid: a grid study's axes (1 to 3), in the [grid] table's order; () otherwise.
    """

    path: Path
    title: str
    scene: Path
    kind: str
    steps: int
    samples: int
    seed: int
    batch: int
    params: tuple[Parameter, ...]
    points: tuple[str, ...]
    links: tuple[str, ...]
    grid: tuple[GridAxis, ...] = ()
    sliders: tuple[str, ...] = ()
    omega: tuple[str, ...] = ()
    transmission: tuple[str, ...] = ()
    alpha: tuple[str, ...] = ()
    strokes: tuple[str, ...] = ()
    torque: tuple[str, ...] = ()
    limits: tuple = ()
    certify: str | None = None  # the certification dial asked for the run (None: the scene's [solver])
    kernel: str | None = None  # the kinematic passes asked by the API (None: the scene's [solver] kernel)


def spec_scene(spec) -> Scene:
    """The scene a study or workspace file names, with the kernel the API asked (`spec.kernel`)
    in place of its [solver] kernel where one was asked."""
    asked = getattr(spec, "kernel", None)
    return Scene.load(spec.scene, [f'solver.kernel="{asked}"'] if asked else None)


def load_study(path: str | Path) -> StudySpec:
    """Read and check a study file. Raises SceneError naming the file and the key."""
    return load_file(path, "study", parse_study)


def parse_study(raw: dict[str, Any], path: Path) -> StudySpec:
    """The StudySpec of a study file's TOML content `raw` (relative paths: from its folder)."""
    where = _Where(path)
    where.known(raw, _TOP, "")
    kind = raw.get("kind", "sensitivity")
    if kind not in KINDS:
        raise where.error("kind", f"kind = {kind!r} is not one of {', '.join(KINDS)}")
    if kind == "workspace":
        raise where.error("kind", "a workspace study is read by pinmech.study (design/workspace/file.py)")
    _refuse_unused(raw, kind, where)
    scene = raw.get("scene")
    if not isinstance(scene, str):
        raise where.error("scene", f"scene = {scene!r}: give the scene file, e.g. \"../scenes/four_bar.toml\"")
    params = raw.get("params")
    if not isinstance(params, dict) or not params:
        raise where.error("params", "give at least one [params.NAME] table")
    outputs = raw.get("outputs", {})
    where.known(outputs, _OUTPUT_KEYS, "outputs")
    named = {k: _names(outputs.get(k, []), where, f"outputs.{k}") for k in sorted(_OUTPUT_KEYS)}
    if not any(named.values()):
        raise where.error("outputs", "name at least one output: points = [\"P\"] or links = [\"rocker\"]")
    counts = {k: where.whole(raw, k, default) for k, default in
              (("steps", 73), ("samples", 200), ("seed", 0), ("batch", 64))}
    parsed = tuple(_parameter(name, table, where) for name, table in params.items())
    _refuse_memory(kind, counts, named, len(parsed), _grid_points(raw, kind), where)
    return StudySpec(path, str(raw.get("title", path.stem)), (path.parent / scene), kind, counts["steps"],
                     counts["samples"], counts["seed"], counts["batch"], parsed, named["points"],
                     named["links"], _grid(raw, kind, parsed, where), named["sliders"], named["omega"],
                     named["transmission"], named["alpha"], named["strokes"],
                     named["torque"], _spec_table(raw, where))


def _spec_table(raw: dict[str, Any], where: _Where) -> tuple:
    """The `[spec]` table: output name -> "0.3 mm" (+-) or {lower, upper}, as written."""
    table = raw.get("spec", {})
    if not isinstance(table, dict):
        raise where.error("spec", 'give [spec] as a table: "P.y" = "0.3 mm" or { lower = "-0.2 mm", upper = "0.3 mm" }')
    for name, value in table.items():
        if not isinstance(value, (str, dict)):
            raise where.error(f"spec.{name}", f"{value!r} must be a +- quantity (\"0.3 mm\") or {{ lower, upper }}")
    return tuple((name, tuple(value.items()) if isinstance(value, dict) else value) for name, value in table.items())


#: Columns each output name gives (a point's x, y, z; a slider's s and s_dot; one else).
_WIDTH = {"points": 3, "sliders": 2}
#: Copies of the variants' outputs alive at once: the batches, their deviations from the
#: nominal, and np.percentile's sorted copy.
_COPIES = 3


def _refuse_memory(kind: str, counts: dict[str, int], named: dict[str, tuple], n_par: int, points: int,
                   where: _Where) -> None:
    """Refuse a study whose arrays would pass counts.MAX_BYTES, from the file's counts alone:
    variants (samples, or grid points) x steps x outputs x 8 bytes x _COPIES."""
    outputs = sum(_WIDTH.get(k, 1) * len(v) for k, v in named.items())
    variants, key = {"tolerance": (counts["samples"], "samples"), "grid": (points, "grid")}.get(kind, (n_par, "steps"))
    nbytes = float(variants) * counts["steps"] * (outputs + n_par) * 8 * _COPIES
    said = memory_refusal(nbytes, f"{variants} {'variants' if kind != 'sensitivity' else 'parameters'} x "
                          f"{counts['steps']} poses x {outputs} outputs", f"{key} or steps")
    if said:
        raise where.error(key, said)


def _grid_points(raw: dict[str, Any], kind: str) -> int:
    """A grid study's points as the file counts them (checked by _grid); 0 otherwise."""
    table = raw.get("grid") if kind == "grid" else None
    if not isinstance(table, dict):
        return 0
    counts = [e.get("count") for e in table.values() if isinstance(e, dict)]
    return math.prod(c for c in counts if isinstance(c, int) and not isinstance(c, bool) and c > 0)


def _refuse_unused(raw: dict[str, Any], kind: str, where: _Where) -> None:
    """A SceneError for the first key this kind does not use (samples on a grid study, a
    parameter's sigma on a sensitivity study...), naming the kinds that use it."""
    unused = [(k, k, kinds) for k, kinds in _TOP_USED_BY.items() if k in raw and kind not in kinds]
    params = raw.get("params")
    for name, table in (params.items() if isinstance(params, dict) else ()):
        unused += [(k, f"params.{name}.{k}", kinds) for k, kinds in _PARAM_USED_BY.items()
                   if isinstance(table, dict) and k in table and kind not in kinds]
    if unused:
        key, where_key, kinds = unused[0]
        used = " or ".join(f"kind = \"{k}\"" for k in kinds)
        raise where.error(where_key, f"{key} is for {used}; a {kind} study would not use it: remove it")


def _grid(raw: dict[str, Any], kind: str, params: tuple[Parameter, ...], where: _Where) -> tuple[GridAxis, ...]:
    """The [grid] table's axes: given exactly when kind = "grid"."""
    if kind != "grid":
        if "grid" in raw:
            raise where.error("grid", f"[grid] is for kind = \"grid\" (this study's kind is {kind!r})")
        return ()
    table = raw.get("grid")
    if not isinstance(table, dict):
        raise where.error("grid", "a grid study needs [grid.NAME] tables: from = \"30 mm\", to = \"60 mm\", count = 7")
    if not 1 <= len(table) <= 3:
        raise where.error("grid", f"give 1 to 3 [grid.NAME] tables, got {len(table)}")
    axes = tuple(_axis(name, entry, params, where) for name, entry in table.items())
    points = math.prod(a.count for a in axes)
    if points > _GRID_MAX:
        raise where.error("grid", f"{points} grid points is more than {_GRID_MAX}: lower the counts")
    return axes


def _axis(name: str, entry: Any, params: tuple[Parameter, ...], where: _Where) -> GridAxis:
    key, names = f"grid.{name}", [p.name for p in params]
    if name not in names:
        raise where.error(key, f"'{name}' is not a parameter (the [params] tables: {', '.join(names)})")
    where.known(entry, _GRID_KEYS, key)
    missing = sorted(_GRID_KEYS - set(entry))
    if missing:
        raise where.error(key, f"missing {', '.join(missing)}: give from = \"30 mm\", to = \"60 mm\", count = 7")
    count = entry["count"]
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= _GRID_MAX:
        raise where.error(f"{key}.count", f"count = {count!r} must be a whole number from 1 to {_GRID_MAX}")
    along = _Where(where.path, "angle" if is_angle(entry["from"]) else params[names.index(name)].kind)
    start, stop = along.length(entry, "from", key), along.length(entry, "to", key)
    if count > 1 and not start < stop:
        raise where.error(key, f"from {entry['from']} is not below to {entry['to']} (count {count})")
    if count == 1 and start != stop:
        raise where.error(key, f"count = 1 is the one value from = {entry['from']}: give to = from, or a count above 1")
    return GridAxis(name, names.index(name), start, stop, count, along.kind)


def _parameter(name: str, table: Any, where: _Where) -> Parameter:
    key = f"params.{name}"
    if not isinstance(table, dict):
        raise where.error(key, "must be a table (joint = \"A\", component = \"x\", tolerance = \"0.1 mm\")")
    where.known(table, _PARAM_KEYS, key)
    given = [t for t in _TARGETS if t in table]
    if len(given) != 1:
        raise where.error(key, "give one of joint = \"NAME\" (its origin), cut = \"NAME\" (a cut frame's origin), "
                          "point = \"NAME\" (a named point), body = \"NAME\" (an MJCF body's pos) or param = \"NAME\" "
                          "(a drawn linkage's [params] entry)")
    target = given[0]
    if not isinstance(table[target], str):
        raise where.error(f"{key}.{target}", f"{target} = {table[target]!r} must be a name")
    side = table.get("side", "parent" if target == "cut" else "")
    if target == "cut" and side not in ("parent", "child"):
        raise where.error(f"{key}.side", f"side = {side!r} must be \"parent\" or \"child\"")
    if target != "cut" and "side" in table:
        raise where.error(f"{key}.side", f"side is for a cut's frames; a {target} has one origin")
    component = table.get("component", "x" if target == "param" else None)
    if target == "param" and "component" in table:
        raise where.error(f"{key}.component", "a drawn linkage's param is a length of its own: it has no component")
    if component not in AXES:
        raise where.error(f"{key}.component", f"component = {component!r} must be \"x\", \"y\" or \"z\"")
    kind = _kind(table) if target == "param" else "length"
    where = _Where(where.path, kind)
    nominal = where.length(table, "nominal", key) if "nominal" in table else None
    lower, upper = _bounds(table, key, where, nominal)
    distribution, spread = _distribution(table, key, where)
    return Parameter(name, target, str(table[target]), side, AXES[component], nominal, lower, upper,
                     distribution, spread, kind)


def _kind(table: dict) -> str:
    """A drawn param's kind, by the unit of its first value given: "angle" for "0.5 deg",
    else "length" (values of the other kind are then refused by name)."""
    given = [table[k] for k in ("nominal", "tolerance", "sigma") if k in table]
    given += list(table["bounds"]) if isinstance(table.get("bounds"), list) else []
    return "angle" if given and is_angle(given[0]) else "length"


def _bounds(table: dict, key: str, where: _Where, nominal: float | None) -> tuple[float, float]:
    if "bounds" not in table:
        return -math.inf, math.inf
    bounds = table["bounds"]
    if not isinstance(bounds, list) or len(bounds) != 2:
        raise where.error(f"{key}.bounds", f"bounds = {bounds!r} must be [lower, upper], e.g. [\"119 mm\", \"121 mm\"]")
    lower, upper = (to_si(b, where.kind, where=f"{where.path}, {key}.bounds") for b in bounds)
    if not lower < upper:
        raise where.error(f"{key}.bounds", f"lower {bounds[0]} is not below upper {bounds[1]}")
    if nominal is not None and not lower <= nominal <= upper:
        raise where.error(f"{key}.nominal", f"nominal {table['nominal']} is outside bounds {bounds[0]} .. {bounds[1]}")
    return lower, upper


def _distribution(table: dict, key: str, where: _Where) -> tuple[str, float]:
    given = "sigma" in table or "tolerance" in table
    distribution = table.get("distribution", "normal" if given else "fixed")
    if distribution not in DISTRIBUTIONS:
        raise where.error(f"{key}.distribution", f"distribution = {distribution!r} is not one of "
                          f"{', '.join(DISTRIBUTIONS)}")
    if distribution == "fixed":
        spread = [k for k in ("sigma", "tolerance", "k") if k in table]
        if spread:
            raise where.error(f"{key}.{spread[0]}", f"a fixed parameter has no spread: remove {spread[0]}, or give "
                              "distribution = \"normal\" or \"uniform\"")
        return distribution, 0.0
    if "sigma" in table and ("tolerance" in table or distribution == "uniform"):
        raise where.error(f"{key}.sigma", "give sigma (normal) or tolerance (+-, normal at k sigma, or uniform)")
    if "sigma" in table and "k" in table:
        raise where.error(f"{key}.k", "k (tolerance at k sigma) goes with tolerance; sigma is the standard deviation")
    if "sigma" in table:
        return distribution, where.positive(table, "sigma", key)
    if "tolerance" not in table:
        raise where.error(key, f"a {distribution} distribution needs tolerance = \"0.1 mm\" or sigma = \"0.03 mm\"")
    tol = where.positive(table, "tolerance", key)
    if distribution == "uniform":
        if "k" in table:
            raise where.error(f"{key}.k", "k (tolerance at k sigma) is for a normal distribution")
        return distribution, tol
    k = table.get("k", 3)
    if isinstance(k, bool) or not isinstance(k, (int, float)) or not 0 < k < 100:
        raise where.error(f"{key}.k", f"k = {k!r} must be a number of sigmas between 0 and 100, e.g. 3")
    return distribution, tol / float(k)


def _names(value: Any, where: _Where, key: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise where.error(key, f"{value!r} must be a list of names")
    return tuple(value)


class _Where(FileWhere):
    """The study file, for errors naming it and the key; `kind`: the quantity its values are
    ("length", or "angle" for a drawn angle param)."""

    limits = _LIMITS

    def __init__(self, path: Path, kind: str = "length") -> None:
        super().__init__(path)
        self.kind = kind

    def length(self, table: dict, name: str, key: str) -> float:
        return to_si(table[name], self.kind, where=f"{self.path}, {key}.{name}")

    def positive(self, table: dict, name: str, key: str) -> float:
        value = self.length(table, name, key)
        if not value > 0:
            raise self.error(f"{key}.{name}", f"{name} = {table[name]!r} must be a positive {self.kind}")
        return value
