"""A synthesis's report: text and JSON (errors at each target in mm, the defects checked,
the transmission-angle range, the rejected candidates by cause) and its figure (the
targets over each linkage's coupler curve, the linkage drawn at the first target)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinmech.angles import position_text, turn_degrees
from pinmech.design.figure_file import number_points, pyplot, save
from pinmech.design.synthesis.kinematics import kinematics
from pinmech.design.synthesis.linkage import motion_values
from pinmech.design.synthesis.objective import carried_angle
from pinmech.design.synthesis.result import MET, Linkage, SynthesisResult

DEFECTS = {
    "branch": "none: every pose on one assembly (B {side}), by construction",
    "circuit": "none: no fold of the dyad ({fold}) between the first and the last target",
    "order": "none: the crank turns {way} from target to target, within one turn",
}


def linkage_summary(lk: Linkage) -> dict:
    """One linkage's numbers, in mm and deg."""
    if lk.params is not None:  # a six-bar: its drawn linkage's params
        from pinmech.design.synthesis.sixbar_output import sixbar_summary

        return sixbar_summary(lk)
    slider = lk.topology == "slider-crank"
    inverted = lk.topology == "inverted-slider-crank"
    way = "counter-clockwise" if lk.way > 0 else "clockwise"
    side = ("ahead" if lk.s > 0 else "behind") if slider or inverted else ("left" if lk.s > 0 else "right")
    where = f"{'ahead of' if lk.s > 0 else 'behind'} A's foot on the slide" if slider else f"{side} of A -> O4"
    fold = "the rod square to the slide" if slider else "coupler and rocker in line"
    if inverted:
        where = f"= F, the slot's foot, {'behind' if lk.s > 0 else 'ahead of'} the crank's pin A along the guide"
        fold = "|O4 A| = |offset|, the slot square to O4 -> A"
    shape = ({"dimensions_mm": {n: round(float(v) * 1e3, 9) for n, v in zip(kinematics(lk.topology).NAMES, lk.z)
                                if n != "slide"}, "slide_deg": round(math.degrees(lk.z[2]), 9)} if slider else
             {"dimensions_mm": {n: round(float(v) * 1e3, 9) for n, v in zip(kinematics(lk.topology).NAMES, lk.z)},
              "ground_mm": round(math.hypot(lk.z[2] - lk.z[0], lk.z[3] - lk.z[1]) * 1e3, 9)})
    if lk.task != "function" or slider:
        errors = {"errors_mm": [float(e) * 1e3 for e in lk.errors],
                  "max_error_relative": float(np.max(lk.errors) / lk.size)}
        if lk.task == "function":
            errors["slider_start_mm"] = lk.phi0 * 1e3
    else:
        errors = {"errors_deg": [math.degrees(float(e)) for e in lk.errors], "rocker_start_deg": math.degrees(lk.phi0)}
    return {
        "topology": lk.topology,
        **shape,
        "assembly": side,
        "grashof": lk.grashof,
        "crank_deg": [turn_degrees(math.degrees(v)) for v in motion_values(lk)],
        **errors,
        **({"angle_errors_deg": [math.degrees(float(e)) for e in lk.angle_errors],
            "offset_deg": math.degrees(lk.phi0)} if lk.angle_errors is not None else {}),
        "meets_targets": lk.meets(MET),
        "met_within_relative": MET,
        "transmission_deg": [round(math.degrees(v), 3) for v in lk.transmission],
        "defects": {k: v.format(side=where, way=way, fold=fold) for k, v in DEFECTS.items()},
    }


def summary(result: SynthesisResult) -> dict:
    """The JSON summary of a synthesis."""
    return {
        "file": str(result.spec.path),
        "task": result.spec.task,
        "topology": result.spec.topology,
        "targets": len(result.spec.targets),
        "seed": result.spec.seed,
        "evaluations": result.evaluations,
        "generations": result.generations,
        "rejected": dict(sorted(result.rejected.items())),
        "linkages": [linkage_summary(lk) for lk in result.linkages],
    }


