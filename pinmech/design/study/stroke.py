"""A slider's stroke as a study output: max - min of its coordinate s over the cycle,
the extremes located between the poses, and its exact sensitivity by the envelope theorem.

Over the poses the largest and least s bracket the extremes; each is located by the
secant method on ds/dtheta = 0 (ds/dtheta by the implicit-function theorem at each pose)
from the pose and its neighbour across the sign change, every trial pose closed by the
loop solver's Newton; where the secant leaves the poses' bracket, golden section
(extremum.golden_minimum) narrows it to 1e-5 first. The secant
locates the extreme to the solver's precision (golden section alone cannot: s is flat
there, so its noise hides the extreme's place to ~sqrt(1e-15 / s'') ~ 1e-7 rad, which
would leave d(s)/dp off by d2s/(dtheta dp) times that).

Where the extreme is inside the cycle ds/dtheta = 0 there, so moving it along the cycle
changes s to second order only (the envelope theorem), and

    d(stroke)/dp = ds/dp |_(q at the max) - ds/dp |_(q at the min)

each ds/dp at its pose by the implicit-function theorem (sensitivity.py). Where an extreme
sits at an end of a cycle that is not a whole turn, the driver value there is held, and
the same formula holds. A trial pose that does not close (a fold beside the extreme)
leaves the pose's own extreme and marks nothing refined: a SweepError names the slider.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.exceptions import PinmechError, SweepError
from pinmech.extremum import golden_minimum
from pinmech.model.closure_core import closure_rows

COARSE = 1e-5  # [rad or m] of the driver: the golden section's bracket, then the secant's first step
TOL = 1e-13  # [rad or m] of the driver: the secant stops at steps below this
_SECANT_STEPS = 12  # it needs 5 to 7 from the poses, 3 or 4 from COARSE


class Stroke:
    """One slider's stroke on a StudyMechanism `sm`: `value(q)` over a solved cycle and
    the poses of its extremes (q_max, q_min) for the sensitivity."""

    def __init__(self, sm, name: str, idx_q: int, idx_v: int) -> None:
        self.sm, self.name, self.iq, self.iv = sm, name, idx_q, idx_v
        solver = sm.solver
        self.k = list(solver.drivers).index(sm.sweep.driver)
        values = sm.values
        self.whole_turn = sm.sweep.is_angular and math.isclose(abs(values[-1] - values[0]), 2 * math.pi,
                                                               rel_tol=0, abs_tol=1e-12)

    def extremes(self, q: np.ndarray) -> tuple[float, np.ndarray, float, np.ndarray]:
        """(s_max [m], q there, s_min [m], q there) over the cycle q (steps, nq) of the
        variant now written in the model."""
        self.sm.solver.refresh()  # ground cut frames the variant moved
        s = q[:, self.iq]
        top = self._refine(q, int(np.argmax(s)), -1.0)
        low = self._refine(q, int(np.argmin(s)), +1.0)
        return top[0], top[1], low[0], low[1]

    def _refine(self, q: np.ndarray, i: int, sign: float) -> tuple[float, np.ndarray]:
        """The extreme (sign -1: largest) of s between the poses beside pose i: golden
        section to COARSE, then the secant method on ds/dtheta = 0 to solver precision.
        An extreme at an end of a cycle that is not a whole turn, where s still grows
        outwards, is that end's pose (the driver held there)."""
        values, n = self.sm.values, len(self.sm.values)
        span = values[-1] - values[0]
        at_end = not self.whole_turn and (i == 0 or i == n - 1)
        if n < 3 or (at_end and sign * self._slope(q[i]) * (1 if i == n - 1 else -1) < 0):
            return float(q[i, self.iq]), q[i]
        lo = values[i - 1] if i > 0 else (values[-2] - span if self.whole_turn else values[0])
        hi = values[i + 1] if i < n - 1 else (values[1] + span if self.whole_turn else values[-1])
        guess = q[i]
        try:
            x, q_x = self._from_poses(q, i, lo, hi)
            if x is None:  # the secant from the poses left them: golden section first
                x = golden_minimum(lambda t: sign * float(self._close(guess, t)[self.iq]), min(lo, hi), max(lo, hi),
                                   COARSE)
                x, q_x = self._secant(x - COARSE, self._close(guess, x - COARSE), x, self._close(guess, x))
        except PinmechError as exc:
            raise SweepError(f"{self.sm.spec.path}: outputs.strokes: the extreme of '{self.name}' near the driver at "
                             f"{values[i]:.6g} does not close between the poses ({exc})",
                             driver=self.sm.sweep.driver, value=float(values[i]), cause=exc) from exc
        if sign * q_x[self.iq] <= sign * q[i, self.iq]:
            return float(q_x[self.iq]), q_x
        return float(q[i, self.iq]), q[i]

    def _from_poses(self, q: np.ndarray, i: int, lo: float, hi: float) -> tuple[float | None, np.ndarray]:
        """The secant on ds/dtheta = 0 from pose i and its neighbour across the sign change
        of ds/dtheta; (None, q[i]) where it leaves [lo, hi]."""
        values, n = self.sm.values, len(self.sm.values)
        g = self._slope(q[i])
        side = -1 if g * (self._slope(q[i - 1]) if i > 0 else self._slope(q[-2])) < 0 else +1
        j = i + side
        if j < 0 or j >= n:  # beyond an end of a whole turn: the pose a turn away
            j = j % (n - 1)
        x_j = lo if side < 0 else hi
        x, q_x = self._secant(x_j, q[j], values[i], q[i])
        return (x, q_x) if min(lo, hi) <= x <= max(lo, hi) else (None, q[i])

    def _secant(self, x0: float, q0: np.ndarray, x1: float, q1: np.ndarray) -> tuple[float, np.ndarray]:
        """The root of ds/dtheta by the secant method from two closed poses (ds/dtheta from
        the closure's implicit-function theorem at each), each new pose closed from the last."""
        g0, g1 = self._slope(q0), self._slope(q1)
        for _ in range(_SECANT_STEPS):
            if g1 == g0 or abs(x1 - x0) < TOL:
                break
            x0, g0, x1 = x1, g1, x1 - g1 * (x1 - x0) / (g1 - g0)
            q1 = self._close(q1, x1)
            g1 = self._slope(q1)
        return x1, q1

    def _slope(self, q: np.ndarray) -> float:
        """ds/dtheta [m/rad or m/m] at a closed pose: dq/dtheta = -J_dep^-1 J_driver."""
        sm = self.sm
        J = closure_rows(sm.mechanism).jacobian(q)
        drv = [sm.mechanism.driver_index(n) for n in sm.solver.drivers]
        dep = [v for v in range(sm.model.nv) if v not in drv]
        rate = np.zeros(sm.model.nv)
        rate[drv[self.k]] = 1.0
        rate[dep] = -np.linalg.solve(J[:, dep], J[:, drv[self.k]])
        return float(rate[self.iv])

    def _close(self, guess: np.ndarray, x: float) -> np.ndarray:
        solver = self.sm.solver
        driver_q = np.array(self.sm.reference.driver_q, dtype=float)
        driver_q[self.k] = x
        return solver.close(guess, driver_q)[0]


def stroke_sensitivity(sm, stroke: Stroke, q_max: np.ndarray, q_min: np.ndarray, dq_dp) -> np.ndarray:
    """d(stroke)/dp (n_par,) [m/m]: ds/dp at the max pose - at the min pose (the module);
    dq_dp(q) gives the configuration sensitivity (nv, n_par) at a closed pose."""
    return dq_dp(q_max)[stroke.iv] - dq_dp(q_min)[stroke.iv]
