"""Each dyad's transmission angle over a sweep: least and largest, and the largest pressure
angle, over the driver's whole range of motion, located between the poses.

Conventions (transmission.py): the transmission angle mu is on [0, 180] deg (Norton's
angle between the coupler and the output; 90 best), the pressure angle its deviation
|90 - mu| (acute mu = 90 - pressure). A slider's or slot's mu = 90 - phi is on [0, 90].

Three kinds of extreme, each found where it lies:

- inside the range, between two poses: the poses on either side bracket it, golden
  section refines it to extremum.TOL (`Tracked`);
- where coupler and output fall in line (a toggle passed, a change point): the side
  of the line they are on (`dyad_side`) changes sign between two poses; bisection on
  that sign locates it, and mu is 0 or 180 deg there exactly, the pressure angle 90;
- at a fold of the driver (the end of its travel: a rocker's toggle): the pose at the
  fold, located to rounding (fold_pose.py), counted as a pose of the range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.extremum import TOL, Tracked
from pinmech.solve.transmission import DyadAngles, dyad_angles, dyad_side


#: A transmission angle whose least and largest differ by no more than this [deg] is one
#: constant value: the angles come from unit vectors rounded at ~1e-14 deg, so a spread below
#: 1e-9 deg is rounding, and "from 90 deg at one pose to 90 deg at another" says nothing.
CONSTANT_ANGLE_DEG = 1e-9


@dataclass(frozen=True)
class AngleExtremes:
    """A dyad's (named by its pin B) least and largest transmission angle mu [deg] on
    [0, 180] and largest pressure angle |90 - mu| [deg], each with its driver value [rad
    or m]; `refined` False where one is the value over the poses only (a trial pose
    beside it did not close), `in_line` the driver values where the coupler and the output
    fell in line (mu 0 or 180 deg)."""

    name: str
    low: float
    low_at: float
    high: float
    high_at: float
    pressure: float
    pressure_at: float
    refined: bool
    in_line: tuple[float, ...] = ()

    @property
    def acute_low(self) -> float:
        """The least acute transmission angle, 90 - the largest pressure angle [deg]."""
        return 90.0 - self.pressure

    @property
    def constant(self) -> bool:
        """Whether mu is one value at every pose (an inverted slider's block square to its rod):
        its least and largest within CONSTANT_ANGLE_DEG, rounding of unit vectors (~1e-14 deg)."""
        return bool(self.high - self.low <= CONSTANT_ANGLE_DEG)

    def as_dict(self) -> dict:
        """SI: angles [rad], driver values [rad or m]."""
        rad = math.radians
        return {"pin": self.name, "transmission_angle_least": rad(self.low), "transmission_angle_least_at": self.low_at,
                "transmission_angle_largest": rad(self.high), "transmission_angle_largest_at": self.high_at,
                "pressure_angle_largest": rad(self.pressure), "pressure_angle_largest_at": self.pressure_at,
                "transmission_angle_acute_least": rad(self.acute_low), "in_line_at": list(self.in_line),
                "located": self.refined, "transmission_angle_constant": self.constant}


@dataclass
class _Side:
    """The last solved pose's side of the line (x, q, dyad_side), and the brackets found."""

    last: tuple[float, np.ndarray, float] | None = None
    brackets: list[tuple[float, np.ndarray, float, float]] | None = None


class AngleWatch:
    """The transmission angles of every dyad of a sweep, fed pose by pose.

    Args:
        dyads: the linkage's dyads; place_at: (q0, x0, x) -> places the linkage at the pose
            followed from q0 at x0 to driver value x (raises PinmechError where it cannot).
    """

    def __init__(self, linkage, dyads, place_at) -> None:
        self.linkage, self.dyads, self.place_at = linkage, list(dyads), place_at
        self.least = [Tracked(1.0) for _ in self.dyads]
        self.largest = [Tracked(-1.0) for _ in self.dyads]
        self.pressure = [Tracked(-1.0) for _ in self.dyads]
        self.sides = [_Side(None, []) for _ in self.dyads]

    def add(self, x: float, q: np.ndarray, previous: float | None, angles: list[DyadAngles], *,
            origin: tuple[float, np.ndarray] | None = None, bracket: bool = True) -> None:
        """A pose of the range (the linkage placed at q): its angles; `origin` for a pose no
        path leaves (a fold); `bracket` False for one whose q is not closed (interpolated)."""
        for i, (dyad, a) in enumerate(zip(self.dyads, angles)):
            self.least[i].add(a.mu, x, q, previous, origin)
            self.largest[i].add(a.mu, x, q, previous, origin)
            self.pressure[i].add(a.pressure, x, q, previous, origin)
            side, now = self.sides[i], dyad_side(self.linkage, dyad)
            if bracket and origin is None and side.last is not None and side.last[2] * now < 0:
                side.brackets.append((side.last[0], side.last[1], side.last[2], x))
            if bracket and origin is None:
                side.last = (x, q, now)

    def cut(self) -> None:
        """No bracket across here (a fold crossed, a failed pose at a fold)."""
        for side in self.sides:
            side.last = None

    def extremes(self) -> list[AngleExtremes]:
        return [self._extremes(i) for i in range(len(self.dyads))]

    def _extremes(self, i: int) -> AngleExtremes:
        dyad, found, refined = self.dyads[i], [], True
        for tracked, what in ((self.least[i], "mu"), (self.largest[i], "mu"), (self.pressure[i], "pressure")):
            try:
                found.append(tracked.refine(lambda x, t=tracked, w=what: self._angle(dyad, t, x, w)))
            except PinmechError:  # a trial pose beside a fold or a change point: the value over the poses
                found.append((tracked.at, tracked.value))
                refined = False
        (low_at, low), (high_at, high), (p_at, p) = found
        lines = [self._in_line(dyad, *b) for b in self.sides[i].brackets]
        for x, mu in lines:  # mu is 0 or 180 deg there, the pressure angle 90
            if mu < low:
                low, low_at = mu, x
            if mu > high:
                high, high_at = mu, x
            if p < 90.0:
                p, p_at = 90.0, x
        return AngleExtremes(dyad.joint.name, low, low_at, high, high_at, p, p_at, refined,
                             tuple(x for x, _ in lines))

    def _angle(self, dyad, tracked: Tracked, x: float, what: str) -> float:
        """An angle of the dyad [deg] at driver value x, the pose followed from the tracked one."""
        at, q = tracked.follow_from()
        self.place_at(q, at, x)
        return getattr(dyad_angles(self.linkage, dyad), what)

    def _in_line(self, dyad, x0: float, q0: np.ndarray, s0: float, x1: float) -> tuple[float, float]:
        """Where the dyad's side changes sign between x0 and x1, by bisection to TOL (or to
        where the poses stop closing: a change point's own pose is singular), and mu there:
        0 or 180 deg, as mu approaches it."""
        self.place_at(q0, x0, x0)
        a, b, mu = x0, x1, dyad_angles(self.linkage, dyad).mu
        while abs(b - a) > TOL:
            m = 0.5 * (a + b)
            try:
                self.place_at(q0, x0, m)
            except PinmechError:  # within rounding of a singular pose: the bracket is the answer
                break
            side = dyad_side(self.linkage, dyad)
            mu = dyad_angles(self.linkage, dyad).mu
            if side == 0.0:
                a = b = m
            elif (side > 0) == (s0 > 0):
                a = m
            else:
                b = m
        return 0.5 * (a + b), (0.0 if mu < 90.0 else 180.0) if dyad.kind == "pin" else 0.0
