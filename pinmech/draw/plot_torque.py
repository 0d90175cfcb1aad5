"""The driver's torque figure of a sweep (matplotlib, extra `plot`), as a textbook prints it.

Dynamics: the driver torque T(θ) with its mean T̄ and its zeros in one panel; below it, in a
panel of its own, the flywheel's energy E(θ) = ∫ (T̄ − T) dθ [J] (what a flywheel turning the
mechanism at the mean motor torque T̄ gains from its start): its maximum is where the speed is
highest (ω max), its minimum where it is lowest (ω min), and the energy fluctuation ΔE is the
height between them. Statics: the torque that holds the loads and, when there are loads, the
mechanical advantage; never an energy (there is no motion to store it).

A whole turn is drawn on the sweep figure's own axis, 0 to 360°, whatever angle it began at.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pinmech.solve.flywheel import energy_curve
from pinmech.draw.plot_curves import draw_markers


@dataclass(frozen=True)
class TorqueCurve:
    """What the torque figure draws, in the drawn units.

    Attributes:
        driver: the driver's name.
        angular: a turning driver (torque [N m] against degrees), else a slider (force [N]
            against metres).
        x: the driver's values as drawn (degrees, 0-360 for a whole turn; or metres).
        torque: the driver torque [N m] (force [N]) at each x.
        zeros: x where the torque changes sign (linear interpolation between poses).
        mean: the mean torque T̄ [N m] over the run (None: statics, or no cycle).
        energy: E(θ) = ∫ (T̄ − T) dθ [J] at each x (None without a mean).
        advantage: the mechanical advantage at each x (statics with loads, else None).
        advantage_unit: its unit ("1", "m", "1/m").
    """

    driver: str
    angular: bool
    x: np.ndarray
    torque: np.ndarray
    zeros: list[float]
    mean: float | None = None
    energy: np.ndarray | None = None
    advantage: np.ndarray | None = None
    advantage_unit: str = "1"
    markers: list[tuple[float, str]] = field(default_factory=list)

    @property
    def energy_fluctuation(self) -> float | None:
        """ΔE = E max − E min [J] (None without an energy curve)."""
        return None if self.energy is None else float(np.max(self.energy) - np.min(self.energy))


def torque_curve(driver: str, values: np.ndarray, torques: np.ndarray, *, angular: bool, cycle: bool,
                 advantage: np.ndarray | None = None, advantage_unit: str = "1") -> TorqueCurve:
    """The curve to draw from the swept driver values [rad or m] and torques [N m or N] in
    sweep order; `cycle`: the mean and E(θ) are drawn (a driver run in one sense, dynamics)."""
    values, torques = np.asarray(values, float), np.asarray(torques, float)
    zeros = [float(z) for z in _zeros(values, torques)]
    mean = energy = None
    if cycle:
        mean, given_up = energy_curve(values, torques)
        energy = -given_up  # what the flywheel gains: ∫ (T̄ - T) dθ
    x = np.degrees(values) if angular else values
    zeros = list(np.degrees(zeros)) if angular else zeros
    order = np.arange(len(x))
    if angular and abs(abs(x[-1] - x[0]) - 360.0) <= 1e-9 * 360.0:  # a whole turn: 0 to 360 deg
        x, order = _turn(x)
        zeros = sorted(float(z) % 360.0 for z in zeros)
    pick = (lambda a: None if a is None else np.asarray(a, float)[order])
    return TorqueCurve(driver, angular, x, torques[order], zeros, mean, pick(energy), pick(advantage),
                       advantage_unit)


def _zeros(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Where y changes sign between samples (linear interpolation)."""
    i = np.nonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)[0]
    return x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i])


