"""Limit positions of a planar linkage over a sweep of one driver: rocker extremes, slider
dead centres, the toggles at them, the swing or stroke, and the time ratio of a
quick-return motion.

An output's limit position is where its rate vanishes while the driver moves (Norton,
Design of Machinery, §3.5 and §4.10; Uicker, §1.10): a rocker's extreme angle, a
piston's dead centre. Over a sweep the output's rate per unit driver rate (the solved
rates at unit driver speed, so a scene's speed of zero does not hide them) changes sign
between two poses; the driver value is then found by bisection, each trial pose followed
from the bracket's first pose on the sweep's assembly, to BISECTION_TOL.

Time ratio of a quick return: with the driver turning at constant speed through one
turn and the output reaching two limit positions at driver values x1, x2, the output's
strokes take the driver angles alpha = |x2 - x1| and beta = 2 pi - alpha; Q is the
larger over the smaller (Q >= 1; Norton eq. "Q = alpha / beta").
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pinmech.solve.continuation import Route
from pinmech.model.planar_linkage import PlanarLinkage
from pinmech.solve.transmission import Dyad, Output, output_position, output_rate, toggle

#: Driver values of limit positions are bisected to this [rad or m].
BISECTION_TOL = 1e-12


@dataclass(frozen=True)
class LimitPosition:
    """An output at the end of its travel.

    Attributes:
        output: the output link's name.
        kind: "rocker extreme" or "dead centre".
        label: "max" or "min" (the output's angle [rad] or place along the slide [m]);
            a dead centre adds "TDC" (farther from the driving link's pivot) or "BDC".
        driver: the driver value there [rad or m], to BISECTION_TOL.
        value: the output's angle [rad] or place along its slide [m] there.
        toggle: "extended" or "folded" when the driving link and the coupler are in line
            there, else "".
        slide: a dead centre's slide coordinate s [m] (the slide joint's, as the CSV's
            `NAME.s` and the figures give it: from the drawn pose), None for a rocker or a
            slide closed by a loop cut.
    """

    output: str
    kind: str
    label: str
    driver: float
    value: float
    toggle: str
    slide: float | None = None

    def as_dict(self) -> dict:
        return {"output": self.output, "kind": self.kind, "label": self.label, "driver": self.driver,
                "value": self.value, "toggle": self.toggle, "slide_coordinate": self.slide}


@dataclass(frozen=True)
class Travel:
    """An output's travel over a sweep: its limit positions, swing [rad] or stroke [m], and
    the time ratio when the sweep is one turn of an angular driver with two limits.

    Attributes:
        alpha, beta: the driver angles of the slower and the quicker stroke [rad].
        ratio: Q = alpha / beta (>= 1), None unless the sweep is one whole turn.
    """

    output: str
    kind: str
    limits: tuple[LimitPosition, ...]
    travel: float | None
    alpha: float | None = None
    beta: float | None = None
    ratio: float | None = None

    def as_dict(self) -> dict:
        word = "swing" if self.kind == "rocker extreme" else "stroke"
        return {"output": self.output, "limits": [x.as_dict() for x in self.limits], word: self.travel,
                "time_ratio": self.ratio, "slow_stroke_driver_angle": self.alpha,
                "quick_stroke_driver_angle": self.beta}


class LimitFinder:
    """Finds the limit positions of dyad outputs along a sweep's driver.

    Args:
        solver: the sweep's `LoopSolver` (its assembly is followed).
        linkage: the planar linkage of the same mechanism.
        driver_index: which of the solver's drivers is swept.
        driver_q: every driver's value [rad or m] (the others are held).
        dyads: the linkage's dyads, to say whether a limit position is a toggle.
    """

    def __init__(self, solver, linkage: PlanarLinkage, driver_index: int, driver_q: np.ndarray,
                 dyads: Sequence[Dyad] = ()) -> None:
        self.solver, self.linkage, self.dyads = solver, linkage, list(dyads)
        self.k, self.x = driver_index, np.asarray(driver_q, dtype=float).copy()
        self.unit = np.zeros(len(self.x))
        self.unit[driver_index] = 1.0

    def rate(self, output: Output, q: np.ndarray) -> float:
        """The output's rate per unit driver rate at a closed q [rad/rad, m/rad, ...]."""
        with self.solver.lock:
            v, _, _ = self.solver.rates(q, self.unit, np.zeros(len(self.unit)))
        self.linkage.place(q, v)
        return output_rate(self.linkage, output)

    def pose(self, q0: np.ndarray, x0: float, x: float) -> np.ndarray:
        """The closed q at driver value x, followed from the closed q0 at x0."""
        a, b = self.x.copy(), self.x.copy()
        a[self.k], b[self.k] = x0, x
        with self.solver.lock:
            return self.solver.follow(q0, a, b, Route(tuple(a.tolist())))

    def limits(self, output: Output, values: np.ndarray, qs: list[np.ndarray]) -> list[LimitPosition]:
        """Limit positions of an output between consecutive sweep poses (values [rad
        or m], qs their closed configurations, None where a pose failed)."""
        rates = [None if q is None else self.rate(output, q) for q in qs]
        out = []
        for i in range(len(values) - 1):
            r0, r1 = rates[i], rates[i + 1]
            if r0 is None or r1 is None or not (r0 * r1 < 0 or (r0 == 0 and i > 0)):
                continue
            x, q = self.bisect(output, qs[i], float(values[i]), float(values[i + 1]), r0)
            out.append(self.limit(output, q, x, extreme_label(r0, float(values[i + 1] - values[i]))))
        return out

    def bisect(self, output: Output, q0: np.ndarray, a: float, b: float, ra: float) -> tuple[float, np.ndarray]:
        """The driver value in [a, b] where the output's rate changes sign (ra at a), and q there."""
        x0 = a
        while abs(b - a) > BISECTION_TOL:
            m = 0.5 * (a + b)
            if m in (a, b):  # rounding: no float between them
                break
            rm = self.rate(output, self.pose(q0, x0, m))
            if rm == 0:
                a = b = m
            elif (rm > 0) == (ra > 0):
                a = m
            else:
                b = m
        x = 0.5 * (a + b)
        return x, self.pose(q0, x0, x)

    def limit(self, output: Output, q: np.ndarray, x: float, label: str) -> LimitPosition:
        self.linkage.place(q)
        name = self.linkage.names[output.output]
        kind = "rocker extreme" if output.kind == "pin" else "dead centre"
        dyad = next((d for d in self.dyads if d.output == output.output), None)
        lay = toggle(self.linkage, dyad) if dyad is not None else ""
        return LimitPosition(name, kind, label, x, output_position(self.linkage, output), lay, self._slide(output, q))

    def _slide(self, output: Output, q: np.ndarray) -> float | None:
        """The slide joint's coordinate s at q [m], if the output's slide is a joint of the tree."""
        mech = self.linkage.mechanism
        if output.kind != "slide" or output.ground.name not in mech.joints:
            return None
        return mech.coordinate(q, output.ground.name)


def extreme_label(rate: float, step: float) -> str:
    """"max" or "min": the output's extreme met moving the driver by `step` [rad or m] from
    where its rate per unit driver rate is `rate` (a driver swept backwards, or turning back
    past a fold, meets a maximum where the rate per unit driver is negative)."""
    return "max" if rate * step > 0 else "min"


def travel(limits: list[LimitPosition], span: float | None) -> Travel | None:
    """Swing or stroke and time ratio of one output's limit positions; `span` the sweep's
    driver travel [rad] when it is one whole turn of an angular driver, else None."""
    if not limits:
        return None
    highs = [x.value for x in limits if x.label.startswith("max")]
    lows = [x.value for x in limits if x.label.startswith("min")]
    amount = None
    if highs and lows:
        amount = max(highs) - min(lows)
        if limits[0].kind == "rocker extreme":
            amount = math.remainder(amount, 2 * math.pi) % (2 * math.pi)
    limits = _dead_centres(limits)
    if span is None or len(limits) != 2:
        return Travel(limits[0].output, limits[0].kind, tuple(limits), amount)
    first = abs(limits[1].driver - limits[0].driver)
    alpha, beta = max(first, 2 * math.pi - first), min(first, 2 * math.pi - first)
    return Travel(limits[0].output, limits[0].kind, tuple(limits), amount, alpha, beta, alpha / beta)


def _dead_centres(limits: list[LimitPosition]) -> list[LimitPosition]:
    """Name a slide's two dead centres: TDC where crank and rod are extended, BDC folded."""
    if limits[0].kind != "dead centre":
        return limits
    word = {"extended": " TDC", "folded": " BDC"}
    return [LimitPosition(x.output, x.kind, x.label + word.get(x.toggle, ""), x.driver, x.value, x.toggle, x.slide)
            for x in limits]
