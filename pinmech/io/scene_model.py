"""A scene read in its model's terms: the mechanism it loads, its drivers in SI, its guess,
the solver that keeps its assembly, and the names it asks to report.

Everything here is parsed and checked once, at the edge, before anything is solved;
`analysis.py` (driven scenes) and `analysis_task.py` (rate problems) build on it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pinmech.arguments import instance_of
from pinmech.solve.branches import parse_assembly
from pinmech.exceptions import FrameNotFound, MobilityError, ModelError, PinmechError, SceneError
from pinmech.model.mechanism import Mechanism, urdf_joint_types, urdf_mimic_leaders
from pinmech.solve.motion import CoincidentPoint
from pinmech.io.scene import Scene
from pinmech.io.scene_drawn import set_drawn_reference
from pinmech.io.scene_tables import DriverSpec
from pinmech.solve.loops import LoopSolver


@dataclass(frozen=True)
class Drivers:
    """Driver joints and their coordinate [rad or m], rate and acceleration, in SI."""

    names: tuple[str, ...]
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray


def load_mechanism(scene: Scene) -> Mechanism:
    """The scene's model (URDF, linkage, MJCF) as a Mechanism, `[lock]` joints locked out."""
    instance_of(scene, Scene, "load_mechanism's scene")
    kind = scene.model_kind
    path = scene.urdf if kind in ("urdf", "robot") else scene.model_file(kind)
    if not path.is_file():
        raise ModelError(f"the scene's {kind} = \"{getattr(scene.file, kind)}\" is not a file", path=str(scene.path))
    loader = _model_loader(scene, kind, path)
    types = loader.joint_types()
    locked = {}
    for name, value in scene.file.lock.items():
        locked[name] = scene.quantity(value, _kind(types, name), "lock", name)
    if scene.file.move is not None:
        locked.update(_locked_by_move(scene, types, locked))
    try:
        mechanism = loader.load(locked)
    except FrameNotFound as exc:
        if exc.kind != "joint to lock":
            raise
        cuts = tuple(set(types) - set(exc.known))  # a drawn loop's closing pins; a URDF's <constraint>s:
        cuts += _constraint_names(path) if kind in ("urdf", "robot") else ()
        raise FrameNotFound("joint (in [lock])", exc.name, exc.known, path=str(scene.path), cuts=cuts) from None
    add_scene_points(scene, mechanism)
    return mechanism


def _constraint_names(path: Path) -> tuple[str, ...]:
    """Names of a URDF's `<constraint>` loop cuts, read from the XML."""
    from pinmech.model.mechanism import read_xml

    return tuple(c.get("name") for c in read_xml(Path(path), "robot", "URDF").findall("constraint"))


@dataclass(frozen=True)
class _Loader:
    """How to read one kind of model file: its joint types, then the mechanism."""

    joint_types: Any
    load: Any


def _model_loader(scene: Scene, kind: str, path) -> _Loader:
    if kind == "linkage":
        from pinmech.model.linkage_model import joint_kinds, load_linkage

        return _Loader(lambda: joint_kinds(path), lambda locked: load_linkage(path, locked=locked))
    if kind == "mjcf":
        from pinmech.model.mjcf import load_mjcf, mjcf_joint_types

        return _Loader(lambda: mjcf_joint_types(path), lambda locked: load_mjcf(path, locked=locked))
    if scene.file.sidecar is not None:
        from pinmech.model.sidecar import load_extended_urdf

        sidecar = scene.model_file("sidecar")
        return _Loader(lambda: urdf_joint_types(path),
                       lambda locked: load_extended_urdf(path, sidecar, locked=locked))
    return _Loader(lambda: urdf_joint_types(path), lambda locked: Mechanism.from_urdf(path, locked=locked))


def _kind(types: dict[str, str], name: str) -> str:
    return "length" if types.get(name) == "prismatic" else "angle"


