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
from pinmech.solve.loops import DEFAULT_TOL, SOLVER_RANGES, LoopSolver
from pinmech.solve.rates import COMPONENTS, DAMPING_RANGE, METHODS, RateSolver, Task

_ORDER_KINDS = {True: ("angular_velocity", "angular_acceleration"), False: ("velocity", "acceleration")}


def scene_tasks(scene: Scene) -> list[Task]:
    """The `[[task]]` entries, in SI units."""
    entries = scene.raw["task"]
    if not isinstance(entries, list) or not entries:
        raise SceneError("task must be an array of tables: [[task]]", path=str(scene.path), key="task")
    return [_task(scene, entry, i) for i, entry in enumerate(entries)]


def _task(scene: Scene, entry: Any, i: int) -> Task:
    where = f"task[{i}]"
    if not isinstance(entry, dict):
        raise SceneError("must be a table", path=str(scene.path), key=where)
    unknown = set(entry) - {"frame", "components", "velocity", "acceleration", "reference"}
    missing = {"frame", "components", "velocity"} - set(entry)
    if unknown or missing:
        raise SceneError(f"unknown keys {sorted(unknown)} / missing keys {sorted(missing)}; a task has frame, "
                         "components, velocity, acceleration (optional) and reference (optional)",
                         path=str(scene.path), key=where)
    comps = entry["components"]
    if not isinstance(comps, list) or not all(c in COMPONENTS for c in comps):
        raise SceneError(f"components {comps!r} must be a list of {', '.join(COMPONENTS)}",
                         path=str(scene.path), key=f"{where}.components")
    values = {}
    for order, key in enumerate(("velocity", "acceleration")):
        given = entry.get(key, [0] * len(comps))
        if not isinstance(given, list) or len(given) != len(comps):
            raise SceneError(f"{key} needs one quantity per component ({len(comps)})",
                             path=str(scene.path), key=f"{where}.{key}")
        values[key] = np.array([
            scene.quantity(x, _ORDER_KINDS[c.startswith("w")][order], where, key, c) for x, c in zip(given, comps)
        ])
    reference = entry.get("reference", "world")
    if reference not in ("world", "local"):
        raise SceneError(f"reference must be \"world\" or \"local\" (the frame's own axes), got {reference!r}",
                         path=str(scene.path), key=f"{where}.reference")
    return Task(str(entry["frame"]), tuple(comps), values["velocity"], values["acceleration"], reference)


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
    for name, value in scene.section("pose").items():
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


def _rate_options(scene: Scene) -> dict[str, Any]:
    options = scene.section("rates")
    unknown = set(options) - {"method", "damping", "max_condition"}
    if unknown:
        raise SceneError(f"unknown key(s) {sorted(unknown)}; known: method, damping, max_condition",
                         path=str(scene.path), key="rates")
    ranges = {"damping": DAMPING_RANGE, "max_condition": SOLVER_RANGES["max_condition"]}
    for key, value in options.items():
        number = key != "method"
        if (number and (isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0)) or (
                not number and not isinstance(value, str)):
            raise SceneError(f"must be {'a positive number' if number else 'a string'}, got {value!r}",
                             path=str(scene.path), key=f"rates.{key}")
        if number and not ranges[key][0] <= value <= ranges[key][1]:
            raise SceneError(f"rates.{key} = {value!r} is outside [{ranges[key][0]:g}, {ranges[key][1]:g}]",
                             path=str(scene.path), key=f"rates.{key}")
        if not number and value not in METHODS:  # a scene's misspelling, not an inconsistent task (8)
            raise SceneError(f"must be one of {', '.join(METHODS)}, got {value!r}", path=str(scene.path),
                             key="rates.method")
    return dict(options)


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
    rates = RateSolver(mechanism, tasks, **_rate_options(scene),
                       tol=scene.solver_options().get("tol", DEFAULT_TOL))  # the q closed above, to this tol
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
