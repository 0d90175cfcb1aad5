"""A study's figures (matplotlib, `pip install "pinmech[plot]"`): the tolerance histograms
with the linear estimate over them, and the sensitivity bars."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinmech.design.figure_file import pyplot, save
from pinmech.design.study.outputs import USER_UNITS as _SCALE
from pinmech.design.study.run import StudyResult
from pinmech.design.study.tolerance import deviation
from pinmech.solve.certify import dial_caption



def titled(result: StudyResult) -> str:
    """The study's title for a figure, with the certification dial where fewer poses than
    all were certified (certify.py)."""
    caption = dial_caption(result.certify)
    return result.spec.title if caption is None else f"{result.spec.title} ({caption})"


def sensitivity_bars(result: StudyResult, path: str | Path) -> Path:
    """One panel per output: the largest |dy/dp| over the cycle for each parameter."""
    plt = pyplot("study")
    n = len(result.outputs)
    fig, axes = plt.subplots(1, n, figsize=(3.2 * n + 1, 3.4), squeeze=False)
    for j, ax in enumerate(axes[0]):
        scale, unit = _SCALE[result.kinds[j]]
        worst = np.abs(result.sensitivity[:, j, :]).max(axis=0) * scale / 1e3
        ax.barh(result.params, worst, color="tab:blue")
        ax.invert_yaxis()
        ax.set_title(result.outputs[j])
        ax.set_xlabel(f"max |d/dp| over the cycle [{unit}/mm]")
    fig.suptitle(f"{titled(result)}: sensitivities over the cycle of {result.driver}")
    return save(plt, fig, path)


def tolerance_histograms(result: StudyResult, path: str | Path) -> Path:
    """One panel per output: the variants' deviation at the pose where the linear sigma is
    largest, with the linear estimate's normal density and its worst case over it."""
    plt = pyplot("study")
    s, (_, y, causes) = result.spread, result.variants
    ok = np.array([not c for c in causes], dtype=bool)
    dev = deviation(y[ok], result.nominal, result.kinds)
    n = len(result.outputs)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n + 1, 3.4), squeeze=False)
    for j, ax in enumerate(axes[0]):
        scale, unit = _SCALE[result.kinds[j]]
        i = int(np.argmax(s.sigma_linear[:, j]))
        d = dev[:, i, j] * scale
        ax.hist(d, bins=40, density=True, color="tab:blue", alpha=0.6, label=f"Monte Carlo ({len(d)})")
        sig = s.sigma_linear[i, j] * scale
        x = np.linspace(-4 * sig, 4 * sig, 200)
        ax.plot(x, np.exp(-0.5 * (x / sig) ** 2) / (sig * math.sqrt(2 * math.pi)), "k-",
                label=f"linear: sigma {sig:.3g} {unit}")
        for w in (-1, 1):
            ax.axvline(w * s.worst_linear[j] * scale, color="tab:red", ls="--", lw=1,
                       label="linear worst case" if w > 0 else None)
        ax.set_title(f"{result.outputs[j]} at {result.driver} = {math.degrees(result.values[i]) % 360:.0f} deg")
        ax.set_xlabel(f"deviation from nominal [{unit}]")
        ax.legend(fontsize=7)
    failed = len(causes) - int(ok.sum())
    fig.suptitle(f"{titled(result)}: {len(causes)} variants, {failed} failed (counted by cause)")
    return save(plt, fig, path)


