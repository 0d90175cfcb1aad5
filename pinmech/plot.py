"""Figures of a sweep (matplotlib, extra `plot`): what a report shows for a mechanism.

Link angles, angular velocities and accelerations, the sliders' relative velocity and
acceleration, and the speed and acceleration magnitudes of chosen points, against the
driver, with the scene's own pose marked.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from pinmech.sweep import Sweep, SweepPose


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise ImportError('plots need matplotlib: pip install "pinmech[plot]"') from exc
    return plt


def plot_sweep(sweep: Sweep, poses: Iterable[SweepPose], path: str | Path, *,
               links: list[str] | None = None, points: list[str] | None = None) -> Path:
    """Draw the sweep's quantities against the driver and save the figure (PNG, PDF, SVG).

    Links and points default to the scene's `[sweep] links/points`, else every moving one.
    """
    plt = _pyplot()
    chosen = sweep.scene.section("sweep")
    links = links or chosen.get("links")
    points = points or chosen.get("points")
    poses = [p for p in poses if p.motion is not None]
    if not poses:
        raise ValueError("no solved pose to plot")
    first = poses[0].motion
    driver_link = sweep.mechanism.joint(sweep.driver).child_link
    links = links or [n for n in first.links if n != driver_link]
    points = points or [n for n, p in first.points.items()
                        if any(np.linalg.norm(q.motion.points[n].velocity) > 0 for q in poses[:5])]
    x = np.array([math.degrees(p.value) if sweep.is_angular else p.value for p in poses])
    x_label = f"{sweep.driver} [{'deg' if sweep.is_angular else 'm'}]"
    normal = sweep.mechanism.plane_normal if sweep.mechanism.plane_normal is not None else np.array([0, 0, 1.0])

    panels = [
        ("link angle [deg]",  # unwrapped, so a link turning through 180 deg draws no jump
         {n: np.degrees(np.unwrap([p.motion.links[n].angle or 0.0 for p in poses])) for n in links}),
        ("angular velocity ω [rad/s]", {n: [normal @ p.motion.links[n].angular_velocity for p in poses] for n in links}),
        ("angular acceleration α [rad/s²]",
         {n: [normal @ p.motion.links[n].angular_acceleration for p in poses] for n in links}),
    ]
    if first.sliders:
        panels.append(("slider relative velocity [m/s]", {n: [p.motion.joints[n].v for p in poses] for n in first.sliders}))
        panels.append(("slider relative acceleration [m/s²]",
                       {n: [p.motion.joints[n].a for p in poses] for n in first.sliders}))
    panels.append(("speed |v| [m/s]", {n: [np.linalg.norm(p.motion.points[n].velocity) for p in poses] for n in points}))
    panels.append(("acceleration |a| [m/s²]",
                   {n: [np.linalg.norm(p.motion.points[n].acceleration) for p in poses] for n in points}))

    cols = 2
    rows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(11, 2.8 * rows), sharex=True, squeeze=False)
    mark = math.degrees(sweep.start) if sweep.is_angular else sweep.start
    for ax, (title, series) in zip(axes.flat, panels):
        for name, values in series.items():
            ax.plot(x, values, label=name, linewidth=1.6)
        ax.axvline(mark, color="0.4", linestyle="--", linewidth=1)
        ax.set_title(title, fontsize=10)
        ax.grid(True, alpha=0.4)
        ax.legend(fontsize=8, loc="best")
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel(x_label)
    fig.suptitle(f"{sweep.scene.title}: sweep of {sweep.driver} (dashed: the scene's pose, "
                 f"{mark:.4g} {'deg' if sweep.is_angular else 'm'})", fontsize=11)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
