"""The one convention for the angles pinmech reports as positions (a crank's angle, a
limit position, a dead centre, where an extreme lies): from world x, counter-clockwise, in
[0, 360) deg ([0, 2 pi) rad). Values along a motion (a sweep's driver column, a synthesis's
crank angles from target to target) start there and run on continuously the way the crank
turns, so they may pass 360 or fall below 0; a driver angle read from a file names a
physical angle, whole turns apart being the same pose of a drawn linkage."""

from __future__ import annotations

import math

TURN = 2 * math.pi


def turn_radians(angle: float) -> float:
    """`angle` [rad] moved by whole turns into [0, 2 pi) (never 2 pi itself)."""
    r = math.fmod(float(angle), TURN)
    if r < 0:
        r += TURN
    return 0.0 if r >= TURN else r + 0.0  # + 0.0: -0.0 is 0


def turn_degrees(angle: float) -> float:
    """`angle` [deg] moved by whole turns into [0, 360) (never 360 itself)."""
    r = math.fmod(float(angle), 360.0)
    if r < 0:
        r += 360.0
    return 0.0 if r >= 360.0 else r + 0.0


def position_text(angle: float, spec: str = ".6g") -> str:
    """An angle [deg] as a printed position: in [0, 360), rounded to 1e-5 deg first (a
    located extreme 5e-7 deg past 0 is "0", not "4.8e-07" or "360"), formatted with `spec`."""
    x = round(turn_degrees(angle), 5) + 0.0
    return format(0.0 if x >= 360.0 else x, spec)
