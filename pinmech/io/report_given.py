"""The "Given" of a lab report, read from a solved scene: the model's dimensions, each driver
with its sense and rates, gravity, loads and the assumptions the numbers rest on.

Everything is read from the model and the scene (nothing is typed twice); lengths in mm,
angles in degrees, rates in rad/s and rpm, as a problem statement writes them.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinmech.model.display import display_names
from pinmech.model.link_nodes import sketch_links
from pinmech.io.analysis_result import Analysis

RPM = 30.0 / math.pi  # rpm per rad/s


def given(analysis: Analysis) -> list[tuple[str, list[str]]]:
    """(heading, lines) of the Given section, in a problem statement's order."""
    return [("Mechanism", _mechanism(analysis)), ("Dimensions", dimensions(analysis)),
            ("Driver", drivers(analysis)), ("Gravity and loads", loads(analysis)),
            ("Assumptions", assumptions(analysis))]


def _mechanism(analysis: Analysis) -> list[str]:
    mech = analysis.mechanism
    plane = ("planar, moving in the plane normal to " + _xyz(mech.plane_normal)) if mech.plane_normal is not None \
        else "spatial"
    moving = sum(not link.is_ground for link in sketch_links(mech).values())
    return [f"{analysis.scene.title}: model {Path(str(mech.source)).name}, {moving} moving links, "
            f"{len(mech.closures)} closed loop(s), {plane}"]


def dimensions(analysis: Analysis) -> list[str]:
    """Each link's distances between its pins and points [mm], the ground's between its pivots."""
    mech = analysis.mechanism
    names = display_names(mech)
    out = []
    for link in sketch_links(mech).values():
        nodes = [n for n in link.nodes if n.kind in ("revolute", "point")]
        pairs = [f"{names.get(a.name, a.name)}{names.get(b.name, b.name)} = "
                 f"{1000 * float(np.linalg.norm(a.position - b.position)):.6g} mm"
                 for a, b in itertools.combinations(nodes, 2)]
        if pairs:
            out.append(f"{'ground (fixed pivots)' if link.is_ground else link.name}: " + ", ".join(pairs))
    return out or ["no pins or points to measure between"]


def drivers(analysis: Analysis) -> list[str]:
    """Each driver: its value, speed and acceleration, and the sense of its speed."""
    mech, d = analysis.mechanism, analysis.drivers
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, analysis.solution.q)
    out = []
    for name, q, v, a in zip(d.names, d.q, d.v, d.a):
        joint = mech.joints[name]
        if joint.is_angular:
            out.append(f"{name} (revolute, {joint.parent_link} to {joint.child_link}): angle {math.degrees(q):.6g} deg, "
                       f"speed {v:.6g} rad/s ({v * RPM:.6g} rpm){_sense(mech, data, joint, v)}, "
                       f"acceleration {a:.6g} rad/s²")
        else:
            out.append(f"{name} ({joint.kind}, {joint.parent_link} to {joint.child_link}): {1000 * q:.6g} mm, "
                       f"speed {v:.6g} m/s along {_xyz(_world_axis(data, joint))}, acceleration {a:.6g} m/s²")
    return out or ["no driver: the scene follows a task"]


def _world_axis(data: pin.Data, joint) -> np.ndarray:
    return data.oMi[joint.id].rotation @ np.asarray(joint.axis, dtype=float)


def _sense(mech, data: pin.Data, joint, v: float) -> str:
    """", counter-clockwise seen from +z" for a revolute driver of a planar mechanism."""
    if mech.plane_normal is None or v == 0:
        return ""
    turn = v * float(mech.plane_normal @ _world_axis(data, joint))
    return f", {'counter-clockwise' if turn > 0 else 'clockwise'} seen from {_xyz(mech.plane_normal)}"


def loads(analysis: Analysis) -> list[str]:
    """Gravity and the scene's loads, or that the scene asks no forces."""
    scene = analysis.scene
    if not scene.file.wants_forces:
        return ["none: a kinematic analysis (no [forces], [gravity] or [[load]] in the scene)"]
    from pinmech.io.forces_scene import force_settings

    settings = force_settings(scene)
    g = float(np.linalg.norm(settings.gravity))
    out = [f"gravity {g:.6g} m/s² along {_xyz(settings.gravity / g)}" if g else "no gravity"]
    for load in settings.loads:
        parts = [f"force {_xyz(load.force)} N" if np.any(load.force) else "",
                 f"torque {_xyz(load.torque)} N·m" if np.any(load.torque) else ""]
        out.append(f"load {load.name} at {load.at}: " + ", ".join(p for p in parts if p))
    return out


def assumptions(analysis: Analysis) -> list[str]:
    """What the numbers rest on."""
    out = ["rigid links; ideal joints (no clearance, no friction, no elasticity)",
           "the drivers' speeds and accelerations as given, at this one pose",
           "angles and rates counter-clockwise positive about the plane's normal; vectors in the world frame, SI"]
    if analysis.scene.file.wants_forces:
        out.append("masses and inertias from the model (links listed massless in [forces] excepted)")
    return out


def _xyz(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in np.asarray(v, dtype=float).ravel()) + ")"
