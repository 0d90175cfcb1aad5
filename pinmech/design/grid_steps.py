"""What a workspace grid's maps (task space or the motors') say of their own resolution."""

from __future__ import annotations


class GridSteps:
    """A mixin for a map over grid axes `coords` (a list of 1-D arrays, in the axes' units:
    m, or rad for a motor's angle)."""

    coords: list

    @property
    def steps(self) -> tuple[float, ...]:
        """The grid's steps [the axes' units]."""
        return tuple(float(c[1] - c[0]) for c in self.coords)

    @property
    def locus_bound(self) -> float:
        """How far a locus midpoint (and so a distance to it) can be from the locus: half the
        largest step [the axes' units]."""
        return max(self.steps) / 2