def _locked_by_move(scene: Scene, types: dict[str, str], locked: dict[str, float]) -> dict[str, float]:
    """`move = [...]`: every other one-dof joint is locked at its `[pose]` value (else 0)."""
    move = scene.file.move
    movable = [n for n, t in types.items() if t in ("revolute", "continuous", "prismatic")]
    for name in move:
        if name not in movable:
            raise FrameNotFound("joint (in move)", name, movable, path=str(scene.path))
    pose = scene.file.pose
    leaders = urdf_mimic_leaders(scene.urdf)  # a <mimic> follower goes with its leader, moved or locked
    return {
        name: scene.quantity(pose[name], _kind(types, name), "pose", name) if name in pose else 0.0
        for name in movable
        if name not in move and name not in locked and (name not in leaders or name in pose)
        and leaders.get(name) not in move
    }


def _scene_joint(scene: Scene, mechanism: Mechanism, name: str, key: str):
    """A joint the scene names, or FrameNotFound naming the scene file and key."""
    if name not in mechanism.joints:
        raise FrameNotFound(f"joint (in [{key}])", name, list(mechanism.joints), path=str(scene.path),
                            cuts=mechanism.cut_names)
    return mechanism.joints[name]


def scene_drivers(scene: Scene, mechanism: Mechanism) -> Drivers:
    """The `[drivers]` table in SI units, checked against the model's joints. A sidecar's
    motors (robot.yaml's name_mot) drive a scene whose file has no `[drivers]`, at the
    reference pose and at rest; a `--set` on some of them keeps the others so."""
    table = scene.file.drivers
    rows = _default_motors(scene, mechanism, table)
    for name, spec in table.items():
        rows[name] = _driver_row(scene, mechanism, name, spec)
    names = list(rows)
    if len(names) != mechanism.mobility:
        raise MobilityError(f"{scene.path}, drivers: {mechanism.source} has mobility {mechanism.mobility} "
                            f"({mechanism.model.nv} joint freedoms{_held_note(scene, mechanism)}, "
                            f"{mechanism.rank_report().rank} independent closure equations): "
                            f"{'drive that many joints' if mechanism.mobility else 'it cannot move'}; "
                            f"the scene drives {len(names)} "
                            f"({', '.join(names) or 'none'}){_still_free(mechanism, names)}"
                            f"{_motors_note(scene, mechanism, table)}",
                            mobility=mechanism.mobility, drivers=len(names))
    arr = np.array(list(rows.values()), dtype=float).reshape(-1, 3)
    return Drivers(tuple(names), arr[:, 0].copy(), arr[:, 1].copy(), arr[:, 2].copy())


def _held_note(scene: Scene, mechanism: Mechanism) -> str:
    """" once [lock] holds O4" where the scene's locks took freedoms away (else "")."""
    if not mechanism.locked:
        return ""
    by = "[lock] and move" if scene.file.move is not None else "[lock]"
    return f" once {by} holds {', '.join(mechanism.locked)}"


def _lock_lines(mechanism: Mechanism, names: list[str]) -> str:
    """The `[lock]` lines holding `names` at their reference values, in deg or mm."""
    reference = mechanism.neutral()
    lines = []
    for name in names:
        value = mechanism.coordinate(reference, name)
        said = f"{np.degrees(value):.6g} deg" if mechanism.joints[name].is_angular else f"{value * 1e3:.6g} mm"
        lines.append(f'[lock] {name} = "{said}"')
    return "; ".join(lines)


def _file_has_drivers(scene: Scene) -> bool:
    return bool(scene.file.drivers if scene.file_drivers is None else scene.file_drivers)


def _default_motors(scene: Scene, mechanism: Mechanism, table: dict[str, DriverSpec]) -> dict[str, list[float]]:
    """The sidecar's motors at the reference pose, at rest [rad or m], that drive besides
    the table: all of them when the scene file has no `[drivers]` and the table (from
    `--set`) names motors only; none otherwise."""
    motors = mechanism.motors
    if not motors or _file_has_drivers(scene) or not set(table) <= set(motors):
        return {}
    reference = mechanism.neutral()
    return {name: [mechanism.coordinate(reference, name), 0.0, 0.0] for name in motors}


