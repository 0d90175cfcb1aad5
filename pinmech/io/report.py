"""Reports of a solved scene: readable text in the textbook's order, and JSON in SI units."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pinmech.arguments import instance_of
from pinmech.solve.certify import NOT_CERTIFIED
from pinmech.solve.limits import limit_violations
from pinmech.solve.motion import Motion
from pinmech.io.analysis_result import Analysis


def _vec(x: np.ndarray) -> list[float]:
    return [float(c) for c in np.asarray(x).reshape(-1)]


def _number(x: float | np.ndarray) -> float | list[float]:
    return x if isinstance(x, float) else _vec(x)


def motion_dict(motion: Motion) -> dict[str, Any]:
    """The `joints`, `links`, `points` and `sliders` sections (SI, world frame)."""
    links = {}
    for name, link in motion.links.items():
        entry: dict[str, Any] = {
            "angular_velocity": _vec(link.angular_velocity),
            "angular_acceleration": _vec(link.angular_acceleration),
        }
        if link.angle is not None:
            entry["angle"] = link.angle
            if link.angle_axis != "x":
                entry["angle_axis"] = link.angle_axis  # the link's x axis is normal to the plane
        links[name] = entry
    return {
        "joints": {n: {"q": _number(j.q), "v": _number(j.v), "a": _number(j.a), "type": j.kind}
                   for n, j in motion.joints.items()},
        "links": links,
        "points": {
            n: {"position": _vec(p.position), "velocity": _vec(p.velocity), "acceleration": _vec(p.acceleration),
                "link": p.link}
            for n, p in motion.points.items()
        },
        "sliders": {
            n: {
                "parent": s.parent,
                "child": s.child,
                "relative_velocity": _vec(s.relative_velocity),
                "relative_acceleration": _vec(s.relative_acceleration),
                "coriolis_acceleration": _vec(s.coriolis_acceleration),
                "axis": _vec(s.axis),
                "s": s.s,
                "s_dot": s.s_dot,
                "s_ddot": s.s_ddot,
            }
            for n, s in motion.sliders.items()
        },
    }


def to_dict(analysis: Analysis) -> dict[str, Any]:
    """One JSON-ready object for a solved scene (SI units, vectors [x, y, z] in the world frame)."""
    instance_of(analysis, Analysis, "to_dict's analysis")
    out: dict[str, Any] = {
        "title": analysis.scene.title,
        "scene": str(analysis.scene.path),
        "urdf": str(analysis.mechanism.source),
        "units": "SI: m, rad, s; vectors [x, y, z] in the world frame",
        "drivers": {
            n: {"q": float(q), "v": float(v), "a": float(a)}
            for n, q, v, a in zip(analysis.drivers.names, analysis.drivers.q, analysis.drivers.v, analysis.drivers.a)
        },
    }
    out.update(motion_dict(analysis.motion))
    out["limit_violations"] = [v.as_dict() for v in limit_violations(analysis.mechanism, analysis.motion)]
    out.update(assembly_dict(analysis))
    out["accuracy"] = analysis.solution.accuracy.as_dict()
    if analysis.extra:
        out.update({k: v for k, v in analysis.extra.items() if not k.startswith("_")})
    if _has_design(analysis):
        from pinmech.solve.diagnostics import design_dict

        out["design"] = design_dict(scene_design(analysis))
    return out


def scene_design(analysis: Analysis):
    """The scene's design diagnostics (design.py), with the rates per unit driver rate of a
    one-driver planar mechanism for its mechanical advantage."""
    from pinmech.solve.diagnostics import analysis_design
    from pinmech.solve.loops import LoopSolver

    names = list(analysis.drivers.names)
    unit = None
    if analysis.mechanism.plane_normal is not None and len(names) == 1:
        solver = LoopSolver(analysis.mechanism, names, **analysis.scene.solver_options())
        unit, _, _ = solver.rates(analysis.solution.q, [1.0], [0.0])
    return analysis_design(analysis, unit)


def _has_design(analysis: Analysis) -> bool:
    """Design diagnostics belong to driven mechanisms, not to [[task]] scenes."""
    return not (analysis.extra and "task" in analysis.extra)


def assembly_dict(analysis: Analysis) -> dict[str, Any]:
    """The assembly (per loop block: sign and label), how the pose was reached, and
    whether the scene pins its assembly ([guess] or assembly)."""
    sol = analysis.solution
    if sol.assembly is None:
        return {}
    out: dict[str, Any] = {"assembly": sol.assembly.as_dict(), "assembly_pinned": _pinned(analysis)}
    route = sol.route
    if route is not None:
        out["route"] = {
            "from": dict(zip(analysis.drivers.names, map(float, route.start))),
            "continuation_steps": route.steps,
            "change_points": [dict(zip(analysis.drivers.names, map(float, x))) for x in route.change_points],
        }
    return out


def _pinned(analysis: Analysis) -> bool:
    return bool(analysis.scene.file.guess) or analysis.scene.file.assembly is not None


def to_json(analysis: Analysis) -> str:
    """`to_dict` as indented JSON text (non-finite numbers become null)."""
    instance_of(analysis, Analysis, "to_json's analysis")
    import json  # here: a text report does not need it

    return json.dumps(_finite(to_dict(analysis)), indent=2)


def _finite(x: Any) -> Any:
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_finite(v) for v in x]
    return x


# ---------------------------------------------------------------------- text
def _num(x: float) -> str:
    return f"{x + 0.0: .6g}"  # + 0.0 turns -0.0 into 0.0


class _Text:
    """Formats vectors as (x, y) for a mechanism moving in the world xy plane, else (x, y, z)."""

    def __init__(self, analysis: Analysis) -> None:
        normal = analysis.mechanism.plane_normal
        self.planar_z = normal is not None and abs(abs(normal[2]) - 1.0) < 1e-12
        self.lines: list[str] = []
        # Per unit, the largest point vector reported: what rounding noise is measured against.
        points = analysis.motion.points.values()
        self.sizes = {
            unit: max((float(np.max(np.abs(getattr(p, attr)), initial=0.0)) for p in points), default=0.0)
            for unit, attr in (("m", "position"), ("m/s", "velocity"), ("m/s^2", "acceleration"))
        }

    def vec(self, x: np.ndarray, unit: str) -> str:
        parts = x[:2] if self.planar_z else x
        # Components below 1e-12 of the vector's size, or of the largest point vector of the
        # same unit, are rounding noise (cos 90 deg = 6e-17; a_D = 0 computed as 9e-16).
        floor = 1e-12 * max(float(np.max(np.abs(x), initial=0.0)), self.sizes.get(unit, 0.0))
        return "(" + ", ".join(_num(c if abs(c) > floor else 0.0) for c in parts) + f") {unit}"

    def norm(self, x: np.ndarray, unit: str) -> str:
        size = float(np.linalg.norm(x))
        return f"{_num(size if size > 1e-12 * self.sizes.get(unit, 0.0) else 0.0)} {unit}"

    def spin(self, w: np.ndarray, unit: str) -> str:
        return f"{_num(w[2])} {unit} (k)" if self.planar_z else self.vec(w, unit)

    def head(self, title: str) -> None:
        self.lines += ["", title, "-" * len(title)]

    def row(self, name: str, *cells: str) -> None:
        self.lines.append(f"  {name:<10} " + "   ".join(cells))


def to_text(analysis: Analysis) -> str:
    """A readable report in the textbook's order: positions, angles, link rates, points, sliders."""
    instance_of(analysis, Analysis, "to_text's analysis")
    m = analysis.motion
    t = _Text(analysis)
    drivers = ", ".join(f"{n} = {_angle_or_length(analysis, n, q)}" for n, q in zip(analysis.drivers.names, analysis.drivers.q))
    label = "pose" if analysis.extra and "task" in analysis.extra else "drivers"
    t.lines += [f"{analysis.scene.title}", f"model {analysis.mechanism.source}", f"{label}: {drivers}"]
    t.head("Positions")
    for name, p in m.points.items():
        t.row(name, t.vec(p.position, "m"), f"on {p.link}")
    if any(link.angle is not None for link in m.links.values()):
        t.head("Link angles (x axis from world x)")
        for name, link in m.links.items():
            if link.angle is not None:
                axis = "" if link.angle_axis == "x" else f"   (its {link.angle_axis} axis: x is normal to the plane)"
                t.row(name, f"phi = {_num(math.degrees(link.angle))} deg = {_num(link.angle)} rad{axis}")
    t.head("Angular velocities and accelerations")
    for name, link in m.links.items():
        t.row(name, "omega = " + t.spin(link.angular_velocity, "rad/s"), "alpha = " + t.spin(link.angular_acceleration, "rad/s^2"))
    t.head("Velocities of points")
    for name, p in m.points.items():
        t.row(name, "v = " + t.vec(p.velocity, "m/s"), "|v| = " + t.norm(p.velocity, "m/s"))
    t.head("Accelerations of points")
    for name, p in m.points.items():
        t.row(name, "a = " + t.vec(p.acceleration, "m/s^2"), "|a| = " + t.norm(p.acceleration, "m/s^2"))
    if m.sliders:
        t.head("Sliders (child relative to parent)")
        for name, s in m.sliders.items():
            t.row(name, f"{s.child} on {s.parent}")
            t.row("", "v_rel = " + t.vec(s.relative_velocity, "m/s"))
            t.row("", "a_rel = " + t.vec(s.relative_acceleration, "m/s^2"))
            t.row("", "a_cor = 2 omega x v_rel = " + t.vec(s.coriolis_acceleration, "m/s^2"))
    t.head("Joints")
    for name, j in m.joints.items():
        t.row(name, *_joint_cells(j.kind, j.q, j.v, j.a))
    violations = limit_violations(analysis.mechanism, analysis.motion)
    if violations:
        t.head("Joint limits")
        t.lines += [f"  WARNING: {v.describe()}" for v in violations]
    _assembly_lines(t, analysis)
    t.head("Accuracy")
    t.lines.append(_accuracy_line(analysis))
    for line in (analysis.extra or {}).get("_text", []):
        t.lines.append(line)
    if _has_design(analysis):
        from pinmech.solve.diagnostics import design_lines

        t.lines += design_lines(scene_design(analysis))
    return "\n".join(t.lines) + "\n"


