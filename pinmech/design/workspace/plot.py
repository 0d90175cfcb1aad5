"""Workspace study figures: per working mode, the reached region filled by kappa (the
dimensionless Jacobian's condition number, log scale, filled contours: no grid staircase),
the type II locus (red) and the type I locus (black: the workspace's boundary, where a leg
stretches or folds) as contour lines of the determinants' zeros and of the reached region,
the assembly mode with det Phi_p < 0 hatched, and the robot at its scene's pose with its
motors (a plane grid). A box grid (Delta) is drawn as slices across z."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pinmech.design.figure_file import pyplot, save
from pinmech.design.workspace.run import WorkspaceResult

_SLICES = 4


def workspace_figure(result: WorkspaceResult, path: str | Path) -> Path:
    """A workspace map per working mode (a row of z slices each for a box grid), as PNG or SVG."""
    plt = pyplot("study")
    from matplotlib.colors import LogNorm

    planes = _planes(result)
    modes = result.modes
    panels = [(k, plane, col) for k in range(len(modes)) for col, plane in enumerate(planes)]
    ncols = len(planes) if len(planes) > 1 else min(2, len(modes))
    nrows = -(-len(panels) // ncols)
    fig, axs = plt.subplots(nrows, ncols, figsize=(3.8 * ncols + 1.4, 3.6 * nrows + 0.6), squeeze=False,
                            layout="constrained")
    for ax in axs.flat[len(panels):]:
        ax.set_visible(False)
    finite = result.values["kappa"][np.isfinite(result.values["kappa"])]
    norm = LogNorm(vmin=max(1.0, float(finite.min())), vmax=max(2.0, float(np.percentile(finite, 98))))
    u, unit = result.spec.unit_si, result.spec.unit
    image = None
    robot = _robot(result) if len(result.coords) == 2 else None
    levels = np.geomspace(norm.vmin, norm.vmax, 13)
    for ax, (k, (label, index, near), col) in zip(axs.flat, panels):
        mode = modes[k]
        here = result.reached[..., k][index]
        kappa = np.ma.masked_invalid(np.where(here, np.clip(result.values["kappa"][..., k][index], norm.vmin,
                                                              norm.vmax), np.nan))
        x, y = result.coords[0] / u, result.coords[1] / u
        if kappa.count() >= 4:
            image = ax.contourf(x, y, kappa.T, levels=levels, norm=norm, cmap="viridis", extend="neither")
        _loci(ax, result, k, index, here, x, y)
        if robot is not None:
            robot(ax)
        m = result.measures[mode]
        scale = u ** len(result.coords)
        power = len(result.coords)
        measure = (f"\n{result.kind} {_number(m.value / scale)} +- {_number(m.bound / scale)} {unit}^{power}"
                   if col == 0 else "")
        ax.set_title(f"mode {mode}{label}{measure}", fontsize=8)
        ax.set_aspect("equal")
        ax.set_xlabel(f"x [{unit}]")
        ax.set_ylabel(f"y [{unit}]")
    kappa_bar(fig, image, axs, norm, f"kappa (J over L = {result.length / u:.4g} {unit})")
    fig.legend(handles=_legend(robot is not None), loc="outside lower center", ncol=4, fontsize=7, frameon=False)
    fig.suptitle(f"{result.spec.title}: workspace of '{result.spec.point}'", fontsize=10)
    return save(plt, fig, path, tight=False)


def _loci(ax, result: WorkspaceResult, k: int, index, here: np.ndarray, x: np.ndarray, y: np.ndarray) -> None:
    """The singularity loci as curves: type II where det2 changes sign (red), type I where
    det1 does and along the reached region's edge (black); det2 < 0 hatched where the panel
    holds both assembly modes."""
    det1, det2 = (np.ma.masked_invalid(result.values[f][..., k][index]).T for f in ("det1", "det2"))
    if here.any() and not here.all():
        ax.contour(x, y, edge_field(here, result.values["det1"][..., k][index]).T, levels=[0.0], colors="black",
                   linewidths=1.2)
    for det, colour in ((det1, "black"), (det2, "red")):
        if det.count() >= 4 and det.min() < 0 < det.max():
            ax.contour(x, y, det, levels=[0.0], colors=colour, linewidths=1.2)
    if det2.count() >= 4 and det2.min() < 0 < det2.max():  # two assembly modes on the panel
        ax.contourf(x, y, det2, levels=[det2.min() - 1.0, 0.0], colors="none", hatches=["//"])



def kappa_bar(fig, image, axs, norm, label: str) -> None:
    """kappa's colour bar beside the maps, on its log scale, ticked 1, 2, 5, 10, ... in plain numbers."""
    ticks = [t for t in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000) if norm.vmin <= t <= norm.vmax]
    bar = fig.colorbar(image, ax=axs, label=label, shrink=0.6, spacing="proportional", ticks=ticks)
    bar.ax.set_yticklabels([f"{t:g}" for t in ticks])


