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
    """An angle [deg] as a position, formatted with `spec`: in [0, 360), and never "360"
    (359.9999999 rounded to 6 figures is the position 0)."""
    text = format(turn_degrees(angle), spec)
    return format(0.0, spec) if float(text) >= 360.0 else text
