"""The `forces` section of a report: JSON (SI, world frame) and text lines."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pinmech.solve.forces import ForceSolution, Reaction
from pinmech.model.mechanism import Mechanism


def _vec(x: np.ndarray) -> list[float]:
    return [float(c) for c in np.asarray(x).reshape(-1)]


def _effort_unit(mechanism: Mechanism, driver: str) -> str:
    return "N m" if mechanism.joint(driver).is_angular else "N"


def reaction_dict(r: Reaction, plane_normal: np.ndarray | None) -> dict[str, Any]:
    """One joint's or cut's reaction: the force `by` exerts `on` [N], its moment about
    `point` [N m], magnitude, direction angle in the plane [rad] (planar only)."""
    out: dict[str, Any] = {
        "by": r.by, "on": r.on, "type": r.kind, "cut": r.is_cut, "point": _vec(r.point),
        "force": _vec(r.force), "moment": _vec(r.moment), "magnitude": r.magnitude,
        "angle": r.angle(plane_normal),
    }
    if r.kind == "prismatic":
        out["normal_force"] = _vec(r.normal_force)
        out["axial_force"] = r.axial_force
    elif r.kind in ("revolute", "continuous"):
        out["axial_moment"] = r.axial_moment
    return out


def forces_dict(f: ForceSolution, mechanism: Mechanism, *, static: bool) -> dict[str, Any]:
    """The JSON `forces` section."""
    p = f.power
    return {
        "gravity": _vec(f.gravity),
        "static": static,
        "method": f.method,
        "drivers": {n: {"effort": float(e), "unit": _effort_unit(mechanism, n)} for n, e in zip(f.drivers, f.effort)},
        "reactions": {n: reaction_dict(r, mechanism.plane_normal) for n, r in f.reactions.items()},
        "power": {"driver": p.driver_power, "gravity": p.gravity_power, "loads": p.load_power,
                  "kinetic_rate": p.kinetic_rate, "velocity": p.velocity, "residual": p.residual},
        "condition_number": f.condition,
        "equation_residual": f.equation_residual,
    }


def _num(x: float) -> str:
    return f"{x + 0.0: .6g}"


def _vector(x: np.ndarray, planar_z: bool, unit: str, size: float) -> str:
    floor = 1e-12 * size
    parts = x[:2] if planar_z else x
    return "(" + ", ".join(_num(c if abs(c) > floor else 0.0) for c in parts) + f") {unit}"


def forces_text(f: ForceSolution, mechanism: Mechanism, *, static: bool, loads: list[str],
                advantage: tuple[float | None, str] = (None, "")) -> list[str]:
    """Report lines: what was assumed, driver efforts, reactions, the power balance."""
    normal = mechanism.plane_normal
    planar_z = normal is not None and abs(abs(normal[2]) - 1.0) < 1e-12
    g = float(np.linalg.norm(f.gravity))
    gravity = f"gravity {g:.6g} m/s^2 along {_vector(f.gravity / g, planar_z, '', 1.0).strip()}" if g else "gravity off"
    mode = "statics (speeds and accelerations zero)" if static else "dynamics at the pose's speeds and accelerations"
    lines = ["", "Forces", "------", f"  {mode}; {gravity}; loads: {', '.join(loads) or 'none'}"]
    if f.method != "exact":
        lines.append("  minimum-norm reactions (the loops are redundant: one choice among many)")
    for name, effort in zip(f.drivers, f.effort):
        kind = "torque" if mechanism.joint(name).is_angular else "force"
        lines.append(f"  {name:<10} driver {kind} = {_num(effort)} {_effort_unit(mechanism, name)}")
    if advantage[0] is not None:
        lines.append(f"  mechanical advantage |load| / |{f.drivers[0]} effort| = {advantage[0]:.6g} {advantage[1]}")
    lines += ["", "Joint reactions (force of the first link on the second, world frame)",
              "-------------------------------------------------------------------"]
    size = max((r.magnitude for r in f.reactions.values()), default=0.0)
    width = max((len(r.by) + len(r.on) + 4 for r in f.reactions.values()), default=0)
    for name, r in f.reactions.items():
        label = f"{name} (cut)" if r.is_cut else name
        cells = [f"{r.by + ' on ' + r.on:<{width}}", "F = " + _vector(r.force, planar_z, "N", size), f"|F| = {_num(r.magnitude)} N"]
        angle = r.angle(normal)
        if angle is not None and r.magnitude > 1e-12 * size:
            cells.append(f"at {_num(math.degrees(angle))} deg")
        if r.kind == "prismatic":
            about = f"frame on {r.on}" if r.is_cut else "origin"  # where a cut's wrench acts
            moment = float(normal @ r.moment) if normal is not None else float(np.linalg.norm(r.moment))
            moment = moment if abs(moment) > 1e-12 * size * mechanism.length_scale else 0.0  # rounding noise
            cells = cells[:1] + ["normal " + _vector(r.normal_force, planar_z, "N", size),
                                 f"moment {_num(moment)} N m (about {name}'s {about})"]
        lines.append(f"  {label:<10} " + "   ".join(cells))
    p = f.power
    lines += ["", (f"  power balance ({p.velocity} velocities): drivers {p.driver_power:.6g} W + gravity "
                   f"{p.gravity_power:.6g} W + loads {p.load_power:.6g} W = dT/dt {p.kinetic_rate:.6g} W, "
                   f"residual {p.residual:.1e}; equations residual {f.equation_residual:.1e}, "
                   f"condition number {f.condition:.4g}")]
    return lines
