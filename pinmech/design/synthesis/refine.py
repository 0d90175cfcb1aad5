"""Refining a synthesis candidate: least squares from its row (bounds kept, exact
Jacobian), then the first of the fitted row and the row itself that makes a Linkage free
of defects (motion.causes, checked by the caller's `linkage`)."""

from __future__ import annotations

from typing import Callable

import numpy as np

from pinmech.design.synthesis.result import Linkage

Vector = Callable[[np.ndarray], np.ndarray]


def refine(residual: Vector, jacobian: Vector, v0: np.ndarray, lower: np.ndarray, upper: np.ndarray,
           linkage: Callable[[np.ndarray], Linkage | None]) -> Linkage | None:
    """The Linkage of the least-squares fit of residual from v0 within [lower, upper], or of
    v0 itself if the fitted one has a defect (linkage returns None); None if neither has."""
    import scipy.optimize as opt

    candidates = []
    try:
        with np.errstate(all="ignore"):
            fit = opt.least_squares(residual, np.clip(v0, lower, upper), jac=jacobian, bounds=(lower, upper),
                                    method="trf", x_scale="jac", ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=400)
        candidates.append(fit.x)
    except (np.linalg.LinAlgError, ValueError):  # a fold or an open dyad on the way: keep v0
        pass
    candidates.append(np.asarray(v0, dtype=float))
    for v in candidates:
        lk = linkage(v)
        if lk is not None:
            return lk
    return None
