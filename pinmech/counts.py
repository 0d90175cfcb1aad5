"""How many poses one run may be asked for: work that would never end is refused first.

A path of 1 s at a step of 1e-300 s, or a sweep of 1e12 steps, is a typing slip, not a
study: at some 1e5 poses a second (the compiled core, without output) ten million poses
are minutes of work and gigabytes of CSV; beyond that pinmech refuses before any work.
"""

from __future__ import annotations

import math

from pinmech.exceptions import OptionError

#: The most poses (sweep rows, path steps, frames) one run computes.
MAX_POSES = 10_000_000


def checked_count(count: float, name: str, what: str) -> None:
    """Refuse a count of poses over MAX_POSES (or not finite), naming where it was asked.

    Args:
        count: the poses asked (a float: duration / step may be 1e300).
        name: where it was asked, as the user wrote it ("models/x.toml: [sweep] step").
        what: how the count came about ("1 s of path at a step of 1e-300 s").

    Raises:
        OptionError: naming `name`, the count and the limit.
    """
    if not count <= MAX_POSES:
        count = float(count) if count < 1e300 else math.inf
        raise OptionError(f"{name}: {what} is {count:.3g} poses, more than the {MAX_POSES:,} one run computes "
                          f"(minutes of work and gigabytes of rows already; this would not end): take a coarser "
                          f"step or split the range", option=name, value=count)
