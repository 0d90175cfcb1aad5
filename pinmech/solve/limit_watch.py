"""Where an output's rate changes sign over a sweep, including at the sweep's own poses.

An output's limit position is where its rate per unit driver rate changes sign
(limit_positions.py). Pose by pose, the rate's sign is read with a rounding band: a rate
within ZERO_RATE of the output's scale is zero, neither sign. A sign change between two
poses of opposite signs, with or without zero poses between them, brackets a limit
(bisected later); a zero pose at an end of the sweep (an inline slider-crank swept from
its dead centre, theta = 0) is a limit there, named by the rate of the pose beside it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: A rate [rad/rad, or m/rad over the mechanism's size] within this of zero has no sign:
#: rates are exact to about the condition number times eps of their size (~1e-14), and a
#: pose this near a limit is the limit to |rate| / |d rate / d driver|.
ZERO_RATE = 1e-12


@dataclass
class Bracket:
    """Driver values x0 < or > x1 with the output's rate r0 at x0 (closed q0 there), of
    the opposite sign at x1: a limit lies between."""

    x0: float
    q0: np.ndarray
    r0: float
    x1: float


@dataclass
class EndLimit:
    """A limit at a pose at an end of the sweep (its rate zero): driver value x, closed q,
    and 'max' or 'min' of the output there."""

    x: float
    q: np.ndarray
    label: str


@dataclass
class RateWatch:
    """One output's rate signs over a sweep (fed pose by pose with `add`).

    Args:
        scale: the rate's size [1 for a rocker, the mechanism's size for a piston].
    """

    scale: float
    brackets: list[Bracket] = field(default_factory=list)
    ends: list[EndLimit] = field(default_factory=list)
    _last: tuple[float, np.ndarray, float] | None = None  # the last pose with a sign: x, q, rate
    _zeros: list[tuple[float, np.ndarray]] = field(default_factory=list)  # zero poses since it
    _count: int = 0  # poses seen since the last break

    def sign(self, rate: float) -> int:
        return 0 if abs(rate) <= ZERO_RATE * self.scale else (1 if rate > 0 else -1)

    def add(self, x: float, q: np.ndarray, rate: float) -> None:
        """A solved pose: driver value x [rad or m], closed q, the output's rate there."""
        s = self.sign(rate)
        self._count += 1
        if s == 0:
            self._zeros.append((x, q))
            return
        last = self._last
        if last is not None and self.sign(last[2]) != s:
            self.brackets.append(Bracket(last[0], last[1], last[2], x))
        elif last is None and self._zeros and self._count == len(self._zeros) + 1:  # the sweep began on a limit
            x0, q0 = self._zeros[0]
            self.ends.append(EndLimit(x0, q0, "min" if rate * (x - x0) > 0 else "max"))
        self._last, self._zeros = (x, q, rate), []

    def tail(self) -> EndLimit | None:
        """The limit at the last pose so far, where its rate is zero after a pose with a sign."""
        if self._last is None or not self._zeros:
            return None
        x0, _, r0 = self._last
        x, q = self._zeros[-1]
        return EndLimit(x, q, "max" if r0 * (x - x0) > 0 else "min")

    def end(self) -> None:
        """The sweep broke off (an interpolated pose, a fold crossed): a zero pose before the
        break is a limit there; nothing is bracketed across it."""
        found = self.tail()
        if found is not None:
            self.ends.append(found)
        self._last, self._zeros, self._count = None, [], 0

    def limits(self) -> tuple[list[Bracket], list[EndLimit]]:
        """The brackets, and the limits at poses (the last pose's included)."""
        found = self.tail()
        return list(self.brackets), self.ends + ([found] if found is not None else [])
