"""Limit positions and transmission-angle extremes located from a turn's swept poses, each
then closed by one solve at its driver value (the engine's `LimitFinder.pose`, followed
from the pose before it, on the drawn assembly):

- a limit position lies where an output's rate per unit driver changes sign between two
  poses; its driver value is the root of the cubic through the rate and its derivative
  at both (Hermite: an error of order h^4 r''''/384, some 1e-9 rad for 1-degree poses),
  polished by one Newton step on the engine's rate at the closed pose there; its label
  and value are the engine's (`LimitFinder.limit`) at that pose;
- a least or largest transmission angle lies at the vertex of the parabola through the
  least (largest) sampled angle and its two neighbours (a whole turn wraps around), its
  value the engine's `dyad_angles` at the closed pose there (the angle's error is of the
  second order in the vertex's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.solve.limit_positions import extreme_label
from pinmech.solve.transmission import dyad_angles


@dataclass(frozen=True)
class Extreme:
    """A dyad's transmission angle at its least or largest [deg] and the driver there."""

    value: float
    at: float
    refined: bool


def hermite_root(cubic: np.ndarray, r0: float, r1: float) -> float | None:
    """The root in [0, 1] of a step's `cubic` (its rate r0, r1 at the ends), as a fraction
    of the step, or None (no sign change)."""
    if r0 == 0.0:
        return 0.0
    if r0 * r1 > 0:
        return None
    s = r0 / (r0 - r1)  # the chord's root, then Newton on the cubic (kept in [0, 1])
    for _ in range(30):
        value, slope = np.polyval(cubic, s), np.polyval(np.polyder(cubic), s)
        if slope == 0.0:
            break
        step = value / slope
        s = min(1.0, max(0.0, s - step))
        if abs(step) < 1e-15:
            break
    return float(s)


def limit_poses(design, output, x: np.ndarray, q: np.ndarray, rate: np.ndarray, change: np.ndarray) -> list:
    """(LimitPosition, closed q) of an output at every sign change of its rate over the poses."""
    found = []
    for i in range(len(x) - 1):
        h = float(x[i + 1] - x[i])
        s = hermite_root(_cubic(rate, change, i, h), float(rate[i]), float(rate[i + 1]))
        if s is None or (s == 0.0 and i > 0 and rate[i - 1] * rate[i + 1] > 0):
            continue  # no change of sign (a zero touched and left on the same side is no limit)
        at = float(x[i] + s * h)
        try:
            closed = design.finder.pose(q[i], float(x[i]), at)
            at, closed = _polished(design, output, q[i], float(x[i]), at, closed, _slope(rate, change, i, s, h))
        except PinmechError:  # a pose between that does not close: no limit stated there
            continue
        label = extreme_label(float(rate[i]) if rate[i] != 0 else float(rate[i + 1]), h)
        found.append((design.finder.limit(output, closed, at, label), closed))
    return found


def _cubic(rate: np.ndarray, change: np.ndarray, i: int, h: float) -> np.ndarray:
    """The rate over step i as a cubic in the fraction s of the step (Hermite: the rates and
    their derivatives per unit driver at both ends)."""
    r0, r1, m0, m1 = float(rate[i]), float(rate[i + 1]), h * float(change[i]), h * float(change[i + 1])
    return np.array([2 * r0 - 2 * r1 + m0 + m1, -3 * r0 + 3 * r1 - 2 * m0 - m1, m0, r0])


def _slope(rate: np.ndarray, change: np.ndarray, i: int, s: float, h: float) -> float:
    """The cubic's slope per unit driver at fraction s of step i."""
    return float(np.polyval(np.polyder(_cubic(rate, change, i, h)), s)) / h


def _polished(design, output, q0: np.ndarray, x0: float, at: float, closed: np.ndarray, slope: float):
    """One Newton step on the engine's rate at the closed pose: the limit's driver value to
    the solver's rounding rather than to the cubic's error (kept if the step is not small)."""
    if slope == 0.0:
        return at, closed
    better = at - design.finder.rate(output, closed) / slope
    if abs(better - at) > 1e-6:
        return at, closed
    return better, design.finder.pose(q0, x0, better)


def angle_extreme(design, dyad, x: np.ndarray, q: np.ndarray, mu: np.ndarray, sign: float,
                  whole_turn: bool) -> Extreme:
    """The least (sign 1) or largest (sign -1) transmission angle mu [deg] over the poses:
    the best pose, then successive parabolas through the best three points (each vertex
    closed and its angle computed by the engine), until the vertex moves less than 1e-9 of
    the step."""
    k, n = int(np.argmin(sign * mu)), len(x)
    if 0 < k < n - 1:
        before, after = k - 1, k + 1
    elif whole_turn and k in (0, n - 1):
        before, after = n - 2, 1
    else:  # an end of the motion's range: the extreme is there
        return Extreme(float(mu[k]), float(x[k]), False)
    h = float(x[1] - x[0])
    points = [(-h, sign * float(mu[before])), (0.0, sign * float(mu[k])), (h, sign * float(mu[after]))]
    best = points[1]
    for _ in range(6):
        vertex = _vertex(points)
        if vertex is None or abs(vertex - best[0]) < 1e-9 * abs(h):
            break
        try:
            design.linkage.place(design.finder.pose(q[k], float(x[k]), float(x[k]) + vertex))
        except PinmechError:
            break
        found = (vertex, sign * float(dyad_angles(design.linkage, dyad).mu))
        points = sorted(points + [found], key=lambda p: p[1])[:3]
        best = points[0]
    at = float(x[k]) + best[0]
    if whole_turn:
        at = float(x[0]) + math.remainder(at - float(x[0]), 2 * math.pi) % (2 * math.pi)
    return Extreme(sign * best[1], at, best[0] != 0.0)


def _vertex(points: list[tuple[float, float]]) -> float | None:
    """The abscissa of the vertex of the parabola through three points (None: no minimum)."""
    (x0, f0), (x1, f1), (x2, f2) = points
    top = (x1 - x0) ** 2 * (f1 - f2) - (x1 - x2) ** 2 * (f1 - f0)
    bottom = (x1 - x0) * (f1 - f2) - (x1 - x2) * (f1 - f0)
    if bottom == 0.0:
        return None
    return x1 - 0.5 * top / bottom
