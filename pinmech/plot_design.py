"""What the sweep figures draw of the design diagnostics (pinmech.design_sweep): each dyad's
transmission angle (Norton's acute mu [deg]) with its least value marked, and the limit
positions of the outputs (rocker extremes, dead centres, the toggles at them) as vertical
lines in every panel and as ghost outlines of the mechanism in the paths figure.

The least angle is first the least over the poses, then refined by golden section between
the poses on either side of it, each trial pose followed from the least one (as the limit
positions are bisected), to LEAST_TOL; where a trial pose cannot close (a fold beside it)
the least over the poses stands and the figure says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.transmission import dyad_angles

#: The driver value of the least transmission angle is refined to this [rad or m].
LEAST_TOL = 1e-10
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass
class _Least:
    """The least acute angle of a dyad over the poses so far, and the poses around it."""

    mu: float
    at: float
    q: np.ndarray
    before: float | None
    after: float | None = None


@dataclass(frozen=True)
class LeastAngle:
    """A dyad's least transmission angle: `mu` [deg] at driver value `at` [rad or m];
    `refined` False where it is the least over the poses only."""

    name: str
    mu: float
    at: float
    refined: bool


class DesignTrace:
    """Feeds the sweep's `DesignSweep` and keeps what its figures draw.

    Args:
        sweep: the `Sweep` (its one `DesignSweep` is shared with the tables and the summary).
    """

    def __init__(self, sweep) -> None:
        from pinmech.design_sweep import design_of

        self.design = design_of(sweep)
        self.dyads = list(self.design.dyads) if self.design.applicable else []
        self._least: list[_Least | None] = [None] * len(self.dyads)
        self._last: float | None = None

    @property
    def names(self) -> list[str]:
        """Each dyad by its pin B (as the CSV columns name it)."""
        return [d.joint.name for d in self.dyads]

    def add(self, pose, q: np.ndarray | None) -> list[float]:
        """The acute transmission angle of each dyad at a pose [deg] (NaN where it failed)."""
        out = self.design.evaluate(pose)
        if not out or q is None:
            self._last = None
            return [math.nan] * len(self.dyads)
        mus = [acute for _, acute, _ in out["angles"]]
        for k, mu in enumerate(mus):
            least = self._least[k]
            if least is not None and least.after is None and least.at == self._last:
                least.after = pose.value
            if least is None or mu < least.mu:
                self._least[k] = _Least(mu, pose.value, q.copy(), self._last)
        self._last = pose.value
        return mus

    def least(self) -> list[LeastAngle]:
        """Each dyad's least transmission angle, refined between the poses around it."""
        out = []
        for dyad, least in zip(self.dyads, self._least):
            if least is None:
                continue
            try:
                at, mu = self._refine(dyad, least)
                out.append(LeastAngle(dyad.joint.name, mu, at, True))
            except PinmechError:  # a trial pose beside a fold: the least over the poses stands
                out.append(LeastAngle(dyad.joint.name, least.mu, least.at, False))
        return out

    def _refine(self, dyad, least: _Least) -> tuple[float, float]:
        """Golden-section search for the least acute angle between the poses around it."""
        lo = least.at if least.before is None else least.before
        hi = least.at if least.after is None else least.after
        lo, hi = min(lo, hi), max(lo, hi)

        def mu(x: float) -> float:
            q = self.design.finder.pose(least.q, least.at, x)
            self.design.linkage.place(q)
            return dyad_angles(self.design.linkage, dyad).mu_acute

        a, b = lo, hi
        c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
        fc, fd = mu(c), mu(d)
        while b - a > LEAST_TOL:
            if fc < fd:
                b, d, fd = d, c, fc
                c = b - _GOLDEN * (b - a)
                fc = mu(c)
            else:
                a, c, fc = c, d, fd
                d = a + _GOLDEN * (b - a)
                fd = mu(d)
        x = 0.5 * (a + b)
        best = min([(mu(x), x), (least.mu, least.at)])
        return best[1], best[0]

    def limits(self) -> list[tuple[str, float, np.ndarray]]:
        """(label, driver value [rad or m], closed q) of every output's limit position."""
        from pinmech.limit_positions import travel

        out = []
        for found in self.design.limit_poses() if self.design.applicable else []:
            named = travel([limit for limit, _ in found], None).limits if found else ()  # TDC, BDC
            for limit, (_, q) in zip(named, found):
                lay = f" ({limit.toggle})" if limit.toggle and limit.kind == "rocker extreme" else ""
                out.append((f"{limit.output} {limit.label}{lay}", limit.driver, q))
        return out


def mark_least(ax, least: LeastAngle, x: float, colour: str, label: str, unit: str = "°") -> None:
    """The least transmission angle on its panel: a triangle and a legend entry (x as
    drawn, in `unit`)."""
    word = "least" if least.refined else "least over the poses"
    ax.plot([x], [least.mu], "v", color=colour, markersize=8, markeredgecolor="0.1", zorder=6, clip_on=False,
            gid="least transmission angle", label=f"{label}: {word} μ = {least.mu:.1f}° at {unit_x(x, unit)}")


def unit_x(x: float, unit: str = "°") -> str:
    """A driver value as a figure prints it (rounded to 1e-3: 5e-7 deg is 0 deg)."""
    return f"{round(x, 3) + 0.0:g}{unit}"