def _driver_row(scene: Scene, mechanism: Mechanism, name: str, spec: DriverSpec) -> list[float]:
    """One `[drivers.NAME]` table as [q, v, a] in SI."""
    if name in mechanism.locked:
        raise SceneError(f"joint '{name}' is both driven and locked", path=str(scene.path), key=f"drivers.{name}")
    joint = _scene_joint(scene, mechanism, name, "drivers")
    if name in mechanism.mimics:
        leader = mechanism.mimics[name].leader
        raise SceneError(f"joint '{name}' follows '{leader}' (URDF <mimic>): drive {leader} instead",
                         path=str(scene.path), key=f"drivers.{name}")
    row = [0.0, 0.0, 0.0]
    for key, order, value in spec.given():
        row[order] = scene.joint_quantity(value, joint.kind, order, "drivers", name, key)
    return row


def _still_free(mechanism: Mechanism, names: list[str]) -> str:
    """What still moves with too few drivers held: the mechanism (an undriven freedom), or
    a joint spinning on its own (a rod about its own axis)."""
    if len(names) >= mechanism.mobility:
        return ""
    from pinmech.model.mobility import moving_joints

    missing = mechanism.mobility - len(names)
    moving = moving_joints(mechanism, names, mechanism.rank_report().q)
    if moving:
        first = next((m for m in mechanism.motors if m in moving), moving[0])
        more = "one more joint" if missing == 1 else f"{missing} more joints"
        held = "with those held" if names else "with no joint driven"
        return (f"; {held}, the mechanism still moves ({', '.join(moving)} move together): drive {more}, "
                f"e.g. {first}")
    free = mechanism.idle_joints(names)
    if not free:
        return ""
    single = [n for n in free if n in mechanism.joints and mechanism.joints[n].nv == 1]
    advice = (f"lock it where it stands ({_lock_lines(mechanism, single)}) or drive it" if len(single) == len(free) else
              "a ball joint cannot be locked by one value: give it two hinges across the rod instead "
              "(a universal joint), or lock or drive a one-freedom joint")
    return (f"; with those held, {', '.join(free)} can still turn on its own, moving no joint's centre (as a rod "
            f"spinning about its own axis): {advice}")


def _motors_note(scene: Scene, mechanism: Mechanism, table: dict[str, DriverSpec]) -> str:
    """Why a sidecar's motors are not among the drivers, when the scene file names none."""
    if not mechanism.motors or _file_has_drivers(scene) or set(table) <= set(mechanism.motors):
        return ""
    others = ", ".join(n for n in table if n not in mechanism.motors)
    return (f" ({Path(scene.file.sidecar).name}'s motors {', '.join(mechanism.motors)} drive a scene without "
            f"[drivers], and a --set on one of them keeps the others; {others} is not a motor, so the drivers "
            "are the ones set)")


def scene_guess(scene: Scene, mechanism: Mechanism) -> np.ndarray:
    """Starting configuration from `[guess]`: it picks the assembly branch."""
    q = mechanism.neutral()
    for name, value in scene.file.guess.items():
        joint = _scene_joint(scene, mechanism, name, "guess")
        if name in mechanism.mimics:
            leader = mechanism.mimics[name].leader
            raise SceneError(f"joint '{name}' follows '{leader}' (URDF <mimic>): give {leader}'s value instead",
                             path=str(scene.path), key=f"guess.{name}")
        mechanism.set_coordinate(q, name, scene.joint_quantity(value, joint.kind, 0, "guess", name))
    return q


