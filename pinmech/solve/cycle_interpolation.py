"""A sweep's interpolated poses: exact poses every n-th, quintic Hermite between, and
each interval's interpolation error measured where it peaks (solve_range's `interpolate`).
A mixin of cycle._Cycle: it uses the cycle's solver, path, reference and measurer."""

from __future__ import annotations

import math

import numpy as np

from pinmech.exceptions import SingularPoseError
from pinmech.solve.hermite import interpolate_poses
from pinmech.solve.manifold import difference_many
from pinmech.solve.range_chunk import _ACCURACY, RangeChunk, _accuracy_arrays, _Fallback

#: Where the error of a quintic Hermite interpolant peaks within its interval (to
#: leading order, s^3 (1 - s)^3 and its derivatives): the middle for positions and
#: accelerations, (1 - 1/sqrt 5) / 2 for velocities (and its mirror image, as large).
PEAKS = (0.5, 0.5 - 0.5 / math.sqrt(5.0))
#: An interpolated pose's error bound: this factor times the largest interpolation error
#: measured at its interval's peaks (exact poses solved there). The leading-order error
#: peaks there; higher orders shift the peak and change its height
#: (tests/test_interpolation_bounds.py checks it against the R-RTR's closed form).
INTERPOLATION_SAFETY = 4.0
#: Largest Newton step (rad, or loop sizes) from an interpolated guess to the exact pose it
#: is measured against: the guess is as good as the interpolation, and the assembly is
#: checked after (a step to another branch is refused by its signature).
MEASURE_STEP = 0.05


