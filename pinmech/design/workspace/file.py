"""A workspace study file (`kind = "workspace"`): parsed and validated once into a `WorkspaceSpec`.

    title = "Five-bar: reachable workspace and singularity loci"
    scene = "../scenes/five_bar.toml"     # the mechanism; its motors are the actuators
    kind = "workspace"
    batch = 500                            # grid points a Dask task

    [workspace]
    point = "closedloop1_A"                # the end point (a named point or frame)
    x = { from = "-100 mm", to = "200 mm", count = 121 }   # one axis per motor: x, y (plane)
    y = { from = "-60 mm", to = "200 mm", count = 105 }    # or x, y, z (space)
    modes = ["+-", "-+"]                   # working modes (a sign per leg, motors' order); default all
    length = "60 mm"                       # characteristic length of the dimensionless Jacobian
    refine_depth = 6                       # halve the boundary's cells up to 6 times ...
    area_tolerance = 0.01                  # ... or until the area's bound is 1 % of it

An actuator-space study gives the motors' ranges instead of x, y (, z): the forward
kinematics (every assembly mode) at each cell of the motors' grid, and its image in space.

    [workspace.actuators]                  # one axis a motor, by name, in the motors' order
    mot1 = { from = "-90 deg", to = "270 deg", count = 73 }
    mot2 = { from = "-180 deg", to = "180 deg", count = 73 }

Every mistake is a SceneError naming the study file, the key and the value as written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pinmech.counts import memory_refusal
from pinmech.design.file_where import load_file
from pinmech.design.study.file import GridAxis, _Where
from pinmech.design.workspace.measure import MAX_DEPTH
from pinmech.exceptions import UnitError
from pinmech.units import to_si

_TOP = {"title", "scene", "kind", "batch", "workspace"}
_KEYS = {"point", "x", "y", "z", "modes", "length", "refine_depth", "area_tolerance", "actuators"}
_AXIS_KEYS = {"from", "to", "count"}
_MAX_POINTS = 2_000_000
_DEFAULT_DEPTH = 6  # halvings when only area_tolerance is given: 1/64 of a step at most


@dataclass(frozen=True)
class WorkspaceSpec:
    """A validated workspace study (lengths in m).

    Attributes:
        path: the study file; scene: the scene file it names; kind: "workspace".
        point: the end point's name; axes: the task-space grid's axes (named x, y, z) [m].
        modes: the working modes asked ("+-" ...: one sign a leg, in the motors' order),
            () for every one; length: the characteristic length [m] (None: the mechanism's).
        batch: grid points a batch (a Dask task); unit, unit_si: the user's length unit
            (from the first axis's `from`) and its size [m].
        space: "task" (axes x, y, z: the end point's coordinates) or "actuator" (axes named
            by the motors, [rad] or [m]: the motors' values);
        refine_depth: halvings of the cells the workspace's boundary crosses (0: none);
            area_tolerance: stop halving once the bound is this share of the area (None:
            halve `refine_depth` times).
    """

    path: Path
    title: str
    scene: Path
    point: str
    axes: tuple[GridAxis, ...]
    modes: tuple[str, ...]
    length: float | None
    batch: int
    unit: str
    unit_si: float
    refine_depth: int = 0
    area_tolerance: float | None = None
    space: str = "task"
    kind: str = "workspace"
    seed: int = 0
    kernel: str | None = None  # the kinematic passes asked by the API (None: the scene's [solver] kernel)

    @property
    def task_rows(self) -> tuple[int, ...]:
        """The world coordinates (0 x, 1 y, 2 z) of the end point that make the task."""
        if self.space == "actuator":
            return tuple(range(len(self.axes)))
        return tuple(a.param for a in self.axes)

    @property
    def size(self) -> int:
        """Grid points in all."""
        return math.prod(a.count for a in self.axes)


def load_workspace(path: str | Path) -> WorkspaceSpec:
    """Read and check a workspace study file. Raises SceneError naming the file and the key."""
    return load_file(path, "study", parse_workspace)


def parse_workspace(raw: dict[str, Any], path: Path) -> WorkspaceSpec:
    """The WorkspaceSpec of a study file's TOML content `raw` (relative paths: from its folder)."""
    where = _Where(path)
    where.known(raw, _TOP, "")
    scene = raw.get("scene")
    if not isinstance(scene, str):
        raise where.error("scene", f"scene = {scene!r}: give the scene file, e.g. \"../scenes/five_bar.toml\"")
    table = raw.get("workspace")
    if not isinstance(table, dict):
        raise where.error("workspace", "a workspace study needs a [workspace] table: point = \"P\", "
                          "x = { from = \"-100 mm\", to = \"100 mm\", count = 51 }, y = ...")
    where.known(table, _KEYS, "workspace")
    point = table.get("point")
    if not isinstance(point, str) or not point:
        raise where.error("workspace.point", f"point = {point!r}: name the end point, e.g. point = \"tool\"")
    names = [k for k in ("x", "y", "z") if k in table]
    if "actuators" in table:
        if names or "refine_depth" in table or "area_tolerance" in table:
            extra = (names or [k for k in ("refine_depth", "area_tolerance") if k in table])[0]
            raise where.error(f"workspace.{extra}", f"an actuator-space grid ([workspace.actuators]) takes no "
                              f"{extra}: give the motors' ranges, or x, y (, z) for a task-space grid")
        axes, space = _actuator_axes(table["actuators"], where), "actuator"
    elif names not in (["x", "y"], ["x", "y", "z"]):
        raise where.error("workspace", f"give the grid's axes x, y (a plane) or x, y, z (a box), or the motors' "
                          f"ranges in [workspace.actuators]; got {names or 'none'}")
    else:
        axes, space = tuple(_axis(n, table[n], where) for n in names), "task"
    size = math.prod(a.count for a in axes)
    if size > _MAX_POINTS:
        raise where.error("workspace", f"{size} grid points is more than {_MAX_POINTS}: lower the counts")
    _refuse_memory(size, len(axes), table.get("modes"), where)
    length = _length(table, where)
    unit = _unit(table["x"]["from"] if space == "task" else table.get("length", "1 mm"))
    batch = where.whole(raw, "batch", 500)
    tolerance = _tolerance(table, where)
    depth = _depth(table, where, _DEFAULT_DEPTH if tolerance is not None else 0)
    return WorkspaceSpec(path, str(raw.get("title", path.stem)), path.parent / scene, point, axes,
                         _modes(table.get("modes", []), where), length, batch, unit,
                         to_si(f"1 {unit}", "length", where=f"{path}, workspace.x.from"), depth, tolerance, space)


#: Numbers a grid point keeps per mode: reached, det1, det2, sigma1, sigma2, kappa, the
#: motors' values (up to 3), two distances, its coordinates (up to 3); the maps and the
#: batches they come from are alive together (x 2).
_PER_MODE = 14 * 2


def _refuse_memory(size: int, axes: int, modes: Any, where: _Where) -> None:
    """Refuse a map whose arrays would pass counts.MAX_BYTES: grid points x working modes
    (those asked, else 2 per leg, a leg per axis) x _PER_MODE x 8 bytes."""
    count = len(modes) if isinstance(modes, list) and modes else 2 ** axes
    said = memory_refusal(float(size) * count * _PER_MODE * 8, f"{size} grid points x {count} working modes",
                          "the counts")
    if said:
        raise where.error("workspace", said)


def _actuator_axes(table: Any, where: _Where) -> tuple[GridAxis, ...]:
    """The motors' axes, in the file's order: values in rad (an angle) or m (a length)."""
    if not isinstance(table, dict) or len(table) not in (2, 3):
        raise where.error("workspace.actuators", f"give 2 or 3 motors' ranges, e.g. mot1 = {{ from = \"-90 deg\", "
                          f"to = \"90 deg\", count = 37 }}; got {len(table) if isinstance(table, dict) else table!r}")
    return tuple(_axis(name, entry, where, f"workspace.actuators.{name}", k) for k, (name, entry) in
                 enumerate(table.items()))


def _axis(name: str, entry: Any, where: _Where, key: str = "", param: int | None = None) -> GridAxis:
    """A grid axis: a task axis x, y, z [m], or a motor's (`param` its index) [rad or m]."""
    key = key or f"workspace.{name}"
    if not isinstance(entry, dict):
        raise where.error(key, f"{name} = {entry!r}: give {{ from = ..., to = ..., count = ... }}")
    where.known(entry, _AXIS_KEYS, key)
    missing = sorted(_AXIS_KEYS - set(entry))
    if missing:
        example = '{ from = "-100 mm", to = "100 mm", count = 51 }'
        raise where.error(key, f"missing {', '.join(missing)}: give {example}")
    count = entry["count"]
    if isinstance(count, bool) or not isinstance(count, int) or not 2 <= count <= 10_000:
        raise where.error(f"{key}.count", f"count = {count!r} must be a whole number from 2 to 10000")
    if param is None:
        start, stop = where.length(entry, "from", key), where.length(entry, "to", key)
    else:
        start, stop = (_motor_value(entry, end, f"{where.path}, {key}") for end in ("from", "to"))
    if not start < stop:
        raise where.error(key, f"from {entry['from']} is not below to {entry['to']}")
    return GridAxis(name, "xyz".index(name) if param is None else param, start, stop, count)


def _motor_value(entry: dict, name: str, where: str) -> float:
    """A motor's value [rad or m] as written: an angle ("30 deg"), else a length ("20 mm");
    `where` names the file and the axis's key in the error."""
    errors = []
    for kind in ("angle", "length"):
        try:
            return to_si(entry[name], kind, where=f"{where}.{name}")
        except UnitError as exc:
            if _unit_is(entry[name], kind):  # "1e308 deg", "nan deg": an angle, wrong as a number
                raise
            errors.append(exc)
    raise UnitError(f"{name} = {entry[name]!r} is neither an angle nor a length: give a motor's value "
                    "as \"30 deg\" (a turn) or \"20 mm\" (a slide)", key=f"{where}.{name}") from errors[-1]


def _unit_is(value: Any, kind: str) -> bool:
    """Whether the unit written after the number in `value` is one of `kind`."""
    try:
        return to_si(f"1 {_unit(value)}", kind) > 0
    except UnitError:
        return False


def _length(table: dict, where: _Where) -> float | None:
    if "length" not in table:
        return None
    return where.positive(table, "length", "workspace")


def _depth(table: dict, where: _Where, default: int) -> int:
    value = table.get("refine_depth", default)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_DEPTH:
        raise where.error("workspace.refine_depth", f"refine_depth = {value!r} must be a whole number of "
                          f"halvings from 0 to {MAX_DEPTH}")
    return value


def _tolerance(table: dict, where: _Where) -> float | None:
    if "area_tolerance" not in table:
        return None
    value = table["area_tolerance"]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < 1:
        raise where.error("workspace.area_tolerance", f"area_tolerance = {value!r} must be a share of the area "
                          "between 0 and 1 (a number, e.g. 0.01 for 1 %)")
    return float(value)


def _modes(value: Any, where: _Where) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(m, str) and m and set(m) <= {"+", "-"} for m in value):
        raise where.error("workspace.modes", f"modes = {value!r} must be a list of sign strings, one sign a "
                          "leg in the motors' order, e.g. [\"+-\", \"-+\"]")
    return tuple(dict.fromkeys(value))


def _unit(text: Any) -> str:
    """The unit written after the number ("-100 mm" -> "mm"); metres if none."""
    parts = str(text).split(maxsplit=1)
    return parts[1].strip() if len(parts) == 2 else "m"


def is_workspace(raw: dict[str, Any]) -> bool:
    """Whether a study file's content asks for a workspace study."""
    return raw.get("kind") == "workspace"