def text(result: SynthesisResult) -> str:
    """The text report."""
    s = summary(result)
    lines = [f"{result.spec.title}: {s['task']} generation, {s['topology']}, {s['targets']} targets, seed {s['seed']}",
             f"search: {s['evaluations']} candidates over {s['generations']} generations; rejected: "
             + (", ".join(f"{n} {c}" for c, n in s["rejected"].items()) or "none")]
    if not s["linkages"]:
        lines.append("no linkage meets the targets without a defect and within the constraints")
    for i, lk in enumerate(s["linkages"], start=1):
        lines += [
            f"linkage {i}: {_dimensions(lk)}; {lk['grashof']}, assembly {lk['assembly']}",
            _errors(lk),
            _met(lk),
            f"  crank at the targets [deg]: {', '.join(position_text(v) for v in lk['crank_deg'])}",
            f"  transmission angle over the motion: {lk['transmission_deg'][0]:.4g} .. {lk['transmission_deg'][1]:.4g} deg",
        ]
        lines += [f"  {k} defect: {v}" for k, v in lk["defects"].items()]
    return "\n".join(lines)


def _dimensions(lk: dict) -> str:
    """A linkage's dimensions, in a line."""
    if "params_mm" in lk:
        return ", ".join(f"{n} {v:.6g}" for n, v in lk["params_mm"].items()) + " mm"
    d = lk["dimensions_mm"]
    if lk["topology"] == "inverted-slider-crank":
        point = f", P at {d['along']:.6g} along and {d['across']:.6g} across the slot" if "errors_mm" in lk else ""
        return (f"O2 ({d['O2x']:.6g}, {d['O2y']:.6g}) mm, O4 ({d['O4x']:.6g}, {d['O4y']:.6g}) mm, "
                f"ground {lk['ground_mm']:.6g}, crank {d['crank']:.6g}, slot offset {d['offset']:.6g} mm{point}")
    if lk["topology"] == "slider-crank":
        point = f", P at {d['along']:.6g} along and {d['across']:.6g} across A->B" if "errors_deg" not in lk and \
            "slider_start_mm" not in lk else ""
        return (f"O2 ({d['O2x']:.6g}, {d['O2y']:.6g}) mm, slide at {lk['slide_deg']:.6g} deg offset {d['offset']:.6g}, "
                f"crank {d['crank']:.6g}, rod {d['rod']:.6g} mm{point}")
    return (f"O2 ({d['O2x']:.6g}, {d['O2y']:.6g}) mm, O4 ({d['O4x']:.6g}, {d['O4y']:.6g}) mm, "
            f"ground {lk['ground_mm']:.6g}, crank {d['crank']:.6g}, coupler {d['coupler']:.6g}, "
            f"rocker {d['rocker']:.6g} mm, P at {d['along']:.6g} along and {d['across']:.6g} across A->B")


def _met(lk: dict) -> str:
    """Whether the linkage meets the targets, and what that means (the tolerance)."""
    angular = "errors_deg" in lk and "slider_start_mm" not in lk
    within = (f"every output angle within {lk['met_within_relative']:g} rad" if angular else
              f"every target within {lk['met_within_relative']:g} of its size, the longest link")
    verdict = "yes" if lk["meets_targets"] else "no: the closest this search found (errors above)"
    return f"  meets the targets, {within}: {verdict}"


def _carried(lk: dict) -> str:
    """What a motion's gamma is measured from: the carried link's angle."""
    if "params_mm" in lk:
        return "the link"
    return "the slot" if lk["topology"] == "inverted-slider-crank" else "A->B"


