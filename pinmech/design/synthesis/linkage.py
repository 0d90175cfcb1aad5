"""A synthesised four-bar (slider-crank, inverted slider-crank) written as a drawn linkage
(models/linkages/*.toml) with a scene that sweeps its crank through the targets, and checked
by the engine: the scene solved by continuation from the first target's pose, the coupler
point read at every target.

The drawn linkage is written by the drawn linkage's own writer (model/linkage_write.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pinmech.angles import turn_radians
from pinmech.design.synthesis.kinematics import kinematics
from pinmech.design.synthesis.written import deg_text, mm_text, targets_text
from pinmech.design.synthesis.result import Linkage
from pinmech.outputs import write_whole

_STEP = math.radians(1.0)  # the engine's sweep: at most this crank step between poses


def _mm(v: float) -> str:
    return mm_text(v)


def _deg(v: float) -> str:
    return f"\"{deg_text(v)}\""


def linkage_toml(lk: Linkage, title: str, source: str) -> str:
    """The drawn linkage's TOML text (model.linkage_write): joints at the first target's
    pose (crank at theta_1)."""
    from pinmech.model.linkage_spec import linkage_spec
    from pinmech.model.linkage_write import linkage_toml as written

    p = kinematics(lk.topology).pose(lk.z[None], np.array([lk.s]), lk.theta[:1][None])
    A, P = p.A[0, 0], p.P[0, 0]
    z = lk.z
    path = lk.task != "function"
    slider = lk.topology == "slider-crank"
    what = {"path": "the coupler point P through the targets", "motion": "the coupler through the poses",
            "function": "the slider's travel" if slider else "the rocker's turns"}[lk.task]
    if lk.topology == "inverted-slider-crank":
        from pinmech.design.synthesis.inverted_write import inverted_tables

        what = what.replace("rocker", "guide").replace("coupler", "block")
        header = (f"Synthesised by `pinmech synth {source}`: {what}.\n"
                  f"Drawn at the first target's pose (crank O2 at {math.degrees(motion_values(lk)[0]):.6g} deg from x).")
        return written(linkage_spec(inverted_tables(lk, title), source), header)
    if slider:
        B = p.B[0, 0]
        joints = {"O2": [_mm(z[0]), _mm(z[1])], "A": [_mm(A[0]), _mm(A[1])], "B": [_mm(B[0]), _mm(B[1])]}
        if path:
            joints["P"] = [_mm(P[0]), _mm(P[1])]
        raw = {"title": title, "ground": ["O2"], "joints": joints,
               "links": {"crank": ["O2", "A"], "rod": ["A", "B", "P"] if path else ["A", "B"], "piston": ["B"]},
               "sliders": {"slide": {"block": "piston", "on": "ground", "at": "B",
                                     "along": deg_text(z[2])}}}
        header = (f"Synthesised by `pinmech synth {source}`: {what}.\n"
                  f"Drawn at the first target's pose (crank O2 at {math.degrees(motion_values(lk)[0]):.6g} deg from x).")
        return written(linkage_spec(raw, source), header)
    raw = {"title": title, **four_bar_tables(lk, path)}
    header = (f"Synthesised by `pinmech synth {source}`: {what}.\n"
              f"Drawn at the first target's pose (crank O2 at {math.degrees(motion_values(lk)[0]):.6g} deg from x).")
    return written(linkage_spec(raw, source), header)


def four_bar_tables(lk: Linkage, path: bool) -> dict:
    """A four-bar's drawn-linkage tables with its dimensions as `[params]` (the search's
    names: O2x, O2y, O4x, O4y, crank, coupler, rocker, and a path's or a motion's coupler
    point P as its distances AP, BP from A and B, left or right of A -> B), drawn at the
    first target's crank angle: edit a param and the drawing follows."""
    z = lk.z
    names = ("O2x", "O2y", "O4x", "O4y", "crank", "coupler", "rocker")
    params = {n: _mm(v) for n, v in zip(names, z[:7])}
    joints = {"O2": ["O2x", "O2y"], "O4": ["O4x", "O4y"],
              "A": {"from": "O2", "length": "crank", "angle": deg_text(motion_values(lk)[0])},
              "B": {"from": ["A", "O4"], "lengths": ["coupler", "rocker"], "side": "left" if lk.s > 0 else "right"}}
    if path:
        along, across = float(z[7]), float(z[8])
        params["AP"], params["BP"] = _mm(math.hypot(along, across)), _mm(math.hypot(z[5] - along, across))
        joints["P"] = {"from": ["A", "B"], "lengths": ["AP", "BP"], "side": "left" if across >= 0 else "right"}
    return {"ground": ["O2", "O4"], "params": params, "joints": joints,
            "links": {"crank": ["O2", "A"], "coupler": ["A", "B", "P"] if path else ["A", "B"], "rocker": ["O4", "B"]}}


def motion_values(lk: Linkage) -> np.ndarray:
    """The crank's angles at the targets [rad] along the motion: the first in [0, 2 pi)
    (the convention of every crank angle pinmech reports), the others unwrapped from it
    the way the crank turns (a sweep from 349.3 to 366.4 deg turns counter-clockwise
    through 0)."""
    steps = np.mod(lk.way * np.diff(lk.theta), 2 * math.pi)
    return turn_radians(float(lk.theta[0])) + lk.way * np.concatenate(([0.0], np.cumsum(steps)))


