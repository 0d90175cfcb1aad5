"""The bars of tests/tolerance.py: above the rounding they allow for, far below a real error."""

from __future__ import annotations

import numpy as np

from tests.tolerance import EPS, REGULAR, closure, residual, rounding, stated


def test_a_bar_allows_each_operation_an_ulp_and_the_condition_number_its_share():
    assert rounding(1.0) > 32 * EPS and rounding(0.1, 10.0) == 10 * rounding(0.1)
    assert rounding(np.array([-0.3, 0.2])) == rounding(0.3)  # the size is the largest magnitude


def test_the_closure_bar_is_pinmechs_position_bound_at_the_solvers_tolerance():
    # 4 k tol of the size (Accuracy.error_bounds with the residual at tol = 1e-13), more for rates
    assert 4e-13 * 0.2 < closure(0.2) < 5e-13 * 0.2
    assert closure(1.0, 2.0, 1) > closure(1.0, 2.0) and residual(0.2) < closure(0.2)
    assert stated(1e-16, 2.0, 1.0) < closure(1.0, 2.0)  # an achieved residual below tol: tighter


def test_every_bar_is_far_below_a_real_error():
    # a wrong branch, frame or unit moves a 0.2 m mechanism's points by 1e-4 m and more; angles by 1e-3 rad
    for bar in (closure(0.2, REGULAR), closure(0.2, REGULAR, 1), rounding(0.2, 2e4), residual(1.0)):
        assert bar < 1e-6 * 0.2
    assert closure(np.pi, REGULAR, 2) < 1e-2 * 1e-3  # accelerations at k = 1e2: 16 k^3 tol, 5e-6 of their size