def _accuracy_line(analysis: Analysis) -> str:
    """The closure residual and Newton iterations of a mechanism with loops (an open chain
    has neither: its pose is the scene's), the condition number and the error bounds."""
    acc = analysis.solution.accuracy
    if analysis.mechanism.closures:
        closure = (f"closure residual {acc.residual:.2g} (of each loop's size; the largest loop spans "
                   f"{analysis.mechanism.length_scale:.4g} m), {acc.iterations} Newton iterations, ")
    else:
        closure = "an open chain (no loop to close: the pose is the scene's), "
    if not acc.certified:
        return f"  {closure}condition number {NOT_CERTIFIED} (its residuals checked; no error bound stated)"
    bounds = (max(b, 1e-16) for b in acc.error_bounds)
    return (f"  {closure}condition number {acc.condition:.4g} "
            "(worst-case relative error about {:.0e} in positions, {:.0e} in velocities, {:.0e} in "
            "accelerations)".format(*bounds))


def _assembly_lines(t: _Text, analysis: Analysis) -> None:
    """Which assembly the pose is on, and how it was reached."""
    sol = analysis.solution
    if sol.assembly is None:
        return
    t.head("Assembly (sign of each loop block's Jacobian determinant; docs/explanation/assemblies.md)")
    for name, sign, label in zip(sol.assembly.names, sol.assembly.signs, sol.assembly.labels):
        word = "+" if sign > 0 else "-" if sign < 0 else "0"
        t.row(f"loop {name}", label if label == word else f"{label} ({word})")
    route = sol.route
    if route is not None:
        start = ", ".join(f"{n} = {_angle_or_length(analysis, n, x)}" for n, x in zip(analysis.drivers.names, route.start))
        if route.steps == 0:
            t.lines.append(f"  the scene's own pose ({start}), closed from {_closed_from(analysis)}")
        else:
            t.lines.append(f"  reached from the scene's pose ({start}) by continuation, {route.steps} steps")
        for x in route.change_points:
            at = ", ".join(f"{n} = {_angle_or_length(analysis, n, v)}" for n, v in zip(analysis.drivers.names, x))
            t.lines.append(f"  passed a change point near {at}, on the branch of continuous tangent")
    if not _pinned(analysis):
        found = ("is the one the model is drawn in (its reference pose)" if analysis.mechanism.reference is not None
                 else "was found from the neutral configuration")
        t.lines.append(f"  the scene has no [guess]: this assembly {found}; pin it with [guess] or "
                       f"{sol.assembly.pin_hint()}")


