"""Timing marks on the paths of a sweep: where each point is at every `step` of the driver
(every 30 deg of a crank, as a textbook marks a coupler curve), each place solved at that
very driver value (followed from the pose before it), not read off the drawn curve.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from pinmech.solve.continuation import Route

#: Driver values within this of a pose's are that pose [rad or m].
_SAME = 1e-12


class TimingMarks:
    """Places of named points at every multiple of `step` of the swept driver.

    Args:
        sweep: the `Sweep` (its solver follows the poses; its other drivers are held).
        points: the points (or frames) to mark.
        step: the spacing of the marks [rad or m], > 0.
    """

    def __init__(self, sweep, points: list[str], step: float) -> None:
        self.sweep, self.points, self.step = sweep, list(points), float(step)
        model = sweep.mechanism.model
        self.frames = {p: sweep.mechanism.frame_id(p) for p in self.points}  # by name and kind (sites first)
        self.data = model.createData()
        self.k = list(sweep.drivers.names).index(sweep.driver)
        #: driver value [rad or m] -> point -> world position [m]
        self.marks: dict[float, dict[str, np.ndarray]] = {}
        self._last: tuple[float, np.ndarray] | None = None

    def add(self, value: float, q: np.ndarray | None) -> None:
        """A pose of the sweep at driver `value` (q None: it failed, no mark across it)."""
        if q is None:
            self._last = None
            return
        lo = value if self._last is None else min(self._last[0], value)
        hi = value if self._last is None else max(self._last[0], value)
        for n in range(math.ceil((lo - _SAME) / self.step), math.floor((hi + _SAME) / self.step) + 1):
            t = n * self.step
            key = self._key(t)
            if key in self.marks:
                continue
            if abs(t - value) <= _SAME:
                self.marks[key] = self._places(q)
            elif self._last is not None and abs(t - self._last[0]) > _SAME:
                self.marks[key] = self._places(self._follow(value, q, t))
        self._last = (value, q.copy())

    def _key(self, t: float) -> float:
        """A driver value as marked: an angle modulo a turn (a turn's end is its start)."""
        if self.sweep.is_angular:
            return round(math.degrees(t) % 360.0, 9) % 360.0
        return round(t, 12)

    def _follow(self, value: float, q: np.ndarray, t: float) -> np.ndarray:
        x0 = np.asarray(self.sweep.drivers.q, dtype=float).copy()
        x0[self.k] = value
        x1 = x0.copy()
        x1[self.k] = t
        with self.sweep.solver.lock:
            return self.sweep.solver.follow(q, x0, x1, Route(tuple(x0.tolist())))

    def _places(self, q: np.ndarray) -> dict[str, np.ndarray]:
        model = self.sweep.mechanism.model
        pin.framesForwardKinematics(model, self.data, q)
        return {p: self.data.oMf[f].translation.copy() for p, f in self.frames.items()}

    def label(self, key: float) -> str:
        """A mark's text: the driver's angle [deg] or place [mm]."""
        return f"{key:g}°" if self.sweep.is_angular else f"{1000 * key:g} mm"
