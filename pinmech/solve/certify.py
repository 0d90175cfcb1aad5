"""The certification dial: which poses of a range get the exact condition number (and the
error bounds it gives; the compiled core's `certify_every`).

Every pose gets its closure, velocity and acceleration residuals, the trust region, the
tangent's turn limit and its assembly signature, whatever the level. The levels, as a user
writes them:

- "every-pose" (the default): every pose certified.
- "every-K" (K >= 2, e.g. "every-10"): every K-th pose of a range and its last.
- "ends": the last pose of each range (its first is certified already).
- "none": no pose: residual tolerances and the assembly check only.

Where a step between certified poses is refused (singular, not finite, turning too fast,
another signature), or a certified pose finds a condition number over max_condition, the
core goes back to the last certified pose and certifies every pose up to that one: it
stops, names and locates what it met as at every pose.
"""

from __future__ import annotations

import math
import re

from pinmech.exceptions import OptionError
from pinmech.model.closure_core import _core

#: The level every pose is certified at (the default).
EVERY_POSE = "every-pose"
#: The levels a user may write (K: a whole number >= 2).
LEVELS = ("every-pose", "every-K", "ends", "none")
#: The largest K of "every-K" (a range's poses are at most this many apart to be certified).
MAX_K = 1_000_000
#: What a table or report says of a pose whose condition number was not computed.
NOT_CERTIFIED = "not certified at this pose"

_EVERY = re.compile(r"every-(\d+)")


def checked_certify(value: object) -> str:
    """`value` as one of LEVELS (normalised: "every-1" is "every-pose"), else an OptionError
    naming the levels and the value."""
    text = value.strip().lower() if isinstance(value, str) else None
    if text in (EVERY_POSE, "ends", "none"):
        return text
    match = _EVERY.fullmatch(text) if text is not None else None
    if match and 1 <= int(match.group(1)) <= MAX_K:
        return EVERY_POSE if int(match.group(1)) == 1 else f"every-{int(match.group(1))}"
    raise OptionError(f"certify = {value!r} must be one of {', '.join(LEVELS)} (K a whole number from 2 to "
                      f"{MAX_K}, e.g. \"every-10\")", option="certify", value=value)


def core_level(certify: str) -> int:
    """The compiled core's `certify_every` for a checked level: 1 every pose, K, 0 ends, -1 none."""
    if certify == EVERY_POSE:
        return _core.CERTIFY_EVERY_POSE
    if certify == "ends":
        return _core.CERTIFY_ENDS
    if certify == "none":
        return _core.CERTIFY_NONE
    return int(certify.split("-", 1)[1])


def certified_text(certify: str) -> str:
    """The level in words, for outputs: "every pose", "every 10 poses", "the last pose of each
    range", "no pose"."""
    if certify == EVERY_POSE:
        return "every pose"
    if certify == "ends":
        return "the last pose of each range"
    if certify == "none":
        return "no pose"
    return f"every {certify.split('-', 1)[1]} poses"


def dial_note(certify: str) -> str | None:
    """One line an output carries when its answer was computed with less than every pose
    certified (None at every pose)."""
    if certify == EVERY_POSE:
        return None
    return (f"condition number (and the error bounds it gives) certified at {certified_text(certify)} "
            f"(certify = \"{certify}\"); closure, velocity and acceleration residuals and the assembly at every pose")


def dial_caption(certify: str) -> str | None:
    """A figure's short line for the level (None at every pose)."""
    if certify == EVERY_POSE:
        return None
    if certify == "none":
        return "no condition number (residuals and assembly checked at every pose)"
    return f"condition number at {certified_text(certify)} only (residuals and assembly at every pose)"


def condition_words(condition: float, digits: int = 3) -> str:
    """A condition number for a report: the number, or NOT_CERTIFIED where it is NaN (a pose
    the dial left uncertified)."""
    return NOT_CERTIFIED if math.isnan(condition) else f"{condition:.{digits}g}"
