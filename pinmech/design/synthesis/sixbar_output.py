"""A synthesised six-bar written and checked: its template's drawn linkage with the
params found (model/linkage_write.py), a scene that turns its crank once from the drawn
pose, the engine's sweep of that scene read at the targets, its report lines and figure."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinmech.angles import turn_degrees
from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.written import targets_text
from pinmech.design.synthesis.result import MET, Linkage
from pinmech.design.synthesis.written import deg_text
from pinmech.outputs import write_whole

_STEP = math.radians(1.0)  # the engine check's sweep: at most this crank step between poses


def _template(spec: SynthesisSpec):
    """The template scene's drawn linkage spec, its file and the scene."""
    from pinmech.io.scene import Scene
    from pinmech.model.linkage_spec import read_linkage_spec

    scene = Scene.load(spec.scene)
    linkage, source = read_linkage_spec(scene.model_file("linkage"))
    return linkage, source, scene


def linkage_toml(spec: SynthesisSpec, lk: Linkage) -> str:
    """The drawn linkage's TOML: the template's, its [params] those found [mm]."""
    from pinmech.model.linkage_write import linkage_toml as written

    linkage, _, _ = _template(spec)
    found = linkage.with_params(**{n: lk.params[n] for n in linkage.params})
    what = {"path": f"the coupler point {spec.point} through the targets",
            "function": f"{spec.output}'s turns against the crank's",
            "motion": f"{spec.output} through the poses (its point {spec.point} and its angle)"}[spec.task]
    header = f"Synthesised by `pinmech synth {spec.path}`: {what} ({spec.topology} six-bar)."
    return written(found, header)


def crank_values(lk: Linkage, start: float) -> np.ndarray:
    """The crank's values at the targets on the range from `start` [rad]."""
    return start + np.mod(lk.theta - start, 2 * math.pi)


def scene_toml(spec: SynthesisSpec, lk: Linkage, linkage_file: str) -> str:
    """A scene of the linkage: its crank driven from the drawn pose, swept over one turn."""
    from pinmech.design.synthesis.engine import template

    t = template(spec)
    driver = t.sm.sweep.driver
    shown = _shown(spec)
    deg = [f"\"{deg_text(v)}\"" for v in (t.p0, t.start, t.stop)]
    return "\n".join([
        "# The synthesised six-bar, its crank driven from the drawn pose over the range searched:",
        "#   pinmech sweep THIS_FILE --plot fig.png",
        f"title = \"{spec.title}\"", f"linkage = \"{linkage_file}\"", "",
        f"[drivers.{driver}]", f"angle = {deg[0]}", "",
        "[sweep]", f"from = {deg[1]}", f"to = {deg[2]}", "steps = 361", shown,
        *([targets_text(spec.point, spec.targets[:, :2])] if spec.task in ("path", "motion") else []), "",
        "[report]", shown, ""])


def _shown(spec: SynthesisSpec) -> str:
    """The scene's outputs: the point (path), the output link (function), both (motion)."""
    point, link = f"points = [\"{spec.point}\"]", f"links = [\"{spec.output}\"]"
    return {"path": point, "function": link, "motion": f"{point}\n{link}"}[spec.task]


def write_linkage(spec: SynthesisSpec, lk: Linkage, prefix: str | Path) -> tuple[Path, Path]:
    """PREFIX.toml (the drawn linkage) and PREFIX_scene.toml (its turn); their paths."""
    prefix = Path(prefix)
    linkage, scene = prefix.with_name(prefix.name + ".toml"), prefix.with_name(prefix.name + "_scene.toml")
    write_whole(linkage, linkage_toml(spec, lk))
    write_whole(scene, scene_toml(spec, lk, linkage.name))
    return linkage, scene


def engine_check(spec: SynthesisSpec, scene_file: str | Path, lk: Linkage) -> tuple[np.ndarray, np.ndarray | None]:
    """The written scene swept by the engine (pinmech sweep's path) from its drawn pose to
    the range's start, then up through the targets' crank values, poses at most _STEP apart: the distance of the
    coupler point from each target [m] (a motion's: and its link's angle error at each pose
    [rad]), or the output's turn error at each pair [rad] (and None).

    Raises:
        SweepError: the engine could not follow the motion (a fold, no closure).
    """
    from pinmech.io.scene import Scene
    from pinmech.io.sweep import Sweep

    from pinmech.design.synthesis.engine import template

    sweep, t = Sweep.from_scene(Scene.load(scene_file)), template(spec)
    values = crank_values(lk, t.start)
    order = np.argsort(values)
    dense = list(np.linspace(sweep.start, t.start, max(int(math.ceil(abs(t.start - sweep.start) / _STEP)), 1) + 1))
    at = []
    for v in values[order]:
        n = max(int(math.ceil((v - dense[-1]) / _STEP)), 1)
        dense += list(np.linspace(dense[-1], v, n + 1)[1:])
        at.append(len(dense) - 1)
    wanted = dict(zip(at, order))
    out = [None] * len(values)
    for pose in sweep.poses(np.asarray(dense)):
        if pose.index in wanted:
            m = pose.motion
            place = m.points[spec.point].position[:2] if spec.task != "function" else np.zeros(0)
            angle = np.array([m.links[spec.output].angle]) if spec.task != "path" else np.zeros(0)
            out[wanted[pose.index]] = np.concatenate((place, angle))
    y = np.array(out)
    if spec.task == "path":
        return np.linalg.norm(y - spec.targets, axis=1), None
    if spec.task == "motion":
        turn = y[:, 2] + lk.phi0 - spec.angles
        return np.linalg.norm(y[:, :2] - spec.targets, axis=1), np.abs(np.mod(turn + math.pi, 2 * math.pi) - math.pi)
    turn = y[:, 0] - y[0, 0] - spec.targets[:, 1]
    return np.abs(np.mod(turn + math.pi, 2 * math.pi) - math.pi), None


