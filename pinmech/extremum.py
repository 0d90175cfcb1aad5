"""The least (or largest) of a quantity over a sweep, located between the poses: each
quantity is tracked over the poses with the poses on either side of its extreme, then
refined by golden section between them to TOL of the driver (the design summary and the
sweep figures share this one search)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: The driver value of an extreme is refined to this [rad or m].
TOL = 1e-10
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass
class Tracked:
    """The least value of a quantity over the poses so far (`sign` -1: the largest), its
    driver value `at` [rad or m], the closed q there and the driver values of the poses
    just before and after it (None at an end of the sweep or beside a failed pose)."""

    sign: float = 1.0
    value: float = math.inf
    at: float = math.nan
    q: np.ndarray | None = None
    before: float | None = None
    after: float | None = None
    origin: tuple[float, np.ndarray] | None = None  # where poses near `at` are followed from, if not (at, q)

    def __post_init__(self) -> None:
        self.value = self.sign * math.inf  # worse than any value

    def add(self, value: float, at: float, q: np.ndarray, previous: float | None,
            origin: tuple[float, np.ndarray] | None = None) -> None:
        """A solved pose (driver value `at`, the previous solved pose's `previous`); `origin`
        (driver value, closed q): where to follow poses near it from, for a pose no path
        leaves (a fold: the driver's end of travel)."""
        if self.q is not None and self.after is None and previous is not None and self.at == previous:
            self.after = at
        if self.sign * value < self.sign * self.value:
            self.value, self.at, self.q, self.before, self.after = value, at, q.copy(), previous, None
            self.origin = origin

    def follow_from(self) -> tuple[float, np.ndarray]:
        """(driver value, closed q) that trial poses near the extreme are followed from."""
        return self.origin if self.origin is not None else (self.at, self.q)

    def refine(self, f: Callable[[float], float]) -> tuple[float, float]:
        """(driver value, value) of the extreme of f between the poses around it, by golden
        section to TOL; the pose's own value if no trial point beats it."""
        lo = self.at if self.before is None else self.before
        hi = self.at if self.after is None else self.after
        x = golden_minimum(lambda t: self.sign * f(t), min(lo, hi), max(lo, hi))
        fx = f(x)
        return (x, fx) if self.sign * fx <= self.sign * self.value else (self.at, self.value)


def golden_minimum(f: Callable[[float], float], a: float, b: float, tol: float = TOL) -> float:
    """The x in [a, b] where the unimodal f is least, by golden-section search to tol."""
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = f(c), f(d)
    while b - a > tol:
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - _GOLDEN * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + _GOLDEN * (b - a)
            fd = f(d)
    return 0.5 * (a + b)
