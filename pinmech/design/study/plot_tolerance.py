"""A tolerance study's figures as a designer reads them (matplotlib, `pip install
"pinmech[plot]"`): the spread of each output over the cycle (worst case, RSS, 3 sigma
linear and Monte Carlo against the driver's angle, the spec's limits on it), the coupler
curves with their 3-sigma ellipses, and each output's Pareto chart of the dimensions'
shares of its variance (stackup.py holds the definitions)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinmech.design.figure_file import pyplot, save
from pinmech.design.study.outputs import USER_UNITS
from pinmech.design.study.stackup import covariances, ellipse, point_pairs, stackup
from pinmech.design.study.plot import titled

_NICE = (1.0, 2.0, 5.0)


def _over(st) -> str:
    failed = st.samples - st.solved
    return f"Monte Carlo over the {st.solved} of {st.samples} variants that solved" + (f" ({failed} failed)" if failed else "")


def _angles(result) -> np.ndarray:
    """The driver's values [deg], unwrapped from the first (the cycle's order)."""
    return np.degrees(result.values)


def sigma_curves(result, path: str | Path) -> Path:
    """One panel per output: worst case, RSS, 3 sigma linear and 3 sigma Monte Carlo of its
    deviation at every pose against the driver's angle, and the spec's limits."""
    plt = pyplot("study")
    st, x = stackup(result), _angles(result)
    n = len(result.outputs)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n + 0.6, 3.8), squeeze=False, layout="constrained")
    for j, ax in enumerate(axes[0]):
        scale, unit = USER_UNITS[result.kinds[j]]
        ax.plot(x, st.worst[:, j] * scale, color="tab:red", ls="--", lw=1.2, label="worst case  sum |S| t")
        ax.plot(x, st.rss[:, j] * scale, color="tab:orange", lw=1.2, label="RSS  sqrt(sum (S t)^2)")
        ax.plot(x, 3 * st.sigma_linear[:, j] * scale, color="black", lw=1.2, label="3 sigma linear")
        ax.plot(x, 3 * st.sigma[:, j] * scale, "o", color="tab:blue", ms=2.5, label="3 sigma Monte Carlo")
        if result.outputs[j] in result.limits:
            lo, hi = result.limits[result.outputs[j]]
            ax.axhline(max(-lo, hi) * scale, color="tab:green", lw=1.0, label="spec limit |deviation|")
        ax.set_xlim(x[0], x[-1])
        ax.set_ylim(0, None)
        ax.set_xlabel(f"{result.driver} [deg]")
        ax.set_ylabel(f"{result.outputs[j]}: spread of the deviation [{unit}]")
        ax.set_title(result.outputs[j])
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7, loc="best")
    fig.suptitle(f"{titled(result)}\n{_over(st)}; t: a uniform's half width, else 3 sigma", fontsize=10)
    return save(plt, fig, path, tight=False)


def ellipse_curves(result, path: str | Path, every: int | None = None) -> Path:
    """One panel per point output (x and y both outputs): its nominal path over the cycle
    with the 3-sigma ellipses of its position at every `every`-th pose (Monte Carlo solid,
    linear dashed), magnified by a stated factor so that they show."""
    plt = pyplot("study")
    pairs = point_pairs(result.outputs)
    if not pairs:
        from pinmech.exceptions import OptionRefused

        raise OptionRefused("3-sigma ellipses need a point's x and y among the outputs ([outputs] points)",
                            options=["--plot"])
    st = stackup(result)
    fig, axes = plt.subplots(1, len(pairs), figsize=(5.2 * len(pairs) + 0.4, 5.0), squeeze=False,
                             layout="constrained")
    step = every or max(1, len(result.values) // 12)
    for (name, ix, iy), ax in zip(pairs, axes[0]):
        path_xy = result.nominal[:, [ix, iy]] * 1e3
        linear, mc = covariances(result, ix, iy)
        size = float(np.ptp(path_xy, axis=0).max()) or 1.0
        largest = 3e3 * math.sqrt(max(float(np.linalg.eigvalsh(c).max()) for c in linear)) or 1.0
        k = _nice(size / 12 / largest)
        ax.plot(path_xy[:, 0], path_xy[:, 1], color="0.35", lw=1.0, label=f"{name}: nominal path")
        for i in range(0, len(result.values), step):
            centre = path_xy[i]
            e_lin = centre + k * ellipse(linear[i]) * 1e3
            ax.plot(e_lin[:, 0], e_lin[:, 1], "k--", lw=0.8, label="3 sigma linear" if i == 0 else None)
            if np.all(np.isfinite(mc[i])):
                e_mc = centre + k * ellipse(mc[i]) * 1e3
                ax.plot(e_mc[:, 0], e_mc[:, 1], color="tab:blue", lw=1.1, label="3 sigma Monte Carlo" if i == 0 else None)
            ax.plot(*centre, ".", color="tab:red", ms=4)
        ax.annotate(f"{result.driver} = {math.degrees(result.values[0]) % 360:.0f} deg", path_xy[0], fontsize=7,
                    xytext=(4, 4), textcoords="offset points")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title(f"{name}: 3-sigma ellipses, drawn x{k:g}", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"{titled(result)}\n{_over(st)}; every {step} poses", fontsize=10)
    return save(plt, fig, path, tight=False)


def pareto(result, path: str | Path) -> Path:
    """One panel per output: each dimension's share of its linear variance (S_i sigma_i)^2 /
    sigma^2 at the pose of its largest sigma, largest first, with the cumulative share."""
    plt = pyplot("study")
    st = stackup(result)
    n = len(result.outputs)
    fig, axes = plt.subplots(1, n, figsize=(3.8 * n + 0.6, 3.8), squeeze=False, layout="constrained")
    for j, ax in enumerate(axes[0]):
        i = int(np.argmax(st.sigma_linear[:, j]))
        share = 100.0 * st.contribution[i, j]
        order = np.argsort(-share)
        names = [result.params[k] for k in order]
        ax.bar(names, share[order], color="tab:blue")
        twin = ax.twinx()
        twin.plot(names, np.cumsum(share[order]), "o-", color="tab:red", ms=3)
        twin.set_ylim(0, 105)
        twin.set_ylabel("cumulative [%]", color="tab:red")
        ax.set_ylim(0, 105)
        ax.set_ylabel("share of the variance [%]")
        ax.tick_params(axis="x", rotation=45)
        scale, unit = USER_UNITS[result.kinds[j]]
        ax.set_title(f"{result.outputs[j]} at {result.driver} = {math.degrees(result.values[i]) % 360:.0f} deg\n"
                     f"(sigma linear {st.sigma_linear[i, j] * scale:.3g} {unit})", fontsize=9)
    fig.suptitle(f"{titled(result)}: shares (S_i sigma_i)^2 / sigma^2", fontsize=10)
    return save(plt, fig, path, tight=False)


def _nice(x: float) -> float:
    """The largest of 1, 2, 5 x 10^k not above x (at least 1)."""
    if x <= 1:
        return 1.0
    e = 10.0 ** math.floor(math.log10(x))
    return max(m * e for m in _NICE if m * e <= x)