class Interpolation:
    """The interpolated mode of a sweep (cycle._Cycle)."""

    def _interpolated(self, index: int, xs: np.ndarray) -> RangeChunk:
        """Exact poses every n-th (batched when dense), Hermite between, accuracy measured."""
        n, ref = len(xs), self.ref
        exact_at = np.array(sorted(set(range(self.interpolate - 1, n, self.interpolate)) | {n - 1}), dtype=int)
        qe, d1e, d2e, acc_e = self._exact(xs[exact_at])
        nq, nv = qe.shape[1], d1e.shape[1]
        q, d1, d2 = np.empty((n + 1, nq)), np.empty((n + 1, nv)), np.empty((n + 1, nv))
        acc = _accuracy_arrays(n + 1)
        slots = exact_at + 1
        q[0], d1[0], d2[0] = ref.q, ref.d1, ref.d2
        q[slots], d1[slots], d2[slots] = qe, d1e, d2e
        for name in _ACCURACY:
            acc[name][slots] = acc_e[name]
        acc["condition"][0], acc["sigma_min"][0] = ref.condition, ref.sigma_min
        solved = np.zeros(n + 1, dtype=bool)
        solved[0] = True
        solved[slots] = True
        x = np.concatenate(([ref.p], xs))
        targets = np.flatnonzero(~solved)
        if targets.size:
            q[targets], d1[targets], d2[targets] = self._hermite(x, q, d1, d2, solved, targets)
            self._measure(x, q, d1, d2, solved, targets, acc)
        interpolated = np.zeros(n, dtype=bool)
        interpolated[targets - 1] = True
        return self._actual(index, xs, q[1:], d1[1:], d2[1:], {k: v[1:] for k, v in acc.items()}, interpolated)

    def _hermite(self, x: np.ndarray, q: np.ndarray, d1: np.ndarray, d2: np.ndarray, solved: np.ndarray,
                 targets: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, q', q'' at the slots `targets`, between their solved neighbours."""
        known = np.flatnonzero(solved)
        at = np.searchsorted(known, targets)
        return self._hermite_at(x, q, d1, d2, known[at - 1], known[at], x[targets])

    def _hermite_at(self, x: np.ndarray, q: np.ndarray, d1: np.ndarray, d2: np.ndarray, left: np.ndarray,
                    right: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, q', q'' at driver values `at` between slots `left` and `right` (hermite.py)."""
        try:
            return interpolate_poses(self.solver.model, x, q, d1, d2, left, right, at)
        except ValueError:  # two poses at one driver value: pose by pose instead
            raise _Fallback from None

    def _measure(self, x: np.ndarray, q: np.ndarray, d1: np.ndarray, d2: np.ndarray, solved: np.ndarray,
                 targets: np.ndarray, acc: dict[str, np.ndarray]) -> None:
        """Each interpolated pose gets the worst accuracy measured at its interval's error
        peaks (PEAKS), and the worst condition number of the interval's ends and peaks."""
        known = np.flatnonzero(solved)
        right_of = known[np.searchsorted(known, targets)]
        right = np.unique(right_of)
        left = known[np.searchsorted(known, right) - 1]
        at = np.concatenate([x[left] + p * (x[right] - x[left]) for p in PEAKS])
        reps = len(PEAKS)
        probe = self._hermite_at(x, q, d1, d2, np.tile(left, reps), np.tile(right, reps), at)
        m = self.measurer.measure(*probe) if self.measurer is not None else None
        where = np.searchsorted(right, right_of)
        for name in ("residual", "velocity_residual", "acceleration_residual"):
            worst = np.max(getattr(m, name).reshape(reps, -1), axis=0) if m is not None else np.zeros(len(right))
            acc[name][targets] = worst[where]
        cond = np.maximum(acc["condition"][left], acc["condition"][right])
        sigma = np.minimum(acc["sigma_min"][left], acc["sigma_min"][right])
        if m is not None:
            cond = np.maximum(cond, np.max(m.condition.reshape(reps, -1), axis=0))
            sigma = np.minimum(sigma, np.min(m.sigma_min.reshape(reps, -1), axis=0))
        acc["condition"][targets], acc["sigma_min"][targets] = cond[where], sigma[where]
        if m is not None:
            absolute = np.max(self._interpolation_errors(at, probe).reshape(reps, -1, 3), axis=0)[where]
            acc["interpolation"][targets] = INTERPOLATION_SAFETY * self._relative(absolute, d1[targets], d2[targets])

    def _interpolation_errors(self, at: np.ndarray, probe: tuple) -> np.ndarray:
        """(N, 3) largest differences between interpolated poses (q, q', q'') and the exact
        poses at the same driver values: positions [rad, or sizes of the loops], then q'
        and q'' in the same units per unit of the driver. _Fallback where an exact pose
        cannot be had (the chunk is then solved pose by pose)."""
        q, d1, d2 = self._exact_at(at, probe[0])
        solver = self.solver
        inv = solver._v_scale_inv
        dq = difference_many(solver.model, q, probe[0]) * inv
        return np.stack([np.abs(dq).max(axis=1), np.abs((probe[1] - d1) * inv).max(axis=1),
                         np.abs((probe[2] - d2) * inv).max(axis=1)], axis=1)

    def _exact_at(self, at: np.ndarray, guesses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Exact q, q', q'' at driver values `at`, from interpolated guesses: batched, else
        pose by pose (a guess too far for the batch)."""
        n, ref = len(at), self.ref
        out = self.measurer.try_solve(guesses, self._drivers(at), np.tile(self.unit_v, (n, 1)),
                                      np.tile(self.zero, (n, 1)), max_step=MEASURE_STEP, _on_path=True)
        if out is not None and not (ref.signs and np.any(out.signs != np.array(ref.signs))):
            return out.q, out.v, out.a
        solver = self.solver
        q, d1, d2 = np.empty_like(guesses), np.empty((n, solver.model.nv)), np.empty((n, solver.model.nv))
        for i, (x, guess) in enumerate(zip(self._drivers(at), guesses)):
            q[i], residual = solver.correct(guess, x, max_iterations=solver.max_iterations, strict=False)
            if residual is None:
                raise _Fallback
            try:
                d1[i], d2[i], *_, signs = solver._rates(q[i], self.unit_v, self.zero)
            except SingularPoseError:
                raise _Fallback from None
            if ref.signs and signs != ref.signs:
                raise _Fallback
        return q, d1, d2

    def _relative(self, absolute: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
        """Absolute interpolation errors (positions, q', q'') as relative errors of each
        pose's positions, velocities and accelerations in the scene's rates: the velocity
        error over the pose's largest velocity (lengths in loop sizes), likewise for the
        acceleration q'' w^2 + q' alpha (over w^2 |q'| where every joint's is zero: a
        mechanism whose joints move in proportion has no acceleration to be relative to)."""
        w, alpha = abs(float(self.v_drv[self.k])), float(self.a_drv[self.k])
        inv = self.solver._v_scale_inv
        v = np.abs(d1 * inv).max(axis=1)
        a = np.abs((d2 * (w * w) + d1 * alpha) * inv).max(axis=1)
        a = np.where(a > 0, a, w * w * v)
        error_a = absolute[:, 2] * (w * w) + absolute[:, 1] * abs(alpha)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel_v = np.where(absolute[:, 1] > 0, absolute[:, 1] / v, 0.0)
            rel_a = np.where(error_a > 0, error_a / a, 0.0)
        return np.stack([absolute[:, 0], rel_v, rel_a], axis=1)
