"""The figure of an arm's task followed in time (matplotlib, extra `plot`): joint
coordinates, rates, accelerations and the drift of the achieved path against time, lengths
in one unit a figure (mm or m from the arm's size, `plot_curves.length_unit`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.draw import plot as _plot
from pinmech.draw.plot import MAX_POINTS, _pyplot
from pinmech.draw.plot_curves import length_unit

if TYPE_CHECKING:
    from pinmech.model.mechanism import Mechanism
    from pinmech.solve.path import PathPoint


class PathPlot:
    """Records an arm path point by point, then draws joint coordinates, rates,
    accelerations and the drift against time (`save`)."""

    def __init__(self, mechanism: Mechanism, title: str, *, note: str = "", total: int | None = None,
                 max_points: int = MAX_POINTS) -> None:
        _pyplot()
        self.mechanism, self.title, self.note = mechanism, title, note
        self.joints = [j for j in mechanism.joints.values() if j.nv == 1]
        self.every = max(1, math.ceil(total / max_points)) if total else 1
        self.total = total
        self.t: list[float] = []
        self.rows: list[list[float]] = []
        self.count = 0
        self.length = length_unit(mechanism.length_scale)  # (factor from m, unit) of every length drawn

    def add(self, point: PathPoint) -> None:
        self.count += 1
        if (self.count - 1) % self.every and self.count != self.total:  # the last point is always drawn
            return
        q = [self.mechanism.coordinate(point.q, j.name) for j in self.joints]
        k = np.array([1.0 if j.is_angular else self.length[0] for j in self.joints])
        q = [math.degrees(x) if j.is_angular else x * self.length[0] for x, j in zip(q, self.joints)]
        idx = [j.idx_v for j in self.joints]
        self.t.append(point.time)
        self.rows.append(q + (k * point.v[idx]).tolist() + (k * point.a[idx]).tolist()
                         + [point.drift * self.length[0], point.angular_drift])

    def save(self, path: str | Path) -> Path:
        if not self.rows:
            raise PinmechError(f"no path point: nothing to plot in {path}")
        plt = _pyplot()
        t, data, n = np.array(self.t), np.array(self.rows), len(self.joints)
        angular = all(j.is_angular for j in self.joints)
        mm = self.length[1]
        units = ("deg", "rad/s", "rad/s²") if angular else (f"deg or {mm}", f"rad/s or {mm}/s", f"rad/s² or {mm}/s²")
        fig, axes = plt.subplots(2, 2, figsize=(11, 6.4), sharex=True)
        for k, (ax, name) in enumerate(zip(axes.flat[:3], ("joint coordinate q", "joint rate q̇", "joint acceleration q̈"))):
            for i, joint in enumerate(self.joints):
                ax.plot(t, data[:, k * n + i], linewidth=1.5, label=joint.name)
            ax.set_title(f"{name} [{units[k]}]", fontsize=10)
            ax.set_ylabel(f"[{units[k]}]")
        ax = axes.flat[3]
        drift, angle = data[:, 3 * n], data[:, 3 * n + 1]
        floor = 1e-16
        ax.semilogy(t, np.maximum(drift, floor), linewidth=1.5, label=f"position drift [{mm}]")
        if np.any(angle > 0):
            ax.semilogy(t, np.maximum(angle, floor), linewidth=1.5, label="angle drift [rad]")
        ax.set_title("drift of the achieved path from the asked one", fontsize=10)
        ax.set_ylabel(f"[{mm}] or [rad]")
        for ax in axes.flat:
            ax.grid(True, alpha=0.35)
            ax.legend(fontsize=8, loc="best")
        for ax in axes[-1]:
            ax.set_xlabel("time t [s]")
        fig.suptitle(f"{self.title}: task followed in time{self.note}", fontsize=11)
        fig.tight_layout()
        return _plot._save(plt, fig, path)
