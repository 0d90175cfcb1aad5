"""A task scene, solved: pose set (loops closed), task rates solved, motion read off.

    [pose]                    # joint coordinates (on a closed loop: as many as the mobility)
    A = "50 deg"
    [[task]]
    frame = "D"               # a point, link or frame
    components = ["x", "y"]   # of x, y, z, wx, wy, wz
    reference = "world"       # or "local"
    velocity = ["1 m/s", "0 m/s"]
    acceleration = ["0 m/s^2", "0 m/s^2"]
    [rates]
    method = "exact"          # or "least_squares", "damped"
    damping = 1e-3
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinmech.exceptions import FrameNotFound, SceneError
from pinmech.model.mechanism import Mechanism
from pinmech.solve.motion import evaluate_motion
from pinmech.io.analysis_result import Analysis
from pinmech.solve.results import Accuracy, LoopSolution, RateSolution
from pinmech.io.scene import Scene
from pinmech.io.scene_model import (
    Drivers,
    check_scene_names,
    coincident_points,
    load_mechanism,
    report_lists,
    scene_guess,
)
from pinmech.solve.loops import DEFAULT_TOL, LoopSolver
from pinmech.solve.rates import RateSolver, Task

def scene_tasks(scene: Scene) -> list[Task]:
    """The `[[task]]` entries (validated when the scene was read), in SI units."""
    return [Task(t.frame, t.components, np.array(t.velocity), np.array(t.acceleration), t.reference)
            for t in scene.file.task or ()]


def _check_frames(scene: Scene, mechanism: Mechanism, tasks: list[Task]) -> None:
    """Every task frame is in the model, else FrameNotFound naming the scene and the task."""
    for i, task in enumerate(tasks):
        try:
            mechanism.frame_id(task.frame)
        except FrameNotFound as exc:
            raise FrameNotFound(f"frame (in task[{i}])", task.frame, exc.known, path=str(scene.path)) from None


def scene_pose(scene: Scene, mechanism: Mechanism) -> tuple[np.ndarray, list[str], np.ndarray]:
    """Configuration from `[guess]` then `[pose]`; also the pose joints and their values (SI)."""
    q = scene_guess(scene, mechanism)
    names, values, followers = [], [], {}
    for name, value in scene.file.pose.items():
        if name in mechanism.locked:
            continue
        if name not in mechanism.joints:
            raise FrameNotFound("joint (in [pose])", name, list(mechanism.joints), path=str(scene.path),
                                cuts=mechanism.cut_names)
        if name in mechanism.mimics:  # set by its leader; checked below
            followers[name] = scene.joint_quantity(value, mechanism.mimics[name].kind, 0, "pose", name)
            continue
        joint = mechanism.joints[name]
        x = scene.joint_quantity(value, joint.kind, 0, "pose", name)
        mechanism.set_coordinate(q, name, x)
        names.append(name)
        values.append(x)
    for name, x in followers.items():
        follows = mechanism.coordinate(q, name)
        if abs(x - follows) > 1e-9 * max(1.0, abs(follows)):
            m = mechanism.mimics[name]
            raise SceneError(f"{name} follows {m.leader} (URDF <mimic>: {m.multiplier:g} x {m.leader} + {m.offset:g}) "
                             f"= {follows:.9g} (SI), not {x:.9g}: give {m.leader}'s value only",
                             path=str(scene.path), key=f"pose.{name}")
    return q, names, np.array(values)


def analyse_task(scene: Scene) -> Analysis:
    """Set the pose (closing loops with the pose joints held), then solve the task's rates."""
    mechanism = load_mechanism(scene)
    q, names, values = scene_pose(scene, mechanism)
    residual, iterations = 0.0, 0
    if mechanism.closures:
        solver = LoopSolver(mechanism, names, **scene.solver_options())
        q, iterations, residual = solver.close(q, values)
    tasks = scene_tasks(scene)
    _check_frames(scene, mechanism, tasks)
    check_scene_names(scene, mechanism)
    rates = RateSolver(mechanism, tasks, **scene.file.rates.options(),
                       tol=scene.solver_options().get("tol", DEFAULT_TOL),  # the q closed above, to this tol
                       kernel=scene.solver_options().get("kernel", "generic"))
    rs = rates.solve(q)
    accuracy = Accuracy(residual, iterations, rs.condition, rs.sigma_min,
                        max(rs.closure_velocity_residual, rs.velocity_error),
                        max(rs.closure_acceleration_residual, rs.acceleration_error))
    solution = LoopSolution(q=q, v=rs.v, a=rs.a, accuracy=accuracy, drivers=tuple(names))
    points, links = report_lists(scene)
    if points is None:
        points = list(dict.fromkeys(list(mechanism.points) + [t.frame for t in rates.tasks
                                                                if t.frame not in mechanism.links]))
    motion = evaluate_motion(mechanism, rates.data, q, rs.v, rs.a, points=points, links=links,
                             coincident=coincident_points(scene))
    idx = [mechanism.joint(n).idx_v for n in names]
    drivers = Drivers(tuple(names), values, rs.v[idx], rs.a[idx])
    extra = task_sections(rates.tasks, rs, noise_floors(mechanism, rs))
    return Analysis(scene, mechanism, drivers, solution, motion, extra=extra)


