"""Actuator-space workspace figures: a row an assembly mode, with the motors' map (the cells
where the assembly exists filled by kappa, log scale; the type II locus, where it ends, and
the type I locus as curves, red and black) beside its image in the task space (each cell's end point
coloured likewise). For three motors the map is the slice across the third motor that holds
the most cells, and the image is seen along y (x across, z up)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pinmech.design.figure_file import pyplot, save
from pinmech.design.workspace.actuator import ActuatorResult
from pinmech.design.workspace.actuator_batch import ASSEMBLIES
from pinmech.design.workspace.actuator_report import _scales
from pinmech.design.workspace.plot import edge_field, kappa_bar


def actuator_figure(result: ActuatorResult, path: str | Path) -> Path:
    """Per assembly mode the actuator-space map and its task-space image, as PNG or SVG."""
    plt = pyplot("study")
    from matplotlib.colors import LogNorm
    from matplotlib.lines import Line2D

    fig, axs = plt.subplots(2, 2, figsize=(9.6, 8.2), squeeze=False, layout="constrained")
    finite = result.values["kappa"][np.isfinite(result.values["kappa"])]
    norm = LogNorm(vmin=max(1.0, float(finite.min())), vmax=max(2.0, float(np.percentile(finite, 98))))
    (sx, ux), (sy, uy) = _scales(result)[:2]
    index, label, _ = _slice(result)
    u, unit = result.spec.unit_si, result.spec.unit
    image = None
    for k, assembly in enumerate(ASSEMBLIES):
        ax, image_ax = axs[k]
        here = result.reached[..., k][index]
        kappa = np.ma.masked_invalid(np.where(here, np.clip(result.values["kappa"][..., k][index], norm.vmin,
                                                              norm.vmax), np.nan))
        x, y = result.coords[0] * sx, result.coords[1] * sy
        if kappa.count() >= 4:
            image = ax.contourf(x, y, kappa.T, levels=np.geomspace(norm.vmin, norm.vmax, 13), norm=norm,
                                cmap="viridis")
        _loci(ax, result, k, index, here, x, y)
        ax.set_title(f"assembly {assembly}{label}: {int(result.reached[..., k].sum())} cells", fontsize=8)
        ax.set_xlabel(f"{result.motors[0]} [{ux}]")
        ax.set_ylabel(f"{result.motors[1]} [{uy}]")
        here = result.reached[..., k]
        ends, kap = result.end[..., k, :][here] / u, result.values["kappa"][..., k][here]
        across = 2 if ends.shape[1] == 3 else 1
        image_ax.scatter(ends[:, 0], ends[:, across], c=kap, norm=norm, cmap="viridis", s=4)
        image_ax.set_aspect("equal")
        image_ax.set_title(f"assembly {assembly}: end point '{result.spec.point}' (task-space image)", fontsize=8)
        image_ax.set_xlabel(f"x [{unit}]")
        image_ax.set_ylabel(f"{'z' if across == 2 else 'y'} [{unit}]")
    kappa_bar(fig, image, axs, norm, f"kappa (J over L = {result.length / u:.4g} {unit})")
    fig.legend(handles=[Line2D([], [], color="black", lw=1.2, label="type I locus"),
                        Line2D([], [], color="red", lw=1.2, label="type II locus (the assembly ends)")],
               loc="outside lower center", ncol=2, fontsize=7, frameon=False)
    fig.suptitle(f"{result.spec.title} (actuator space)", fontsize=10)
    return save(plt, fig, path, tight=False)


def _loci(ax, result: ActuatorResult, k: int, index, here: np.ndarray, x: np.ndarray, y: np.ndarray) -> None:
    """The loci as curves: type I where det K changes sign (black); type II, where the
    assembly ends, along the edge of its cells, drawn where det Phi_p^2 reaches 0 (red)."""
    det1 = np.ma.masked_invalid(result.values["det1"][..., k][index]).T
    if det1.count() >= 4 and det1.min() < 0 < det1.max():
        ax.contour(x, y, det1, levels=[0.0], colors="black", linewidths=1.2)
    if here.any() and not here.all():
        ax.contour(x, y, edge_field(here, result.values["det2"][..., k][index]).T, levels=[0.0], colors="red",
                   linewidths=1.2)


def _slice(result: ActuatorResult):
    """(grid index, title suffix, locus filter) of the map: the plane, or the slice across a
    third motor that holds the most cells."""
    if len(result.coords) == 2:
        return (slice(None), slice(None)), "", lambda pts: np.ones(len(pts), bool)
    third = result.coords[2]
    i = int(np.argmax(result.reached.any(axis=-1).sum(axis=(0, 1))))
    s, unit = _scales(result)[2]
    tiny = 1e-9 * (third[-1] - third[0])
    return ((slice(None), slice(None), i), f", {result.motors[2]} = {third[i] * s:.4g} {unit}",
            lambda pts: np.abs(pts[:, 2] - third[i]) <= tiny)