def _turn(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A whole turn's angles [deg] wrapped to [0, 360] and the order that sorts them; the pose
    at 0 deg (the start, or the end) also closes the curve at 360 deg."""
    wrapped = np.mod(x, 360.0)
    order = np.argsort(wrapped, kind="stable")
    wrapped = wrapped[order]
    if np.isclose(wrapped[0], 0.0, atol=1e-9):
        order, wrapped = np.append(order, order[0]), np.append(wrapped, 360.0)
    elif np.isclose(wrapped[-1], 360.0, atol=1e-9):
        order, wrapped = np.insert(order, 0, order[-1]), np.insert(wrapped, 0, 0.0)
    else:  # the turn's ends fall between samples: the first and last poses are the same pose
        order = np.concatenate(([order[-1]], order, [order[0]]))
        wrapped = np.concatenate(([wrapped[-1] - 360.0], wrapped, [wrapped[0] + 360.0]))
    return wrapped, order


def torque_figure(curve: TorqueCurve, title: str):
    """The figure (not saved): torque panel, then E(θ) or the mechanical advantage."""
    from pinmech.draw.plot import _pyplot

    plt = _pyplot()
    second = curve.energy is not None or curve.advantage is not None
    fig, axes = plt.subplots(2 if second else 1, 1, figsize=(11.5, 7.2 if second else 4.2), sharex=True,
                             squeeze=False)
    axes = list(axes.flat)
    _torque_panel(axes[0], curve)
    if curve.energy is not None:
        _energy_panel(axes[1], curve)
    elif curve.advantage is not None:
        _advantage_panel(axes[1], curve)
    if curve.angular and curve.x[0] <= 0.0 and curve.x[-1] >= 360.0:  # a whole turn
        axes[-1].set_xticks(np.arange(0, 361, 45))
        axes[-1].set_xlim(0.0, 360.0)
    else:
        axes[-1].set_xlim(np.min(curve.x), np.max(curve.x))
    axes[-1].set_xlabel(f"driver {curve.driver}, θ [deg]" if curve.angular else f"driver {curve.driver}, s [m]")
    draw_markers(axes, curve.markers)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def _torque_panel(ax, curve: TorqueCurve) -> None:
    name, unit = ("driver torque T", "N·m") if curve.angular else ("driver force F", "N")
    ax.plot(curve.x, curve.torque, color="C0", linewidth=1.6, label=name)
    if curve.mean is not None:
        ax.axhline(curve.mean, color="k", linestyle="--", linewidth=0.9, label=f"mean T̄ = {_g(curve.mean)} {unit}")
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    if curve.zeros:
        ax.plot(curve.zeros, np.zeros(len(curve.zeros)), "o", markerfacecolor="white", markeredgecolor="C3",
                markersize=6, zorder=4, label=f"{name.split()[-1]} = 0 at " + ", ".join(f"{z:.4g}" for z in curve.zeros)
                + (" deg" if curve.angular else " m"))
    ax.set_ylabel(f"{name} [{unit}]")
    ax.set_title(f"{name} to drive the mechanism" if curve.mean is not None else f"{name} to hold the loads (statics)",
                 fontsize=10)
    ax.grid(True, alpha=0.35)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)  # off the curves


def _energy_panel(ax, curve: TorqueCurve) -> None:
    e, x = curve.energy, curve.x
    hi, lo = int(np.argmax(e)), int(np.argmin(e))
    ax.plot(x, e, color="C2", linewidth=1.6, label="E(θ) = ∫ (T̄ − T) dθ")
    ax.plot([x[hi]], [e[hi]], "^", color="C3", markersize=8, label=f"E max at {x[hi]:.4g} deg: ω max")
    ax.plot([x[lo]], [e[lo]], "v", color="C0", markersize=8, label=f"E min at {x[lo]:.4g} deg: ω min")
    at = x[lo] + 0.5 * (x[hi] - x[lo])
    for level in (e[hi], e[lo]):
        ax.axhline(level, color="0.55", linestyle=":", linewidth=0.9)
    ax.annotate("", (at, e[hi]), (at, e[lo]), arrowprops={"arrowstyle": "<->", "color": "k", "lw": 1.1})
    ax.annotate(f"ΔE = {curve.energy_fluctuation:.4g} J", (at, 0.5 * (e[hi] + e[lo])), xytext=(5, 0),
                textcoords="offset points", va="center", fontsize=9,
                bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8})
    ax.set_ylabel("flywheel energy E [J]")
    ax.set_title("energy a flywheel gains at the mean torque (from the sweep's start)", fontsize=10)
    ax.grid(True, alpha=0.35)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)  # off the curves


#: The mechanical advantage is drawn up to this many times its median size: at a toggle it
#: grows without bound, and the spike would flatten the rest of the curve.
ADVANTAGE_CLIP = 20.0


def _advantage_panel(ax, curve: TorqueCurve) -> None:
    ma = np.asarray(curve.advantage, float)
    finite = np.abs(ma[np.isfinite(ma)])
    bound = ADVANTAGE_CLIP * float(np.median(finite)) if finite.size else 1.0
    ax.plot(curve.x, np.where(np.abs(ma) <= bound, ma, np.nan), color="C4", linewidth=1.6,
            label="mechanical advantage (load / driver effort)")
    for z in curve.zeros:
        ax.axvline(z, color="C3", linestyle="--", linewidth=0.9)
    if curve.zeros:
        ax.plot([], [], color="C3", linestyle="--", linewidth=0.9, label="toggle: driver effort 0, advantage → ∞")
    ax.set_ylim(-bound if np.nanmin(ma) < 0 else 0.0, bound)
    ax.set_ylabel(f"mechanical advantage [{curve.advantage_unit}]")
    ax.set_title(f"mechanical advantage (drawn up to ±{_g(bound)} {curve.advantage_unit})", fontsize=10)
    ax.grid(True, alpha=0.35)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)  # off the curves


def _g(value: float) -> str:
    return f"{value:.4g}" if math.isfinite(value) else str(value)


def save_torque_figure(curve: TorqueCurve, title: str, path: str | Path) -> Path:
    """Draw `curve` and save it (PNG, PDF, SVG by suffix)."""
    from pinmech.draw.plot import _pyplot, _save

    return _save(_pyplot(), torque_figure(curve, title), path)