def grid_figure(result: StudyResult, path: str | Path) -> Path:
    """One panel per output over a grid study: for 1-D its min and max over the cycle
    against the parameter (failed points marked x on the axis); for 2-D a map of its range
    over the cycle (max - min) with the failed cells hatched; and a panel of the least
    transmission angle where the mechanism has one. 3-D grids have no figure."""
    from pinmech.exceptions import OptionRefused

    axes_g = result.spec.grid
    if len(axes_g) > 2:
        raise OptionRefused(f"{result.spec.path}: a grid of {len(axes_g)} parameters has no figure (1-D or 2-D only); "
                            "read the table", options=["--plot"])
    plt = pyplot("study")
    panels = _grid_panels(result)
    failed = np.array([bool(c) for c in result.variants[2]])
    fig, axes = plt.subplots(1, len(panels), figsize=(3.8 * len(panels) + 1, 3.6), squeeze=False)
    for (title, unit, lo, hi), ax in zip(panels, axes[0]):
        if len(axes_g) == 1:
            _grid_line(ax, axes_g[0], lo, hi, failed, unit)
        else:
            _grid_map(fig, ax, axes_g, hi - lo if hi is not lo else lo, failed,
                      f"max - min over the cycle [{unit}]" if hi is not lo else f"least over the cycle [{unit}]")
        ax.set_title(title)
    fig.suptitle(f"{titled(result)}: {len(failed)} points, {int(failed.sum())} failed (marked)")
    return save(plt, fig, path)


def _grid_panels(result: StudyResult) -> list[tuple[str, str, np.ndarray, np.ndarray]]:
    """(title, unit, min, max) of each output over the cycle at each point, in the users'
    units; the least transmission angle's panel has min and max the same array."""
    from pinmech.design.study.grid import cycle_range

    lo, hi = cycle_range(result.variants[1], result.kinds)
    panels = []
    for j, name in enumerate(result.outputs):
        scale, unit = _SCALE[result.kinds[j]]
        panels.append((name, unit, lo[:, j] * scale, hi[:, j] * scale))
    if result.transmission is not None:
        mu = np.degrees(result.transmission)
        panels.append(("least acute transmission angle", "deg", mu, mu))
    return panels


def _grid_line(ax, axis, lo: np.ndarray, hi: np.ndarray, failed: np.ndarray, unit: str) -> None:
    size, unit = _axis_unit(axis)
    x = np.asarray(axis.values) / size
    if hi is not lo:
        ax.plot(x, hi, "o-", color="tab:red", ms=3, label="max over the cycle")
    ax.plot(x, lo, "o-", color="tab:blue", ms=3, label="min over the cycle" if hi is not lo else "least over the cycle")
    if failed.any():
        ax.plot(x[failed], np.zeros(int(failed.sum())), "kx", transform=ax.get_xaxis_transform(), clip_on=False,
                label="failed (see table)")
    ax.set_xlabel(f"{axis.name} [{unit}]")
    ax.set_ylabel(f"[{unit}]")
    ax.legend(fontsize=7)


def _grid_map(fig, ax, axes_g, value: np.ndarray, failed: np.ndarray, label: str) -> None:
    shape = (axes_g[0].count, axes_g[1].count)
    x, y = (np.asarray(a.values) / _axis_unit(a)[0] for a in axes_g)
    mesh = ax.pcolormesh(y, x, np.ma.masked_array(value.reshape(shape), failed.reshape(shape)), shading="nearest")
    fig.colorbar(mesh, ax=ax, label=label)
    from matplotlib.patches import Rectangle

    hx, hy = (_half(c) for c in (y, x))
    for i, k in zip(*np.nonzero(failed.reshape(shape))):
        ax.add_patch(Rectangle((y[k] - hx, x[i] - hy), 2 * hx, 2 * hy, facecolor="0.92", edgecolor="0.45",
                               hatch="xx", lw=0.0, label="failed (see table)" if not ax.patches else None))
    if failed.any():
        ax.legend(fontsize=7, loc="lower right")
    ax.set_xlabel(f"{axes_g[1].name} [{_axis_unit(axes_g[1])[1]}]")
    ax.set_ylabel(f"{axes_g[0].name} [{_axis_unit(axes_g[0])[1]}]")


def _axis_unit(axis) -> tuple[float, str]:
    """A grid axis's users' unit: (SI per unit, "mm" or "deg") by its parameter's kind."""
    return (math.pi / 180, "deg") if axis.kind == "angle" else (1e-3, "mm")


def _half(centres: np.ndarray) -> float:
    """Half a cell's width around evenly spaced centres (a single centre: 0.5)."""
    return float(centres[1] - centres[0]) / 2 if len(centres) > 1 else 0.5

