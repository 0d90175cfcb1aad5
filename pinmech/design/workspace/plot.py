"""Workspace study figures: per working mode, the reached points coloured by kappa (the
dimensionless Jacobian's condition number, log scale), the type II locus (red) and the
type I locus (black: the workspace's boundary, where a leg stretches or folds). A box grid
(Delta) is drawn as slices across z."""

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
    for ax, (k, (label, index, near), col) in zip(axs.flat, panels):
        mode = modes[k]
        kappa = np.where(result.reached[..., k], result.values["kappa"][..., k], np.nan)[index]
        x, y = result.coords[0] / u, result.coords[1] / u
        image = ax.pcolormesh(x, y, kappa.T, norm=norm, cmap="viridis", shading="nearest")
        for locus, colour, name in ((result.type1[mode], "black", "type I"), (result.type2[mode], "red", "type II")):
            pts = locus[near(locus)] / u
            ax.plot(pts[:, 0], pts[:, 1], ".", color=colour, markersize=2.5, label=name)
        m = result.measures[mode]
        scale = u ** len(result.coords)
        power = len(result.coords)
        measure = (f"\n{result.kind} {_number(m.value / scale)} +- {_number(m.bound / scale)} {unit}^{power}"
                   if col == 0 else "")
        ax.set_title(f"mode {mode}{label}{measure}", fontsize=8)
        ax.set_aspect("equal")
        ax.set_xlabel(f"x [{unit}]")
        ax.set_ylabel(f"y [{unit}]")
    axs[0, 0].legend(loc="upper left", fontsize=7, markerscale=3)
    fig.colorbar(image, ax=axs, label=f"kappa (J over L = {result.length / u:.4g} {unit})", shrink=0.6)
    fig.suptitle(f"{result.spec.title}: workspace of '{result.spec.point}'", fontsize=10)
    return save(plt, fig, path, tight=False)


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
