"""The frames `pinmech animate` shows: the solved poses of a driver's cycle, or of a task
followed in time (`[[task]]`, as `pinmech path` follows it), each with its readout (the
driver's value, or the time) and the places of its joints and named points, as the
textbook letters them (pinmech.model.display).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from pinmech.model.display import colour_of, display_names
from pinmech.exceptions import PinmechError

if TYPE_CHECKING:
    from pinmech.model.mechanism import Mechanism
    from pinmech.io.scene import Scene


@dataclass
class Frames:
    """Poses to animate.

    Attributes:
        mechanism: the model they are poses of.
        qs: one closed configuration a frame.
        readouts: one text a frame ("A = 30 deg", "t = 0.010 s").
        title: the scene's title and what moves.
        places: each frame's joints, cuts and named points by printed name, world frame [m].
    """

    mechanism: Mechanism
    qs: list[np.ndarray]
    readouts: list[str]
    title: str
    places: list[dict[str, np.ndarray]] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.qs:
            raise PinmechError("no pose of the range could be closed: nothing to animate")
        self.places = frame_places(self.mechanism, self.qs)

    def traces(self) -> dict[str, tuple[float, float, float]]:
        """The named points (the scene's and the model's) whose paths are drawn, by printed
        name -> the colour of their link."""
        names = display_names(self.mechanism)
        out = {}
        for point in self.mechanism.points:
            shown = names.get(point, point)
            if shown in self.places[0]:
                out[shown] = colour_of(self.mechanism, point)
        return out


def frame_places(mechanism: Mechanism, qs: list[np.ndarray]) -> list[dict[str, np.ndarray]]:
    """Each frame's joints, cuts and named points by printed name, world frame [m]: the
    same names in every frame, chosen at the first (one name a place there, as
    `display.labelled_places`), each then followed on its own link."""
    import pinocchio as pin

    from pinmech.model.link_nodes import sketch_links, world_nodes

    names, sketches = display_names(mechanism), sketch_links(mechanism)
    data = mechanism.model.createData()
    pin.forwardKinematics(mechanism.model, data, qs[0])
    tol = 1e-9 * mechanism.length_scale
    chosen: dict[str, tuple] = {}
    seen: list[np.ndarray] = []
    for key, link in sketches.items():
        for i, (node, p) in enumerate(zip(link.nodes, world_nodes(link, data))):
            name = names.get(node.name, node.name)
            if node.kind == "other" or name in chosen or any(np.linalg.norm(p - x) <= tol for x in seen):
                continue
            chosen[name] = (key, i)
            seen.append(p)
    out = []
    for q in qs:
        pin.forwardKinematics(mechanism.model, data, q)
        nodes = {key: world_nodes(link, data) for key, link in sketches.items()}
        out.append({name: nodes[key][i].copy() for name, (key, i) in chosen.items()})
    return out


def driver_frames(scene: Scene, start: str | None, stop: str | None, steps: int, *,
                  skip_failures: bool = False) -> Frames:
    """A driver's cycle: `steps` poses from `start` to `stop` (text with units; None: the
    scene's value and one turn on, or the mechanism's size for a slide)."""
    from pinmech.io.sweep import DriverValues, Sweep
    from pinmech.units import to_si

    sweep = Sweep.from_scene(scene)
    kind = "angle" if sweep.is_angular else "length"
    first = to_si(start, kind, where="--from") if start else sweep.start  # flags, blamed as flags
    last = to_si(stop, kind, where="--to") if stop else first + (sweep.default_values(2)[1] - sweep.start)
    qs, readouts = [], []
    for pose in sweep.poses(DriverValues(first, last, steps), skip_failures=skip_failures):
        if pose.motion is not None:
            qs.append(sweep.last_q.copy())
            readouts.append(_driver_readout(sweep.driver, pose.value, sweep.is_angular))
    return Frames(sweep.mechanism, qs, readouts, f"{scene.title}: {sweep.driver} driven")


def _driver_readout(driver: str, value: float, angular: bool) -> str:
    return f"{driver} = {math.degrees(value):.1f}°" if angular else f"{driver} = {1000 * value:.2f} mm"


def task_frames(scene: Scene, duration: str | None, steps: int) -> Frames:
    """A task ([[task]]) followed in time over `duration` (text with units; None: the
    scene's [sweep] duration) with the scene's step (default 1 ms), `steps` frames kept
    evenly through it (the last one always)."""
    from pinmech.io.analysis_task import scene_pose, scene_tasks
    from pinmech.solve.path import follow_path, step_count
    from pinmech.io.scene_model import load_mechanism
    from pinmech.io.sweep import sweep_options

    options = sweep_options(scene)
    text = duration or options.get("duration")
    if not text:
        raise PinmechError(f"{scene.path}: say how long to follow the task: --duration '0.08 s' "
                           "(or [sweep] duration = \"0.08 s\")")
    total_time = scene.quantity(text, "time", "--duration")
    step = scene.quantity(options.get("step", "1 ms"), "time", "sweep", "step")
    if not (total_time > 0 and 0 < step <= total_time):
        raise PinmechError(f"need 0 < step <= --duration, got step {step} s, duration {total_time} s")
    mechanism = load_mechanism(scene)
    q0, _, _ = scene_pose(scene, mechanism)
    total = step_count(total_time, step) + 1
    every = max(1, round((total - 1) / max(steps - 1, 1)))
    qs, readouts = [], []
    for k, point in enumerate(follow_path(mechanism, scene_tasks(scene), q0, duration=total_time, step=step,
                                          gain=float(options.get("gain", 0.0)),
                                          scheme=options.get("scheme", "taylor"))):
        if k % every == 0 or k == total - 1:
            qs.append(np.array(point.q, dtype=float))
            readouts.append(f"t = {point.time:.3f} s")
    return Frames(mechanism, qs, readouts, f"{scene.title}: task followed in time")