def noise_floors(mechanism: Mechanism, rs: RateSolution) -> dict[str, float]:
    """Below these, a task row's value is rounding noise (for the text report only): 1e-12
    of the size of the terms that cancel in J q_dot and J q_ddot + Jdot q_dot."""
    L = mechanism.length_scale
    v = float(np.max(np.abs(rs.v), initial=0.0))
    a = float(np.max(np.abs(rs.a), initial=0.0))
    asked_v = float(np.max(np.abs(rs.requested_velocity), initial=0.0))
    asked_a = float(np.max(np.abs(rs.requested_acceleration), initial=0.0))
    return {
        "m/s": 1e-12 * max(asked_v, L * v),
        "m/s^2": 1e-12 * max(asked_a, L * a, L * v * v),
        "rad/s": 1e-12 * max(asked_v, v),
        "rad/s^2": 1e-12 * max(asked_a, a, v * v),
    }


_NOTES = {
    "exact": "square task, solved exactly",
    "minimum_norm": "redundant task: the minimum-norm joint rates, null space of dimension {null}",
    "least_squares": "least squares, as asked: the rows cannot all hold, see asked vs got",
    "damped": "damped least squares, as asked: the motion got may differ from the one asked",
}


def task_sections(tasks: tuple[Task, ...], rs: RateSolution,
                  floors: dict[str, float] | None = None) -> dict[str, Any]:
    """The JSON `task` section (requested and achieved) and the report's task lines."""
    floors = floors or {}
    width = max(len(t.frame) for t in tasks)
    rows, lines, k = [], [], 0
    for task in tasks:
        for comp in task.components:
            unit_v, unit_a = ("rad/s", "rad/s^2") if comp.startswith("w") else ("m/s", "m/s^2")
            row = {
                "frame": task.frame, "component": comp, "reference": task.reference,
                "requested_velocity": float(rs.requested_velocity[k]),
                "achieved_velocity": float(rs.achieved_velocity[k]),
                "requested_acceleration": float(rs.requested_acceleration[k]),
                "achieved_acceleration": float(rs.achieved_acceleration[k]),
            }
            rows.append(row)
            got_v = _shown(row["achieved_velocity"], floors.get(unit_v, 0.0))
            got_a = _shown(row["achieved_acceleration"], floors.get(unit_a, 0.0))
            lines.append(
                f"  {task.frame:<{width}} {comp:<2} ({task.reference})  velocity asked "
                f"{row['requested_velocity']: .6g} got {got_v} {unit_v};  acceleration asked "
                f"{row['requested_acceleration']: .6g} got {got_a} {unit_a}"
            )
            k += 1
    note = _NOTES[rs.method].format(null=rs.nullspace_dim)
    header = ["", "Task (end-effector rate problem)", "--------------------------------",
              f"  method: {rs.method} ({note})",
              (f"  condition number {rs.condition:.4g}, smallest singular value {rs.sigma_min:.4g} "
               f"(dimensionless); largest |asked - got|: velocity {rs.velocity_error:.3g}, "
               f"acceleration {rs.acceleration_error:.3g}")]
    return {
        "task": {
            "method": rs.method,
            "rank": rs.rank,
            "nullspace_dim": rs.nullspace_dim,
            "condition_number": rs.condition,
            "sigma_min": rs.sigma_min,
            "velocity_error": rs.velocity_error,
            "acceleration_error": rs.acceleration_error,
            "rows": rows,
        },
        "_text": header + lines,
    }


def _shown(x: float, floor: float) -> str:
    return f"{(x if abs(x) > floor else 0.0) + 0.0: .6g}"
