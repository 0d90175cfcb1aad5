"""Curves of a sweep figure against the driver: the driver axis (0-360° for a whole turn),
angles made continuous or wrapped, one style per branch past a fold, and y limits that do
not let a fold's spike flatten a panel.
"""

from __future__ import annotations

import math

import numpy as np

#: Line styles, one per assembly (a fold changes it).
BRANCH_STYLES = ("-", "--", "-.", ":")
#: A panel's y range reaches this many times the spread of its middle 96% beyond it before
#: the rest is clipped: a fold's spike (α reaches 7.5e5 rad/s² near a four-bar's limit
#: position, where it is 1e2 elsewhere) must not flatten the panel.
SPIKE_FACTOR = 1.0


#: Mechanisms smaller than this [m] are drawn in mm, larger ones in m (one unit a figure).
MM_BELOW = 5.0


def length_unit(size: float) -> tuple[float, str]:
    """(factor from m, unit) a figure draws lengths in, for a mechanism of `size` [m]:
    mm below MM_BELOW (a textbook linkage, an arm), m above."""
    return (1000.0, "mm") if size < MM_BELOW else (1.0, "m")


def driver_axis(x: np.ndarray, angular: bool) -> tuple[np.ndarray, np.ndarray, bool]:
    """The driver values as drawn, the order of the poses along them, and whether they
    make one whole turn (then drawn from 0 to 360 deg, whatever angle the sweep began at;
    `angular` False: as swept)."""
    finite = x[np.isfinite(x)]
    turn = angular and finite.size > 1 and abs(np.ptp(finite) - 360.0) <= 1e-9 * 360.0
    if not turn:
        return x, np.arange(len(x)), False
    wrapped = np.mod(x, 360.0)
    order = np.argsort(wrapped, kind="stable")
    wrapped = wrapped[order]
    at_zero = np.nonzero(np.isclose(wrapped, 0.0, atol=1e-9))[0]
    if at_zero.size:  # the pose at 0 deg closes the turn at 360 deg too
        order = np.append(order, order[at_zero[0]])
        wrapped = np.append(wrapped, 360.0)
    return wrapped, order, True


def angles(y: np.ndarray, style: str) -> np.ndarray:
    """Angles [deg] along the driver: continuous (no jump at +-180, starting in (-180, 180]),
    or wrapped to (-180, 180] with a gap where they jump."""
    y = y.copy()
    ok = np.isfinite(y)
    if style == "continuous":
        y[ok] = np.degrees(np.unwrap(np.radians(y[ok])))
        y[ok] -= 360.0 * math.ceil((y[ok][0] - 180.0) / 360.0) if y[ok].size else 0.0
        return y
    y[ok] = 180.0 - np.mod(180.0 - y[ok], 360.0)
    y[np.nonzero(np.abs(np.diff(y)) > 180.0)[0]] = math.nan  # no vertical line where it wraps
    return y


def nearest(x: np.ndarray, y: np.ndarray, at_x: float, fallback: float) -> float:
    """y at the drawn x nearest `at_x` (`fallback` where that pose failed)."""
    i = int(np.argmin(np.abs(x - at_x)))
    return float(y[i]) if np.isfinite(y[i]) else fallback


def branch_pieces(branch: np.ndarray) -> list[tuple[int, np.ndarray]]:
    """(branch number, mask of the poses drawn in its style) for each branch in `branch`
    (one number a pose); each piece takes the next pose too, so the curve stays joined."""
    out = []
    for b in np.unique(branch):
        mask = branch == b
        mask[1:] |= mask[:-1].copy()
        out.append((int(b), mask))
    return out


def spike_limits(curves: list[np.ndarray]) -> tuple[float, float, float] | None:
    """(low, high, the largest |y|) to draw a panel within when a few poses spike far past
    the rest (a fold), else None: the middle 96% of the values, widened by SPIKE_FACTOR of
    its spread on each side."""
    values = np.concatenate([c[np.isfinite(c)] for c in curves]) if curves else np.array([])
    if values.size < 10:
        return None
    lo, hi = np.percentile(values, [2.0, 98.0])
    spread = max(hi - lo, 1e-12 * max(abs(lo), abs(hi)), 1e-300)
    low, high = lo - SPIKE_FACTOR * spread, hi + SPIKE_FACTOR * spread
    if values.min() >= low and values.max() <= high:
        return None
    return max(low, float(values.min())), min(high, float(values.max())), float(np.max(np.abs(values)))


def legend_beside(ax) -> None:
    """A panel's legend beside it, never over its curves."""
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)


def draw_markers(axes, markers: list[tuple[float, str]]) -> None:
    """Vertical lines at driver values (limit, toggle, fold positions) in every panel, each
    labelled once, at the top of the first panel; a marker met again (each pass through
    folds meets the same limits) is drawn once."""
    seen: set[tuple[float, str]] = set()
    markers = [m for m in markers if (round(m[0], 6), m[1]) not in seen and not seen.add((round(m[0], 6), m[1]))]
    for k, ax in enumerate(axes):
        for x, label in markers:
            ax.axvline(x, color="0.3", linestyle=(0, (4, 2, 1, 2)), linewidth=0.9, zorder=1, gid="marker")
            if k == 0:
                ax.annotate(label, (x, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -2),
                            textcoords="offset points", ha="left", va="top", fontsize=7.5, color="0.25",
                            rotation=90, gid="marker")
