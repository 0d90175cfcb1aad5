"""A variant's cycle in one call of the compiled core: the start pose closed by the core's
corrector from the nominal's, its assembly signature compared with the nominal's, then
every pose of the cycle followed by `Core.follow` (pinmech/csrc/continuation.cpp), the
rules of the scene's sweep (solve/cycle.py, which calls the same follow). No Python runs
per pose.

The core reads the placements written in the user's `pin.Model` at each call, so a
variant is its parameters written in place and nothing is rebuilt. Wherever the core
does not finish cleanly (the start does not close by a full Newton step, or closes on
another assembly; the follow stops at a change point, a fold, a singular or too
ill-conditioned pose) `follow` returns None and the caller solves the variant by the
scene's sweep (the core's pose-by-pose follow), which names the cause or takes the pose:
this range call only answers where it has the whole answer.
"""

from __future__ import annotations

import numpy as np

from pinmech.solve.continuation import Path
from pinmech.solve.core import core_for

_CORRECT_ITERATIONS = 20  # Newton steps of the start pose's corrector (it needs 2 to 4 here)
#: Why the core's follow stopped short (its Stop codes, pinmech/csrc/core.hpp), by name.
STOPS = {1: "fold within the range", 2: "changes assembly", 3: "singular pose", 4: "singular pose"}


class CoreCycle:
    """The compiled follow of a StudyMechanism's cycle, set up once per process.

    Attributes:
        usable: False where the sweep has no compiled core (no loops: an open chain) or
            other drivers move with the swept one (their rates are not the path's).
    """

    def __init__(self, solver, drivers, driver: str, values: np.ndarray, reference) -> None:
        self.solver, self.core = solver, core_for(solver)
        k = solver.drivers.index(driver)
        q_drv, v_drv, a_drv = (np.array(solver._ordered(x), dtype=float) for x in (drivers.q, drivers.v, drivers.a))
        others = np.delete(np.concatenate((v_drv, a_drv)), [k, k + len(v_drv)])
        ref_drv = np.array(reference.driver_q, dtype=float)
        on_path = np.array_equal(np.delete(ref_drv, k), np.delete(q_drv, k))
        self.usable = self.core is not None and not np.any(others) and on_path
        self.w, self.alpha = float(v_drv[k]), float(a_drv[k])
        self.unit_v = np.zeros(len(q_drv))
        self.unit_v[k] = 1.0
        x0 = q_drv.copy()
        x0[k] = 0.0
        self.path = Path(solver, x0, self.unit_v)  # p = the swept driver's value [rad or m]
        self.targets = np.ascontiguousarray(values, dtype=float)
        self.ref_q, self.ref_drv, self.p0 = np.array(reference.q), ref_drv, float(ref_drv[k])
        self.signs = list(reference.signs)

    def follow(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(q, v, a) at every pose of the cycle [rad, m; per s; per s^2] of the variant now
        written in the model, or None where the core hands it back (see the module)."""
        path, _ = self.attempt()
        if path is None:
            return None
        Q, D1, D2 = path
        return Q, D1 * self.w, D2 * (self.w * self.w) + D1 * self.alpha

    def attempt(self) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray] | None, str]:
        """q and its first and second derivatives along the swept driver's value at every
        pose (q, dq/dp, d2q/dp2 [per rad or m]), or None and why (one of STOPS: the start
        does not close, closes on another assembly or too ill-conditioned; the follow met a
        fold, passed a change point, or a pose too ill-conditioned; "" where it answers)."""
        if not self.usable:
            return None, "unusable"
        core, solver = self.core, self.solver
        q, residual = core.correct(self.ref_q, self.ref_drv, _CORRECT_ITERATIONS)
        if residual is None:
            return None, "cannot assemble"
        d1, d2, signs, condition = core.node(q, self.unit_v)[:4]
        if list(signs) != self.signs:
            return None, "other assembly"
        if not condition <= solver.max_condition:
            return None, "singular pose"
        done, stop, Q, D1, D2, _ = core.follow(self.p0, q, d1, d2, self.signs, condition, self.path.x0,
                                               self.path.d, self.path.unit, self.targets, solver.max_condition)
        if done < len(self.targets):
            return None, STOPS.get(int(stop), "singular pose")
        return (Q, D1, D2), ""