def sixbar_summary(lk: Linkage) -> dict:
    """One six-bar's numbers, in mm and deg."""
    angular = lk.task == "function"
    errors = ({"errors_deg": [math.degrees(float(e)) for e in lk.errors]} if angular else
              {"errors_mm": [float(e) * 1e3 for e in lk.errors], "max_error_relative": float(np.max(lk.errors) / lk.size)})
    return {
        "topology": lk.topology,
        "params_mm": {n: round(v * 1e3, 9) for n, v in lk.params.items()},
        "assembly": "as drawn (its sides)",
        "grashof": lk.grashof,
        "crank_deg": [turn_degrees(math.degrees(v)) for v in lk.theta],
        **errors,
        **({"angle_errors_deg": [math.degrees(float(e)) for e in lk.angle_errors],
            "offset_deg": math.degrees(lk.phi0)} if lk.angle_errors is not None else {}),
        "meets_targets": lk.meets(MET),
        "met_within_relative": MET,
        "transmission_deg": [round(math.degrees(v), 3) for v in lk.transmission],
        "defects": {"branch": "none: the crank's whole turn followed on the drawn assembly, no change point",
                    "circuit": "none: no fold within the crank's whole turn",
                    "order": f"none: the crank turns {'counter-clockwise' if lk.way > 0 else 'clockwise'} from "
                             "target to target, within one turn"},
    }


def figure(spec: SynthesisSpec, result, path: str | Path) -> Path:
    """The targets over each linkage's coupler curve over the whole turn (a path), or the
    output's turn against the crank's with the pairs (a function)."""
    from pinmech.design.figure_file import number_points, pyplot, save
    from pinmech.design.synthesis.engine import template

    t = template(spec)
    plt = pyplot("synthesis")
    fig, ax = plt.subplots(figsize=(6.4, 5.0))
    for i, lk in enumerate(result.linkages, start=1):
        t.write(lk.z)
        Q, _, _ = t.follow(t.grid)
        y = t.values(Q)
        label = f"linkage {i}: max error " + (f"{math.degrees(np.max(lk.errors)):.2g} deg" if spec.task == "function"
                                               else f"{np.max(lk.errors) * 1e3:.2g} mm")
        if spec.task == "motion":
            label += f", {math.degrees(np.max(lk.angle_errors)):.2g} deg"
        if spec.task != "function":
            ax.plot(y[:, 0] * 1e3, y[:, 1] * 1e3, lw=1.5, label=label + " (the whole turn)")
            at = np.argmin(np.abs(t.grid - crank_values(lk, t.start)[0]))
            _draw_links(ax, spec, t, Q[at], "k" if i == 1 else "0.6")
        else:
            start = crank_values(lk, t.start)[0]
            turn = np.mod(t.grid - start, 2 * math.pi)
            order = np.argsort(turn)
            phi = np.unwrap(y[order, 0])
            ax.plot(np.degrees(turn[order]), np.degrees(phi - np.interp(0.0, turn[order], phi)), lw=1.5, label=label)
    if spec.task == "motion":  # each pose's angle: a line from its place, the part's
        T, r = spec.targets * 1e3, 0.3 * max(float(np.ptp(spec.targets * 1e3, axis=0).max()), 1e-9)
        for k, ((x, y0), a) in enumerate(zip(T, spec.angles)):
            ax.plot([x, x + r * math.cos(a)], [y0, y0 + r * math.sin(a)], "-", color="tab:red", lw=1.5,
                    label="the poses' angles" if k == 0 else None)
    if spec.task != "function":
        T = spec.targets * 1e3
        ax.plot(T[:, 0], T[:, 1], "x", color="tab:red", ms=8, mew=2, label="poses" if spec.task == "motion" else "targets")
        ax.set_aspect("equal")
        number_points(ax, T)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
    else:
        ax.plot(np.degrees(spec.targets[:, 0]), np.degrees(spec.targets[:, 1]), "x", color="tab:red", ms=8, mew=2,
                label="pairs asked")
        ax.set_xlabel("crank turn from the first pair [deg]")
        ax.set_ylabel(f"{spec.output} turn [deg]")
    ax.grid(alpha=0.3)
    if spec.task == "function":
        ax.legend(fontsize=8)
    else:  # below the drawing, never over a pivot or a pose
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    ax.set_title(spec.title)
    return save(plt, fig, path)


def _draw_links(ax, spec: SynthesisSpec, t, q: np.ndarray, colour: str) -> None:
    """The linkage at pose q: each link's pins joined, the ground pins as triangles [mm]."""
    import pinocchio as pin

    linkage, _, _ = _template(spec)
    mech, data = t.sm.mechanism, t.sm.model.createData()
    pin.framesForwardKinematics(t.sm.model, data, q)
    where = {}
    for name in linkage.joints:
        try:
            where[name] = data.oMf[mech.frame_id(name)].translation[:2] * 1e3
        except Exception:  # a joint without a frame of its name: not drawn
            continue
    for joints in linkage.links.values():
        xy = np.array([where[j] for j in joints if j in where])
        if len(xy) > 1:
            ax.fill(*np.vstack((xy, xy[:1])).T, color=colour, alpha=0.15) if len(xy) > 2 else None
            ax.plot(*np.vstack((xy, xy[:1])).T if len(xy) > 2 else xy.T, "-o", color=colour, lw=1.2, ms=3)
    ground = np.array([where[j] for j in linkage.ground if j in where])
    if len(ground):
        ax.plot(*ground.T, "^", color=colour, ms=8, ls="none")
