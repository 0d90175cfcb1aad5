"""Which branch a four-bar with two equal pairs of opposite links is on, pose by pose, and
where a sweep passes from one to the other.

Such a four-bar (Barker's S2X, S3X: a = c, b = d) has two branches that cross at its change
points, where all four pins fall in line (Norton, Design of Machinery, §2.12): the
parallelogram (the crank and the rocker parallel and of one sense, the coupler parallel
to the ground) and the antiparallelogram (crossed). Told apart at any regular pose by
the sense of O2 A against O4 B. A sweep that goes from one to the other has passed a
change point; the report says so and names the branch taken, whether or not the
continuation noticed it.
"""

from __future__ import annotations

import numpy as np

from pinmech.model.planar_linkage import PlanarLinkage
from pinmech.solve.grashof import EQUAL, loop_classes


class BranchWatch:
    """The branch of each parallelogram-type loop, watched over a sweep.

    Args:
        linkage: the planar linkage (placed by the caller at each pose).
    """

    def __init__(self, linkage: PlanarLinkage) -> None:
        self.linkage, self.loops = linkage, []
        index = {name: i for i, name in linkage.names.items()}
        for loop in loop_classes(linkage):
            if loop.kind != "four-bar" or loop.label != "change point":
                continue
            ground, a, b, c = loop.links
            size = sum(loop.lengths.values())
            if abs(loop.lengths[a] - loop.lengths[c]) <= EQUAL * size and \
                    abs(loop.lengths[b] - loop.lengths[ground]) <= EQUAL * size:
                self.loops.append(("-".join(loop.links), index[a], index[b], index[c]))
        self.last: list[str | None] = [None] * len(self.loops)

    def _vector(self, link: int, towards: int) -> np.ndarray:
        """The link's bar from its ground pin to its pin on `towards` [m]."""
        pins = dict(self.linkage.neighbours(link))
        return self.linkage.pair_point(pins[towards]) - self.linkage.pair_point(pins[0])

    def form(self, i: int) -> str:
        """"parallelogram" (O2 A = O4 B, to 1e-9 of the crank: closed poses are exact to
        1e-13) or "antiparallelogram" at the placed pose."""
        _, a, b, c = self.loops[i]
        u, w = self._vector(a, b), self._vector(c, b)  # O2 A and O4 B: equal on the parallelogram
        return "parallelogram" if np.linalg.norm(u - w) <= 1e-9 * np.linalg.norm(u) else "antiparallelogram"

    def forms(self) -> list[tuple[str, str]]:
        """(loop, its branch) at the placed pose, for each loop watched."""
        return [(loop[0], self.form(i)) for i, loop in enumerate(self.loops)]

    def add(self, where: str) -> list[str]:
        """The placed pose (at `where`, as reports print the driver): a note per loop whose
        branch changed since the last pose given."""
        notes = []
        for i, (name, *_) in enumerate(self.loops):
            now = self.form(i)
            if self.last[i] is not None and now != self.last[i]:
                notes.append(f"loop {name} passed a change point before {where}: now on its {now} branch "
                             f"(was {self.last[i]})")
            self.last[i] = now
        return notes
