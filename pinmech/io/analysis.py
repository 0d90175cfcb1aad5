"""A scene, solved: model loaded, loops closed, rates found, motion read off.

This is the one function the CLI's `solve` and a user's script share:

    analysis = pinmech.analyse(pinmech.Scene.load("models/scenes/r_rtr.toml"))
    analysis.motion.points["D"].velocity   # [m/s], world frame
"""

from __future__ import annotations

from pinmech.arguments import instance_of
from pinmech.exceptions import SceneError
from pinmech.solve.motion import evaluate_motion
from pinmech.io.analysis_result import Analysis
from pinmech.io.scene import Scene, wants_forces
from pinmech.io.scene_model import (
    check_scene_names,
    coincident_points,
    load_mechanism,
    report_lists,
    scene_drivers,
    scene_solver,
)

__all__ = ["Analysis", "analyse"]


def analyse(scene: Scene, *, forces: bool = False, static: bool = False, minimum_norm: bool = False) -> Analysis:
    """Load, close the loops, solve the rates and read off the motion of a scene.

    A scene with `[[task]]` entries is an end-effector rate problem (see `analyse_task`).
    Forces (driver efforts, reactions) are computed when asked (`forces`, `static`) or
    when the scene has a `[forces]`, `[gravity]` or `[[load]]` table (forces_scene.py).
    """
    instance_of(scene, Scene, "analyse's scene")
    if scene.is_task:
        if forces or static or wants_forces(scene):
            raise SceneError("forces are computed for driven mechanisms ([drivers]), not for [[task]] scenes",
                             path=str(scene.path), key="forces")
        from pinmech.io.analysis_task import analyse_task

        return analyse_task(scene)
    mechanism = load_mechanism(scene)
    drivers = scene_drivers(scene, mechanism)
    check_scene_names(scene, mechanism)
    solver = scene_solver(scene, mechanism, drivers)
    solution = solver.solve(drivers.q, drivers.v, drivers.a)
    points, links = report_lists(scene)
    motion = evaluate_motion(mechanism, solver.data, solution.q, solution.v, solution.a,
                             points=points, links=links, coincident=coincident_points(scene))
    if not (forces or static or wants_forces(scene)):
        return Analysis(scene, mechanism, drivers, solution, motion)
    from pinmech.io.forces_scene import analyse_forces

    force_solution, extra = analyse_forces(scene, mechanism, drivers.names, solution.q, solution.v, solution.a,
                                           static=static, minimum_norm=minimum_norm)
    return Analysis(scene, mechanism, drivers, solution, motion, extra=extra, forces=force_solution)