def edge_field(here: np.ndarray, det1: np.ndarray) -> np.ma.MaskedArray:
    """A field whose zero is the reached region's edge, between the grid's points: det1^2
    inside (a leg's sine squared, which falls off linearly to 0 where the leg stretches or
    folds), carried one step outside by linear extrapolation from the two points inside
    (so the edge is drawn where det1^2 reaches 0, a circle as a circle, not the grid's
    staircase); where that fails (a point with no two inside), a step's half: -f inside."""
    f = np.where(here, np.nan_to_num(det1) ** 2, np.nan)
    out = np.full(f.shape, np.nan)
    out[here] = f[here]
    for axis in range(f.ndim):
        for step in (1, -1):
            inner, inner2 = np.roll(f, -step, axis), np.roll(f, -2 * step, axis)
            edge = np.ones(f.shape, bool)
            index = [slice(None)] * f.ndim
            index[axis] = slice(-2, None) if step == 1 else slice(0, 2)
            edge[tuple(index)] = False  # no wrapping round the grid
            guess = np.where(np.isfinite(inner2), 2 * inner - inner2, -inner)
            take = ~here & edge & np.isfinite(inner) & np.isfinite(guess)
            out[take] = np.fmin(np.nan_to_num(out[take], nan=np.inf), np.minimum(guess[take], -1e-300))
    return np.ma.masked_invalid(out)


def _legend(robot: bool) -> list:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    return [Line2D([], [], color="black", lw=1.2, label="type I locus (the edge: a leg stretched or folded)"),
            Line2D([], [], color="red", lw=1.2, label="type II locus"),
            Patch(facecolor="none", edgecolor="0.2", hatch="//", label="assembly mode det Φp < 0"),
            *([Line2D([], [], color="0.4", marker="^", ls="none", label="motors; the robot at its scene's pose")]
              if robot else [])]


def _robot(result: WorkspaceResult):
    """A function drawing the robot at its scene's pose (its motors' triangles) on a panel,
    or None where the scene cannot be drawn."""
    from pinmech.draw.plot_paths import draw_linkage
    from pinmech.exceptions import PinmechError
    from pinmech.io.analysis import analyse
    from pinmech.io.scene import Scene

    try:
        analysis = analyse(Scene.load(result.spec.scene))
    except PinmechError:
        return None
    axes = np.eye(3)[:2]  # the grid's x and y
    return lambda ax: draw_linkage(ax, analysis.mechanism, analysis.solution.q, axes, 1.0 / result.spec.unit_si,
                                   labels=False)


def _number(x: float) -> str:
    """A measure for a title: whole above 100 (35775), else 3 significant digits."""
    return f"{x:.0f}" if abs(x) >= 100 else f"{x:.3g}"


def _planes(result: WorkspaceResult) -> list[tuple[str, tuple, object]]:
    """(title suffix, grid index, locus filter) of each panel: the plane, or z slices."""
    if len(result.coords) == 2:
        return [("", (slice(None), slice(None)), lambda pts: np.ones(len(pts), bool))]
    z = result.coords[2]
    reached = result.reached.any(axis=(0, 1, 3))
    levels = np.flatnonzero(reached)
    picks = np.unique(levels[np.linspace(0, len(levels) - 1, min(_SLICES, len(levels))).round().astype(int)])
    tiny = 1e-9 * (z[-1] - z[0])
    u, unit = result.spec.unit_si, result.spec.unit
    return [(f", z = {z[i] / u:.4g} {unit}", (slice(None), slice(None), i),
             lambda pts, zi=z[i]: np.abs(pts[:, 2] - zi) <= tiny) for i in picks]  # the slice's own edges
