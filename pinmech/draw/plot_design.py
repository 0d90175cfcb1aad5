"""What the sweep figures draw of the design diagnostics (pinmech.solve.diagnostics_sweep): each dyad's
transmission angle (mu on [0, 180] deg, 90 best) with its value farthest from 90 deg marked, and the limit
positions of the outputs (rocker extremes, dead centres, the toggles at them) as vertical
lines in every panel and as ghost outlines of the mechanism in the paths figure.

The marked angle is the design summary's (`DesignSweep.angle_extremes`: refined by golden
section between the poses on either side of it, to extremum.TOL); where a trial pose cannot
close (a fold beside it) the least over the poses stands and the figure says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.angles import position_text


@dataclass(frozen=True)
class LeastAngle:
    """A dyad's transmission angle farthest from 90 deg (its worst): `mu` [deg, 0..180] at
    driver value `at` [rad or m]; `refined` False where it is the worst over the poses only."""

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
        from pinmech.solve.diagnostics_sweep import design_of

        self.design = design_of(sweep)
        self.dyads = list(self.design.dyads) if self.design.applicable else []

    @property
    def names(self) -> list[str]:
        """Each dyad by its pin B (as the CSV columns name it)."""
        return [d.joint.name for d in self.dyads]

    def add(self, pose, q: np.ndarray | None) -> list[float]:
        """The transmission angle of each dyad at a pose [deg, 0..180] (NaN where it failed)."""
        out = self.design.evaluate(pose)
        if not out or q is None:
            return [math.nan] * len(self.dyads)
        return [mu for mu, _, _ in out["angles"]]

    def least(self) -> list[LeastAngle]:
        """Each dyad's least transmission angle, located between the poses around it by the
        design summary's own search (`DesignSweep.angle_extremes`); none for an angle that
        does not change (a slot through its lever's pivot: mu = 90 deg throughout)."""
        if not self.dyads or not self.design.count:
            return []
        return [LeastAngle(x.name, *((x.low, x.low_at) if 90.0 - x.low >= x.high - 90.0 else (x.high, x.high_at)),
                           x.refined) for x in self.design.angle_extremes() if not x.constant]

    def limits(self) -> list[tuple[str, float, np.ndarray]]:
        """(label, driver value [rad or m], closed q) of every output's limit position."""
        from pinmech.solve.limit_positions import travel

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
    word = "farthest from 90°" if least.refined else "farthest from 90° over the poses"
    ax.plot([x], [least.mu], "v", color=colour, markersize=8, markeredgecolor="0.1", zorder=6, clip_on=False,
            gid="least transmission angle", label=f"{label}: {word} μ = {least.mu:.1f}° at {unit_x(x, unit)}")


def unit_x(x: float, unit: str = "°") -> str:
    """A driver value as a figure prints it (rounded to 1e-3: 5e-7 deg is 0 deg); an angle
    as a position, in [0, 360) deg (angles.py)."""
    if unit == "°":
        return f"{position_text(round(x, 3) + 0.0, 'g')}{unit}"
    return f"{round(x, 3) + 0.0:g}{unit}"


#: The transmission angles a designer keeps to (Norton, Design of Machinery, sec. 3.3: mu
#: within 40 to 140 deg for a linkage that runs smoothly) [deg].
BAND = (40.0, 140.0)


def transmission_band(ax) -> None:
    """The transmission angle's panel on its whole range, 0 to 180 deg (mu is computed on it:
    no angle folded about 90 deg), with the 40-140 deg band shaded and 90 deg drawn."""
    ax.axhspan(*BAND, color="#2ca02c", alpha=0.08, zorder=0, gid="transmission band",
               label=f"{BAND[0]:g}°–{BAND[1]:g}°: the usual working band")
    ax.axhline(90.0, color="0.5", linewidth=0.7, linestyle=":", zorder=0)
    ax.set_ylim(0.0, 180.0)
    ax.set_yticks(np.arange(0.0, 181.0, 30.0))
