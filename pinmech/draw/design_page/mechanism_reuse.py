"""One compiled mechanism kept across a page's drags: while a drag changes only the
drawing's dimensions (the same joints, links, pins and slides), its joint and frame
placements are written into the mechanism's `pin.Model` in place, as design studies write
their variants (`model.linkage_placements.DrawnPlacements`), and its reference set to the
new drawn pose; no URDF is loaded and no model built.

As in a study, the loops' sizes (the scale of their closure tolerances) stay those of the
mechanism as built; a drawing whose size has changed by more than SIZE_CHANGE since is built
afresh. A guard: the written model must close every loop at the new drawn pose (as a built
one does by construction), else it is built afresh. A turn that fails after a write is
rolled back (`rollback`), so that the last valid turn keeps its mechanism.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError, PinmechError

#: The closure residual allowed at the drawn pose of a written model (relative, as
#: linkage_model._check_closed holds a built one to).
CLOSED = 1e-9
#: The drawing's size (its points' span) may change by this factor at most before the
#: mechanism is built again (its loops' sizes, the scale of their tolerances, measured anew).
SIZE_CHANGE = 1.25


def structure(linkage) -> tuple:
    """What a drag may not change for the mechanism to be written in place."""
    return (tuple((e.name, e.kind, tuple(e.links)) for e in linkage.edges), tuple(linkage.points),
            tuple(sorted(linkage.point_links.items())), tuple((k, tuple(v)) for k, v in linkage.links.items()),
            tuple(sorted(linkage.hidden)), linkage.spatial)


def _span(linkage) -> float:
    points = np.array([p[:2] for p in linkage.points.values()])
    return float(np.ptp(points, axis=0).max())


class MechanismReuse:
    """The page's mechanism, written in place for each new drawing of the same structure."""

    def __init__(self) -> None:
        self.mechanism = None
        self._key, self._writer, self._size = None, None, 0.0
        self._state = None  # (placements, reference) of the mechanism as it is
        self._before = None  # the state before the last write, for `rollback`

    def mechanism_for(self, linkage):
        """The mechanism of `linkage`: the kept one written in place, or one built afresh.

        Raises:
            ModelError: a linkage the engine cannot build (as `linkage_mechanism`).
        """
        from pinmech.model.linkage_model import linkage_mechanism

        self._before = None
        if self._fits(linkage):
            try:
                return self._written(linkage)
            except PinmechError:  # a slide turned, or the written model does not close: build it
                self.rollback()
        mechanism = linkage_mechanism(linkage)
        self._adopt(linkage, mechanism)
        return mechanism

    def keep(self) -> None:
        """The last write's turn is kept: nothing to roll back to any more."""
        self._before = None

    def rollback(self) -> None:
        """Undo the last write (its turn was not kept): the mechanism as the last kept turn had it."""
        if self._before is not None:
            self._write(*self._before)
            self._state, self._before = self._before, None

    def _fits(self, linkage) -> bool:
        return (self.mechanism is not None and structure(linkage) == self._key
                and 1 / SIZE_CHANGE <= _span(linkage) / self._size <= SIZE_CHANGE)

    def _adopt(self, linkage, mechanism) -> None:
        from pinmech.model.linkage_placements import DrawnPlacements

        self.mechanism, self._key, self._size, self._before = mechanism, structure(linkage), _span(linkage), None
        try:
            self._writer = DrawnPlacements(linkage, mechanism.model)
        except ModelError:  # placements this drawing's rules cannot give: never written in place
            self.mechanism, self._key, self._writer = None, None, None
            return
        self._state = (self._writer.placements(linkage), np.array(mechanism.reference))

    def _written(self, linkage):
        from pinmech.model.linkage_urdf import linkage_urdf

        placements = self._writer.placements(linkage)
        _, coordinates = linkage_urdf(linkage)  # joint -> its coordinate at the drawn pose, as a load sets it
        reference = pin.neutral(self.mechanism.model)
        for name, value in (coordinates or {}).items():
            if name in self.mechanism.joints:
                self.mechanism.set_coordinate(reference, name, value)
        self._before = self._state
        self._write(placements, reference)
        self._state = (placements, reference)
        _check_closed(self.mechanism)
        return self.mechanism

    def _write(self, placements, reference) -> None:
        self._writer.write(placements)
        self.mechanism.reference = np.array(reference, dtype=float)


def _check_closed(mechanism) -> None:
    """Every loop closed at the drawn pose, or ModelError."""
    from pinmech.model.closure_core import closure_rows

    residual = closure_rows(mechanism).residual(mechanism.reference)
    if residual.size and float(np.max(np.abs(residual))) > CLOSED:
        raise ModelError("the written model does not close at the drawn pose", path=mechanism.source)
