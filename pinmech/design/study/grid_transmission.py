"""The least transmission angle of a variant over its cycle, for grid studies.

The planar linkage (pinmech/model/planar_linkage.py) copies its pins' places out of the
model's placements when it is built, so it is rebuilt for each variant after the
variant's values are written: one built at the nominal would measure the nominal's pins.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.exceptions import DiagnosticError
from pinmech.model.planar_linkage import planar_linkage
from pinmech.solve.transmission import dyad_angles, find_dyads


def has_dyads(mechanism, drivers: list[str]) -> bool:
    """Whether the mechanism is a planar linkage with at least one dyad (a transmission angle)."""
    try:
        return bool(find_dyads(planar_linkage(mechanism), drivers))
    except DiagnosticError:
        return False


def least_transmission(mechanism, drivers: list[str], q: np.ndarray) -> float:
    """The least acute transmission angle (Norton's mu, 0 to 90 deg) of every dyad over the
    poses q (steps, nq) of the dimensions now in the model [rad]."""
    linkage = planar_linkage(mechanism)
    dyads = find_dyads(linkage, drivers)
    least = math.inf
    for qi in q:
        linkage.place(qi)
        least = min(least, *(dyad_angles(linkage, d).mu_acute for d in dyads))
    return math.radians(least)
