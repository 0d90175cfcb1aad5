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


#: The most memory the arrays of one study, workspace map or synthesis may take [bytes]:
#: 2 GiB. The bundled tolerance study holds 5 MB; a file asking more (10 million variants
#: x 100,000 poses would be 24 TB) is refused when it is read, before anything is allocated.
MAX_BYTES = 2 * 2**30


def memory_refusal(nbytes: float, what: str, lower: str) -> str | None:
    """The message refusing an estimate of `nbytes` over MAX_BYTES, else None.

    Args:
        nbytes: the arrays' bytes, estimated from the file's counts (float: may be huge).
        what: how the estimate comes about ("2000 variants x 73 poses x 4 outputs").
        lower: what to lower ("samples or steps").
    """
    if nbytes <= MAX_BYTES:
        return None
    return (f"{what} would hold about {nbytes / 2**30:.3g} GiB of arrays, more than the "
            f"{MAX_BYTES / 2**30:g} GiB one run may: lower {lower}")
