"""Numbers as a synthesis writes them into its linkage and scene files: to the last bit of
the float (Python's shortest repr), so the written drawing is the refined linkage the run
reports, not a rounding of it."""

from __future__ import annotations

import math


def mm_text(v: float) -> str:
    """A length [m] as TOML text in mm."""
    return f"{float(v) * 1e3!r} mm"


def deg_text(v: float) -> str:
    """An angle [rad] as TOML text in deg."""
    return f"{math.degrees(float(v))!r} deg"


def targets_text(point: str, targets) -> str:
    """A scene's `[sweep] targets` line: the task's target places of `point` [m], (N, 2) in
    the linkage's plane, written in mm to 12 significant figures, as a user writes them (the
    paths figure draws them on the point's path)."""
    pairs = ", ".join(f"[\"{1e3 * float(x):.12g} mm\", \"{1e3 * float(y):.12g} mm\"]" for x, y in targets)
    return f"targets = {{{point} = [{pairs}]}}"