def _closed_from(analysis: Analysis) -> str:
    """Where the loops of the scene's own pose were closed from."""
    if analysis.scene.file.guess:
        return "its [guess]"
    if analysis.mechanism.reference is not None:
        return "the pose as drawn (the model file's)"
    return "the neutral configuration (every joint at 0)"


def _angle_or_length(analysis: Analysis, name: str, q: float) -> str:
    joint = analysis.mechanism.joint(name)
    return f"{math.degrees(q):.6g} deg" if joint.is_angular else f"{q:.6g} m"


def _joint_cells(kind: str, q, v, a) -> list[str]:
    if kind == "planar":
        return [f"x, y = ({_num(q[0])}, {_num(q[1])}) m, theta = {_num(math.degrees(q[2]))} deg",
                f"v = ({_num(v[0])}, {_num(v[1])}) m/s (joint frame), omega = {_num(v[2])} rad/s",
                f"a = ({_num(a[0])}, {_num(a[1])}) m/s^2 (joint frame), alpha = {_num(a[2])} rad/s^2"]
    if not isinstance(q, float):
        return [f"{kind}: q = ({', '.join(_num(x) for x in q)})", f"v = ({', '.join(_num(x) for x in v)})",
                f"a = ({', '.join(_num(x) for x in a)}) (Pinocchio's configuration and tangent rates, SI)"]
    if kind == "prismatic":
        return [f"q = {_num(q)} m", f"v = {_num(v)} m/s", f"a = {_num(a)} m/s^2"]
    return [
        f"q = {_num(math.degrees(q))} deg",
        f"v = {_num(v)} rad/s ({_num(v * 30 / math.pi)} rpm)",
        f"a = {_num(a)} rad/s^2",
    ]
