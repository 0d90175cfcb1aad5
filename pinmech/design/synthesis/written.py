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
