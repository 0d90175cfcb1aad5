"""Progress and joint-limit watching over the poses of a sweep or the points of a path."""

from __future__ import annotations

import sys


def progress(items, total: int):
    """A progress bar on a terminal (tqdm, if installed); nothing when piped."""
    if not sys.stderr.isatty():
        return items
    try:
        from tqdm import tqdm
    except ImportError:
        return items
    return tqdm(items, total=total, unit="pose", file=sys.stderr, mininterval=0.5)


class LimitWatch:
    """Poses (or path points) that put a joint beyond its limits: counted and summed
    up in a warning, or the run stopped at the first (LimitError) in mode "error"."""

    def __init__(self, mode: str, what: str, column: str = "; see the beyond_limits column") -> None:
        self.mode, self.what, self.column = mode, what, column
        self.count, self.first = 0, ""

    def check(self, violations: list, at: str) -> None:
        from pinmech.solve.limits import enforce

        if violations:
            enforce(violations, self.mode, f"stopped {at}")
            self.count += 1
            self.first = self.first or f"{at}: " + "; ".join(v.describe() for v in violations)

    def summary(self, total: int) -> None:
        if self.count:
            print(f"pinmech: warning: {self.count} of {total} {self.what} put joints beyond their limits "
                  f"(first {self.first}){self.column}", file=sys.stderr)