def scene_solver(scene: Scene, mechanism: Mechanism, drivers: Drivers) -> LoopSolver:
    """A LoopSolver for the scene, its reference set: the scene file's driver values and
    `[guess]` (with `assembly`, if given, checked), so every pose asked is reached on the
    scene's assembly by continuation. A model drawn closed (a linkage file, MJCF's qpos0)
    without `[guess]` has its drawn pose as the reference.

    Raises:
        SceneError: a malformed `assembly`.
        AssemblyError: the guess closes on another assembly than `assembly` asks.
    """
    solver = LoopSolver(mechanism, drivers.names, **scene.solver_options())
    reference = scene.reference()
    try:
        ref_drivers = scene_drivers(reference, mechanism) if reference is not scene else drivers
    except PinmechError:
        ref_drivers = drivers
    if ref_drivers.names != drivers.names:
        ref_drivers = drivers
    asked = scene.file.assembly
    try:
        assembly = "keep" if asked is None else parse_assembly(asked, solver.structure) or "any"
    except ValueError as exc:
        raise SceneError(str(exc), path=str(scene.path), key="assembly") from None
    if mechanism.reference is not None and not scene.file.guess:
        # a drawn linkage, an MJCF file at qpos0: the pose as drawn is the reference assembly
        set_drawn_reference(solver, mechanism, ref_drivers.q, assembly)
    else:
        solver.set_reference(ref_drivers.q, scene_guess(scene, mechanism), assembly)
    return solver


def coincident_points(scene: Scene) -> list[CoincidentPoint]:
    """`[points.NAME] at = "B", link = "link3"`: points of a link under another point."""
    return [CoincidentPoint(name, spec.at, spec.link) for name, spec in scene.file.points.items() if spec.coincident]


def add_scene_points(scene: Scene, mechanism: Mechanism) -> None:
    """`[points.P] link = "coupler", at = ["60 mm", "30 mm", "0 mm"]`: a point fixed on a link.

    The coordinates are in the link's frame (for a drawn linkage: origin on its parent
    joint, x from its first listed point to the next). Adds the point to the mechanism.
    """
    for name, spec in scene.file.points.items():
        if spec.coincident:
            continue
        key = f"points.{name}"
        link = spec.link
        if link not in mechanism.links:
            raise FrameNotFound(f"link (in [points.{name}])", link, list(mechanism.links), path=str(scene.path))
        if name in mechanism.points or mechanism.model.existFrame(name):
            raise SceneError(f"the model already has a frame called '{name}': name the point otherwise",
                             path=str(scene.path), key=key)
        mechanism.add_point(name, link, np.array(spec.xyz))


def report_lists(scene: Scene) -> tuple[list[str] | None, list[str] | None]:
    """Points and links the scene asks to report (None: all)."""
    return scene.file.report.points, scene.file.report.links


def limit_mode(scene: Scene, asked: str | None = None) -> str:
    """What a joint beyond its URDF limits is: "warn" (default) or "error"; `asked` (the
    command line's --limits) overrides the scene's `[report] limits`."""
    return asked or scene.file.report.limits


def check_scene_names(scene: Scene, mechanism: Mechanism) -> None:
    """The points and links a scene names (`[report]`, `[points.X]`) exist in the model.

    Raises:
        FrameNotFound: naming the scene file and the table the unknown name is in.
    """
    points, links = report_lists(scene)
    coincident = coincident_points(scene)
    where = str(scene.path)
    for name in links or []:
        if name not in mechanism.links:
            raise FrameNotFound("link (in [report] links)", name, list(mechanism.links), path=where)
    for c in coincident:
        if c.link not in mechanism.links:
            raise FrameNotFound(f"link (in [points.{c.name}])", c.link, list(mechanism.links), path=where)
        _frame(mechanism, c.at, f"point (in [points.{c.name}] at)", where)
    for name in points or []:
        if name not in {c.name for c in coincident}:
            _frame(mechanism, name, "point or frame (in [report] points)", where)


def _frame(mechanism: Mechanism, name: str, kind: str, where: str) -> None:
    try:
        mechanism.frame_id(name)
    except FrameNotFound as exc:
        raise FrameNotFound(kind, name, exc.known, path=where) from None