def scene_toml(lk: Linkage, linkage_file: str, title: str, targets=None) -> str:
    """A scene of the linkage: the crank O2 driven from the first target's angle, its
    sweep over the motion to the last target; a path's or motion's target places [m] (N, 2)
    written beside it, for the paths figure (`[sweep] targets`)."""
    values = motion_values(lk)
    steps = int(math.ceil(abs(values[-1] - values[0]) / _STEP)) + 1
    shown = {"path": "points = [\"P\"]", "motion": "points = [\"P\"]\nlinks = [\"coupler\"]",
             "function": "links = [\"rocker\"]"}[lk.task]
    if lk.topology == "slider-crank":
        shown = {"path": "points = [\"B\", \"P\"]", "motion": "points = [\"B\", \"P\"]\nlinks = [\"rod\"]",
                 "function": "points = [\"B\"]"}[lk.task]
    if lk.topology == "inverted-slider-crank":
        shown = {"path": "points = [\"A\", \"P\"]", "motion": "points = [\"A\", \"P\"]\nlinks = [\"block\"]",
                 "function": "links = [\"guide\"]"}[lk.task]
    return "\n".join([
        "# The synthesised linkage swept through its targets:",
        "#   pinmech sweep THIS_FILE --plot fig.png",
        f"title = \"{title}\"",
        f"linkage = \"{linkage_file}\"",
        "",
        "[drivers.O2]",
        f"angle = {_deg(values[0])}",
        "",
        "[sweep]",
        f"from = {_deg(values[0])}",
        f"to = {_deg(values[-1])}",
        f"steps = {steps}",
        shown,
        *([targets_text("P", targets)] if targets is not None and lk.task in ("path", "motion") else []),
        "",
        "[report]",
        shown,
        "",
    ])


def write_linkage(lk: Linkage, prefix: str | Path, title: str, source: str, targets=None) -> tuple[Path, Path]:
    """PREFIX.toml (the drawn linkage) and PREFIX_scene.toml (its sweep, with the task's
    target places [m] (N, 2) when given); their paths."""
    prefix = Path(prefix)
    linkage, scene = prefix.with_name(prefix.name + ".toml"), prefix.with_name(prefix.name + "_scene.toml")
    write_whole(linkage, linkage_toml(lk, title, source))
    write_whole(scene, scene_toml(lk, linkage.name, title, targets))
    return linkage, scene


@dataclass(frozen=True)
class EngineCheck:
    """The engine's coupler point at each target's crank angle [m] (a function: the rocker's
    angle [rad]), solved by continuation from the first target's pose on the drawn assembly,
    and its distance to the targets [m] (the angle errors [rad])."""

    points: np.ndarray
    errors: np.ndarray
    angle_errors: np.ndarray | None = None  # a motion's coupler angles against the poses' [rad]
    drift: float | None = None  # path, motion: the engine's P against the synthesis's own [m], at most


def engine_check(scene_file: str | Path, lk: Linkage, targets: np.ndarray,
                 angles: np.ndarray | None = None) -> EngineCheck:
    """Solve the written scene through the motion with the engine (pinmech sweep's path),
    poses at most _STEP apart, and read P at the targets.

    Raises:
        SweepError: the engine could not follow the motion (a fold, no closure).
    """
    from pinmech.io.scene import Scene
    from pinmech.io.sweep import Sweep

    values = motion_values(lk)
    dense = [values[0]]
    for a, b in zip(values[:-1], values[1:]):
        n = int(math.ceil(abs(b - a) / _STEP))
        dense += list(np.linspace(a, b, n + 1)[1:])
    at = {int(np.argmin(np.abs(np.asarray(dense) - v))) for v in values}
    sweep = Sweep.from_scene(Scene.load(scene_file))
    poses = [p.motion for p in sweep.poses(np.asarray(dense)) if p.index in at]
    if lk.task != "function":
        P = np.array([m.points["P"].position[:2] for m in poses])
        own = kinematics(lk.topology).pose(lk.z[None], np.array([lk.s]), lk.theta[None]).P[0]
        drift = float(np.max(np.linalg.norm(P - own, axis=1)))
        if lk.task == "path":
            return EngineCheck(P, np.linalg.norm(P - targets, axis=1), drift=drift)
        coupler = {"slider-crank": "rod", "inverted-slider-crank": "block"}.get(lk.topology, "coupler")
        turn = np.array([m.links[coupler].angle for m in poses]) + lk.phi0 - angles
        return EngineCheck(P, np.linalg.norm(P - targets, axis=1), np.abs(np.mod(turn + math.pi, 2 * math.pi) - math.pi),
                           drift)
    if lk.topology == "slider-crank":  # the block's place along the slide from H, against the travel asked
        from pinmech.design.synthesis.slider import slide_position

        B = np.array([m.points["B"].position[:2] for m in poses])
        x = slide_position(lk.z[None], B[None])[0]
        return EngineCheck(x, np.abs(x - (lk.phi0 + targets[:, 1])))
    output = "guide" if lk.topology == "inverted-slider-crank" else "rocker"
    phi = np.array([m.links[output].angle for m in poses])
    wanted = lk.phi0 + targets[:, 1]  # the rocker's angles asked: its start plus the pairs' turns
    return EngineCheck(phi, np.abs(np.mod(phi - wanted + math.pi, 2 * math.pi) - math.pi))
