"""A scene's `[forces]`, `[gravity]` and `[[load]]` tables, parsed once into typed settings.

    [forces]                          # optional; any of these three tables turns forces on
    massless = ["slider_pin"]         # links meant to have no mass (else: an error naming them)
    static = false                    # true: zero speeds and accelerations (statics)
    minimum_norm = false              # redundant loops: the smallest reactions, not an error
    flywheel = "0.05 kg*m^2"          # sweeps: the coefficient of speed fluctuation with it

    [gravity]                         # default: no gravity (kinematics-only scenes)
    acceleration = "9.81 m/s^2"
    direction = [0, -1, 0]            # world frame, any length

    [[load]]                          # an external load, constant in the world frame
    point = "B_pin"                   # a named point (or link = "piston": its frame origin)
    force = ["-200 N", "0 N"]         # x, y (, z) with units
    torque = "0.5 N*m"                # on the point's link; one value: about the plane normal
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinmech.directions import unit_vector, written
from pinmech.exceptions import FrameNotFound, SceneError
from pinmech.solve.forces import ForceSolver, Load, advantage_unit, mechanical_advantage
from pinmech.model.mechanism import Mechanism
from pinmech.io.scene import Scene

_FORCES_KEYS = {"massless", "static", "minimum_norm", "flywheel"}
_LOAD_KEYS = {"name", "point", "link", "force", "torque"}


@dataclass(frozen=True)
class LoadSpec:
    """A `[[load]]` entry in SI: where (a point or link name), force [N], torque [N m].

    `torque_about_normal` is a single torque [N m] about the plane normal (None when the
    torque was given as a vector)."""

    name: str
    at: str
    key: str
    force: np.ndarray
    torque: np.ndarray
    torque_about_normal: float | None


@dataclass(frozen=True)
class ForceSettings:
    """What a scene asks of the force analysis (SI, world frame)."""

    gravity: np.ndarray
    loads: tuple[LoadSpec, ...]
    massless: tuple[str, ...]
    static: bool
    minimum_norm: bool
    flywheel: float | None


def force_settings(scene: Scene) -> ForceSettings:
    """The scene's force tables, checked (keys, types, units).

    Raises:
        SceneError: unknown keys, wrong types; UnitError: a quantity of the wrong kind
            (a force given in N*m).
    """
    table = scene.section("forces")
    where = str(scene.path)
    unknown = set(table) - _FORCES_KEYS
    if unknown:
        raise SceneError(f"unknown key(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_FORCES_KEYS))}",
                         path=where, key="forces")
    for key in ("static", "minimum_norm"):
        if key in table and not isinstance(table[key], bool):
            raise SceneError(f"must be true or false, got {table[key]!r}", path=where, key=f"forces.{key}")
    flywheel = table.get("flywheel")
    if flywheel is not None:
        flywheel = scene.quantity(flywheel, "moment_of_inertia", "forces", "flywheel")
        if not flywheel > 0:
            raise SceneError(f"must be positive, got {table['flywheel']!r}", path=where, key="forces.flywheel")
    return ForceSettings(
        gravity=_gravity(scene),
        loads=tuple(_load(scene, i, entry) for i, entry in enumerate(_load_entries(scene))),
        massless=tuple(scene.names("forces", "massless") or ()),
        static=bool(table.get("static", False)),
        minimum_norm=bool(table.get("minimum_norm", False)),
        flywheel=flywheel,
    )


def _gravity(scene: Scene) -> np.ndarray:
    table = scene.section("gravity")
    if not table:
        return np.zeros(3)
    where = str(scene.path)
    unknown = set(table) - {"acceleration", "direction"}
    if unknown or "acceleration" not in table or "direction" not in table:
        raise SceneError("give acceleration = \"9.81 m/s^2\" and direction = [0, -1, 0] (world frame)",
                         path=where, key="gravity")
    size = scene.quantity(table["acceleration"], "acceleration", "gravity", "acceleration")
    direction = unit_vector(_numbers(table["direction"], where, "gravity.direction"))
    if direction is None:
        raise SceneError(f"{written(table['direction'])} is not a direction (all zero)", path=where,
                         key="gravity.direction")
    return size * direction


def _numbers(value: Any, where: str, key: str) -> np.ndarray:
    ok = isinstance(value, list) and len(value) == 3 and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) for x in value)
    if not ok or not np.all(np.isfinite(value)):
        raise SceneError(f"must be three numbers [x, y, z], got {value!r}", path=where, key=key)
    return np.array(value, dtype=float)


def _load_entries(scene: Scene) -> list[dict[str, Any]]:
    entries = scene.raw.get("load", [])
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise SceneError("write each load as a [[load]] table", path=str(scene.path), key="load")
    return entries


def _load(scene: Scene, index: int, entry: dict[str, Any]) -> LoadSpec:
    key = f"load[{index}]"
    where = str(scene.path)
    unknown = set(entry) - _LOAD_KEYS
    if unknown:
        raise SceneError(f"unknown key(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_LOAD_KEYS))}",
                         path=where, key=key)
    places = [k for k in ("point", "link") if k in entry]
    if len(places) != 1 or not isinstance(entry[places[0]], str):
        raise SceneError("say where the load acts: point = \"NAME\" (a named point) or link = \"NAME\"",
                         path=where, key=key)
    if "force" not in entry and "torque" not in entry:
        raise SceneError("give a force = [\"x N\", \"y N\"] and/or a torque = \"T N*m\"", path=where, key=key)
    force = _vector(scene, entry.get("force", [0, 0, 0]), "force", key)
    torque_value = entry.get("torque", [0, 0, 0])
    about_normal = None
    if isinstance(torque_value, (str, int, float)) and not isinstance(torque_value, bool):
        about_normal = scene.quantity(torque_value, "torque", key, "torque")
        torque = np.zeros(3)
    else:
        torque = _vector(scene, torque_value, "torque", key)
    name = str(entry.get("name", entry[places[0]]))
    return LoadSpec(name, entry[places[0]], places[0], force, torque, about_normal)


def _vector(scene: Scene, value: Any, kind: str, key: str) -> np.ndarray:
    """Two or three quantities with units ("-200 N", "0 N"), world frame, in SI."""
    if not isinstance(value, list) or len(value) not in (2, 3):
        raise SceneError(f"{kind} must be a list of 2 or 3 quantities, e.g. [\"-200 N\", \"0 N\"], got {value!r}",
                         path=str(scene.path), key=f"{key}.{kind}")
    out = np.zeros(3)
    for i, item in enumerate(value):
        out[i] = scene.quantity(item, kind, key, f"{kind}[{i}]")
    return out


def build_loads(settings: ForceSettings, mechanism: Mechanism, scene: Scene) -> list[Load]:
    """The loads with their frames looked up in the model.

    Raises:
        FrameNotFound: a load on an unknown point or link (naming the scene).
        SceneError: a load on the ground (it moves nothing), or a single torque value on a
            mechanism that is not planar.
    """
    loads = []
    for spec in settings.loads:
        known = list(mechanism.points) + list(mechanism.links) if spec.key == "point" else list(mechanism.links)
        if spec.at not in known:
            raise FrameNotFound(f"{spec.key} (in [[load]] {spec.name})", spec.at, known, path=str(scene.path))
        frame = mechanism.frame_id(spec.at)
        if mechanism.model.frames[frame].parentJoint == 0:
            raise SceneError(f"{spec.key} '{spec.at}' is on the ground: a load there moves nothing",
                             path=str(scene.path), key="load")
        torque = spec.torque
        if spec.torque_about_normal is not None:
            if mechanism.plane_normal is None:
                raise SceneError("torque = one value needs a planar mechanism; give [x, y, z] with units",
                                 path=str(scene.path), key=f"load {spec.name}")
            torque = spec.torque_about_normal * mechanism.plane_normal
        loads.append(Load(spec.name, frame, spec.force, torque))
    return loads


def force_solver(scene: Scene, mechanism: Mechanism, drivers: tuple[str, ...], settings: ForceSettings, *,
                 minimum_norm: bool = False) -> ForceSolver:
    """A ForceSolver for the scene's gravity, loads and massless links."""
    for name in settings.massless:
        if name not in mechanism.links:
            raise FrameNotFound("link (in [forces] massless)", name, list(mechanism.links), path=str(scene.path))
    return ForceSolver(mechanism, drivers, gravity=settings.gravity, loads=build_loads(settings, mechanism, scene),
                       massless=settings.massless, minimum_norm=minimum_norm or settings.minimum_norm)


def analyse_forces(scene: Scene, mechanism: Mechanism, drivers: tuple[str, ...], q: np.ndarray, v: np.ndarray,
                   a: np.ndarray, *, static: bool = False, minimum_norm: bool = False) -> tuple[Any, dict[str, Any]]:
    """Forces at a solved pose of a scene: the ForceSolution and the report entries
    (`forces` for JSON, `_text` lines for the text report)."""
    from pinmech.solve.forces_report import forces_dict, forces_text

    settings = force_settings(scene)
    static = static or settings.static
    solver = force_solver(scene, mechanism, drivers, settings, minimum_norm=minimum_norm)
    if static:
        v, a = np.zeros_like(v), np.zeros_like(a)
    solution = solver.solve(q, v, a)
    names = [spec.name for spec in settings.loads]
    advantage = mechanical_advantage(solution, solver.loads) if static else None
    unit = advantage_unit(mechanism.joint(drivers[0]).is_angular, solver.loads[0]) if advantage is not None else ""
    section = forces_dict(solution, mechanism, static=static)
    section["mechanical_advantage"] = advantage
    text = forces_text(solution, mechanism, static=static, loads=names, advantage=(advantage, unit))
    return solution, {"forces": section, "_text": text}
