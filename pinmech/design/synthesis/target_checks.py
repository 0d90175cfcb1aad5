"""Targets no synthesis can use: two in a row at one place, or more on one line than a
four-bar's coupler curve (a sextic) can pass; each refused naming the file and the key."""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.file_where import FileWhere


#: Two targets in a row closer than this share of the targets' extent are one place: the
#: search meets targets to 1e-10 of the linkage's size, and the crank's order between two
#: such targets would be rounding.
COINCIDENT = 1e-6
#: Targets on one line to within this share of their extent are collinear.
COLLINEAR = 1e-9
#: The most collinear targets a four-bar's coupler point can pass: its curve is a sextic,
#: which meets a line in 6 points at most (no four-bar draws an exact straight line).
FOUR_BAR_ON_A_LINE = 6


def refuse_coincident(xy: np.ndarray, w: FileWhere, key: str) -> None:
    """Refuse two targets in a row at one place (within COINCIDENT of the extent)."""
    scale = float(np.linalg.norm(xy.max(axis=0) - xy.min(axis=0)))
    gaps = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    i = int(np.argmin(gaps))
    if not gaps[i] > COINCIDENT * scale:
        raise w.error(f"{key}[{i + 1}]", f"{key}[{i + 1}] is at {key}[{i}]'s place ({gaps[i] * 1e3:.3g} mm apart, "
                      f"within {COINCIDENT:g} of the targets' extent {scale * 1e3:.6g} mm)")


def refuse_collinear(xy: np.ndarray, w: FileWhere, key: str, topology: str) -> None:
    """Refuse more than FOUR_BAR_ON_A_LINE targets on one line for a four-bar's coupler point."""
    if topology != "four-bar" or len(xy) <= FOUR_BAR_ON_A_LINE:
        return
    centred = xy - xy.mean(axis=0)
    scale = float(np.linalg.norm(xy.max(axis=0) - xy.min(axis=0)))
    off = float(np.linalg.svd(centred, compute_uv=False)[-1]) / math.sqrt(len(xy))
    if off <= COLLINEAR * scale:
        raise w.error(key, f"the {len(xy)} {key} lie on one line (RMS {off * 1e3:.3g} mm off it): a four-bar's "
                      f"coupler curve, a sextic, meets a line in {FOUR_BAR_ON_A_LINE} points at most; give at most "
                      f"{FOUR_BAR_ON_A_LINE}, or a slider-crank (its slider's points move on a line)")
