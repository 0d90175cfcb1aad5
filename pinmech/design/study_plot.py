"""A study's figures (matplotlib, `pip install "pinmech[plot]"`): the tolerance histograms
with the linear estimate over them, and the sensitivity bars."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinmech.design.study import StudyResult
from pinmech.design.tolerance import deviation

_SCALE = {"length": (1e3, "mm"), "angle": (180 / math.pi, "deg")}


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise ImportError(f'study figures need matplotlib: pip install "pinmech[plot]" ({exc})') from exc
    return plt


def sensitivity_bars(result: StudyResult, path: str | Path) -> Path:
    """One panel per output: the largest |dy/dp| over the cycle for each parameter."""
    plt = _pyplot()
    n = len(result.outputs)
    fig, axes = plt.subplots(1, n, figsize=(3.2 * n + 1, 3.4), squeeze=False)
    for j, ax in enumerate(axes[0]):
        scale, unit = _SCALE[result.kinds[j]]
        worst = np.abs(result.sensitivity[:, j, :]).max(axis=0) * scale / 1e3
        ax.barh(result.params, worst, color="tab:blue")
        ax.invert_yaxis()
        ax.set_title(result.outputs[j])
        ax.set_xlabel(f"max |d/dp| over the cycle [{unit}/mm]")
    fig.suptitle(f"{result.spec.title}: sensitivities over one turn of {result.driver}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def tolerance_histograms(result: StudyResult, path: str | Path) -> Path:
    """One panel per output: the variants' deviation at the pose where the linear sigma is
    largest, with the linear estimate's normal density and its worst case over it."""
    plt = _pyplot()
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
    fig.suptitle(f"{result.spec.title}: {len(causes)} variants, {failed} failed (counted by cause)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