def _errors(lk: dict) -> str:
    if "angle_errors_deg" in lk:
        return (f"  error at each pose [mm]: {', '.join(f'{e:.3g}' for e in lk['errors_mm'])} "
                f"(max {lk['max_error_relative']:.3g} of its size); [deg]: "
                f"{', '.join(f'{e:.3g}' for e in lk['angle_errors_deg'])} (the poses' angle is "
                f"{_carried(lk)}'s + {lk['offset_deg']:.6g} deg)")
    if "slider_start_mm" in lk:
        return (f"  slider travel error at each pair [mm]: {', '.join(f'{e:.3g}' for e in lk['errors_mm'])} "
                f"(max {lk['max_error_relative']:.3g} of its size; block at {lk['slider_start_mm']:.6g} mm along the "
                "slide at the first pair)")
    if "params_mm" in lk and "errors_deg" in lk:
        return f"  output turn error at each pair [deg]: {', '.join(f'{e:.3g}' for e in lk['errors_deg'])}"
    if "errors_mm" in lk:
        return (f"  error at each target [mm]: {', '.join(f'{e:.3g}' for e in lk['errors_mm'])} "
                f"(max {lk['max_error_relative']:.3g} of its size)")
    return (f"  rocker angle error at each pair [deg]: {', '.join(f'{e:.3g}' for e in lk['errors_deg'])} "
            f"(rocker at {lk['rocker_start_deg']:.6g} deg at the first pair)")


def figure(result: SynthesisResult, path: str | Path) -> Path:
    """One panel per linkage: the targets, the coupler curve over the motion (solid) and
    the rest of its turn on the same assembly (dotted), the linkage at the first target."""
    if result.spec.scene is not None:  # a six-bar, on the engine
        from pinmech.design.synthesis.sixbar_output import figure as sixbar_figure

        return sixbar_figure(result.spec, result, path)
    if result.spec.task == "function":
        return function_figure(result, path)
    plt = pyplot("synthesis")
    n = max(len(result.linkages), 1)
    fig, axes = plt.subplots(1, n, figsize=(4.6 * n + 0.6, 4.6), squeeze=False)
    T = result.spec.targets * 1e3
    for ax, lk, i in zip(axes[0], result.linkages, range(1, n + 1)):
        pose = kinematics(lk.topology).pose
        values = motion_values(lk)
        motion = np.linspace(values[0], values[-1], 400)
        turn = np.linspace(values[0], values[0] + 2 * math.pi * lk.way, 721)
        s = np.array([lk.s])
        whole, along = pose(lk.z[None], s, turn[None]).P[0] * 1e3, pose(lk.z[None], s, motion[None]).P[0] * 1e3
        ax.plot(whole[:, 0], whole[:, 1], ":", color="0.6", lw=1, label="coupler curve (same assembly)")
        ax.plot(along[:, 0], along[:, 1], "-", color="tab:blue", lw=1.6, label="motion through the targets")
        p = pose(lk.z[None], s, values[:1][None])
        O2, A, B, P = lk.z[:2] * 1e3, p.A[0, 0] * 1e3, p.B[0, 0] * 1e3, p.P[0, 0] * 1e3
        if lk.topology == "slider-crank":  # the slide's line over the block's travel, the block on it
            u = np.array([math.cos(lk.z[2]), math.sin(lk.z[2])])
            ends = np.array([B - 0.6 * lk.size * 1e3 * u, B + 0.6 * lk.size * 1e3 * u])
            ax.plot(*ends.T, "-", color="0.4", lw=0.8)
            ax.plot(*np.array([O2, A, B]).T, "-o", color="k", lw=1.4, ms=3)
            ax.plot(*B, "s", color="k", ms=9, mfc="none")
            ax.plot(*O2, "^", color="k", ms=8)
        elif lk.topology == "inverted-slider-crank":  # the guide O4 -> F and its slot past A, the block at A
            O4 = lk.z[2:4] * 1e3
            u = (A - B) / max(float(np.linalg.norm(A - B)), 1e-12)
            ax.plot(*np.array([O4, B, A + 0.3 * lk.size * 1e3 * u]).T, "-", color="0.4", lw=1.4)
            ax.plot(*np.array([O2, A]).T, "-o", color="k", lw=1.4, ms=3)
            ax.plot(*A, "s", color="k", ms=9, mfc="none")
            ax.plot(*np.array([O2, O4]).T, "^", color="k", ms=8)
        else:
            O4 = lk.z[2:4] * 1e3
            ax.plot(*np.array([O2, A, B, O4]).T, "-o", color="k", lw=1.4, ms=3)
            ax.plot(*np.array([O2, O4]).T, "^", color="k", ms=8)
        if lk.topology == "inverted-slider-crank":  # P on the block, at A
            ax.plot(*np.array([A, P]).T, "-", color="tab:orange", lw=3, alpha=0.6)
        else:
            ax.fill(*np.array([A, B, P]).T, color="tab:orange", alpha=0.3)
        ax.plot(T[:, 0], T[:, 1], "x", color="tab:red", ms=8, mew=2, label="targets")
        if result.spec.angles is not None:  # the poses' angles, and the coupler's at each pose
            L = 0.15 * float(np.ptp(T, axis=0).max())
            a = result.spec.angles
            ax.quiver(T[:, 0], T[:, 1], np.cos(a), np.sin(a), color="tab:red", angles="xy", scale_units="xy",
                      scale=1 / L, width=0.006, label="pose angles")
            q = pose(lk.z[None], s, lk.theta[None])
            c = carried_angle(lk.topology, q, lk.z[None], s, lk.theta[None])[0] + lk.phi0
            ax.quiver(q.P[0, :, 0] * 1e3, q.P[0, :, 1] * 1e3, np.cos(c), np.sin(c), color="tab:blue",
                      angles="xy", scale_units="xy", scale=1 / L, width=0.003, label="coupler at the poses")
        ax.set_aspect("equal")
        number_points(ax, T)
        ax.set_title(f"linkage {i}: max error {np.max(lk.errors) * 1e3:.2g} mm\n"
                     f"{lk.grashof}, transmission {math.degrees(lk.transmission[0]):.0f}.."
                     f"{math.degrees(lk.transmission[1]):.0f} deg", fontsize=9)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.grid(alpha=0.3)
    if result.linkages:
        axes[0][0].legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.22))  # below: never over a pivot
    fig.suptitle(result.spec.title)
    return save(plt, fig, path)


