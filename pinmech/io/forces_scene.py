"""A scene's force analysis: its `[forces]`, `[gravity]` and `[[load]]` tables (typed in
force_tables.py) gathered into ForceSettings, the loads found in the model, the forces
solved at a pose.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinmech.exceptions import FrameNotFound, SceneError
from pinmech.io.force_tables import ForcesSpec, LoadSpec
from pinmech.io.scene import Scene
from pinmech.model.mechanism import Mechanism
from pinmech.solve.forces import ForceSolver, Load, advantage_unit, mechanical_advantage

__all__ = ["ForceSettings", "LoadSpec", "analyse_forces", "build_loads", "force_settings", "force_solver"]


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
    """The scene's force tables (validated when the scene was read) as ForceSettings."""
    tables = scene.file
    forces = tables.forces or ForcesSpec()
    return ForceSettings(
        gravity=np.zeros(3) if tables.gravity is None else tables.gravity.vector,
        loads=tables.load or (),
        massless=forces.massless,
        static=forces.static,
        minimum_norm=forces.minimum_norm,
        flywheel=forces.flywheel,
    )


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
        loads.append(Load(spec.name, frame, np.array(spec.force), np.array(torque)))
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
