"""The tests' tolerances, each derived from what the arithmetic guarantees.

A check compares a number pinmech computes with an independent one (a closed form, an identity,
a published value). Both are rounded, and another libm, BLAS or SIMD path rounds them
differently (numpy's NPY_DISABLE_CPU_FEATURES="X86_V3 X86_V4 AVX512_ICL AVX512_SPR",
OPENBLAS_CORETYPE=Prescott), so a bar is never "1e-12 by habit" but one of:

- `rounding(scale, cond)`: a closed form of a few dozen float operations on numbers of size
  `scale`: each operation (and each libm call) is off by an ulp or so, so the result is within
  STEPS x eps x scale, times the condition number `cond` of the step that amplifies most (a
  square root near zero, an acos near +-1, a difference of near-equal numbers).
- `closure(scale, cond, order)`: a pose the engine solved, its loops closed to the solver's
  tolerance (DEFAULT_TOL of the loop's size): pinmech's own bound (Accuracy.error_bounds) with
  that residual, plus the rounding of the closed form it is checked against.
- `stated(residual, condition, scale, order)`: the bound pinmech states of one solved pose
  (Accuracy.error_bounds: 4 k m on positions, 4 k^2 m on rates, 16 k^3 m on accelerations, m
  the closure residual or eps, k the condition number).
- `residual(scale)`: a closure residual, at most the solver's tolerance of the loop's size.
- `REGULAR`: the condition number of the tests' regular poses, where a check has none at hand;
  `STATED_*`: accuracies the docs claim, checked as such.

To flush what one machine's rounding hides, run the numeric tests with numpy's dispatch and
OpenBLAS's kernels narrowed (the environment above) and with fresh hypothesis draws
(`pytest --hypothesis-profile=explore`; the default profile is derandomized).

A real error (a wrong branch, frame, sign or unit) is a fraction of the numbers' size, 1e-3
and up: every bar here is many orders of magnitude below it, so each check can still fail.
"""

from __future__ import annotations

import numpy as np

from pinmech.solve.results import BOUND_FACTORS, Accuracy
from pinmech.solve.solver_options import DEFAULT_TOL

#: Machine epsilon of float64 [-].
EPS = float(np.finfo(float).eps)
#: Rounded operations allowed a test's closed form, a margin over its count (Higham's
#: gamma_n = n u: n operations lose at most about n half-ulps, here over both sides).
STEPS = 64


def rounding(scale: float, cond: float = 1.0, steps: int = STEPS) -> float:
    """Bar on a closed form of numbers of size `scale` [their unit]: steps x eps x cond x scale."""
    return float(steps * EPS * np.max(cond) * np.max(np.abs(scale)))


def closure(scale: float, cond: float = 1.0, order: int = 0, tol: float = DEFAULT_TOL) -> float:
    """Bar on a pose the engine closed to `tol` of the loops' size, at condition number
    `cond`: pinmech's bound (Accuracy.error_bounds) with the residual at the tolerance it
    guarantees, on positions (order 0: 4 k tol), rates (1: 4 k^2 tol) or accelerations
    (2: 16 k^3 tol), times the size `scale` of the numbers [their unit]; plus the rounding
    of the closed form they are compared with."""
    k = float(np.max(cond))
    return BOUND_FACTORS[order] * k ** (order + 1) * tol * float(np.max(np.abs(scale))) + rounding(scale, k**order)


def stated(residual: float, condition: float, scale: float, order: int = 0) -> float:
    """pinmech's own bound (Accuracy.error_bounds) on a solved pose's positions (order 0),
    velocities (1) or accelerations (2), from the pose's closure `residual` and the rate
    Jacobian's `condition` number, times the size `scale` of the numbers [their unit]; plus
    the rounding of the closed form they are checked against."""
    bounds = Accuracy(float(np.max(residual)), 0, float(np.max(condition)), 0.0).error_bounds
    return bounds[order] * float(np.max(np.abs(scale))) + rounding(scale, float(np.max(condition)) ** order)


def residual(scale: float, tol: float = DEFAULT_TOL) -> float:
    """Bar on the closure residual of a pose the engine solved, loops of size `scale` [m]:
    the solver's tolerance `tol` of that size, plus the rounding of the rows recomputed."""
    return tol * float(np.max(np.abs(scale))) + rounding(scale)


#: The condition number bounding the tests' regular poses (far from folds and dead centres):
#: over a turn the bundled four-bar reaches 4.7, the slider-crank 1.7, the R-RTR 2.0; 1e2
#: leaves room for the other mechanisms whose docstrings state "below 1e2".
REGULAR = 1e2

#: Accuracies the docs state of the engine against textbook closed forms, checked as claims
#: (not rounding bars): the R-RTR within 1e-13 of each quantity's size at every pose
#: (docs/explanation/accuracy.md), sweeps and loop chains within 1e-12 rad (benchmarks.md).
STATED_R_RTR = 1e-13
STATED_SWEEP = 1e-12