def function_figure(result: SynthesisResult, path: str | Path) -> Path:
    """The rocker's turn (a slider-crank's block travel) against the crank's over the motion
    for each linkage, and the pairs."""
    plt = pyplot("synthesis")
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    slider = result.spec.topology == "slider-crank"
    pairs = np.column_stack((np.degrees(result.spec.targets[:, 0]),
                             result.spec.targets[:, 1] * (1e3 if slider else 180 / math.pi)))
    for i, lk in enumerate(result.linkages, start=1):
        k = kinematics(lk.topology)
        values = motion_values(lk)
        crank = np.linspace(values[0], values[-1], 300)
        B = k.pose(lk.z[None], np.array([lk.s]), crank[None]).B[0]
        if slider:
            out = (k.slide_position(lk.z[None], B[None])[0] - lk.phi0) * 1e3
            label = f"linkage {i}: max error {np.max(lk.errors) * 1e3:.2g} mm"
        else:
            phi = np.unwrap(k.guide_angle(lk.z[None], np.array([lk.s]), crank[None])[0]
                            if lk.topology == "inverted-slider-crank" else np.arctan2(B[:, 1], B[:, 0] - lk.z[2]))
            out = np.degrees(phi - lk.phi0)
            out -= 360 * np.round((out[0]) / 360)
            label = f"linkage {i}: max error {math.degrees(np.max(lk.errors)):.2g} deg"
        ax.plot(np.degrees(crank - crank[0]), out, lw=1.5, label=label)
    ax.plot(pairs[:, 0], pairs[:, 1], "x", color="tab:red", ms=8, mew=2, label="pairs asked")
    ax.set_xlabel("crank turn from the first pair [deg]")
    ax.set_ylabel("slider travel [mm]" if slider else "guide turn [deg]" if result.spec.topology ==
                  "inverted-slider-crank" else "rocker turn [deg]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(result.spec.title)
    return save(plt, fig, path)
