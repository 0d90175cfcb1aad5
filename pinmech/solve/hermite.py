"""Quintic Hermite interpolation of closed poses on the configuration manifold.

Between two solved poses at driver values x0 and x1 (h = x1 - x0), a pose at
x0 + s h is interpolated from the poses' configurations and path derivatives
(q, q' = dq/dx, q'' = d2q/dx2), in the tangent space at the first pose:

    q(s) = q0 (+) p(s),  p(0) = 0,  p(1) = q1 (-) q0,  p' and p'' matching h q', h^2 q''

so the interpolant is exact for polynomials of degree five, and its error behaves like
h^6, h^5, h^4 in position, velocity and acceleration (peaking, to leading order, where
s^3 (1 - s)^3 and its derivatives do). Exact in the tangent space for one-dof joints,
whose tangent spaces are all the same; a guess to be corrected for any other joint.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.solve.manifold import difference_many, integrate_many


def interpolate_poses(model: pin.Model, x: np.ndarray, q: np.ndarray, d1: np.ndarray, d2: np.ndarray,
                      left: np.ndarray, right: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, q', q'' at driver values `at`, each between the solved rows `left` and `right`.

    Args:
        x, q, d1, d2: driver values, configurations and path derivatives of solved poses.
        left, right: for each value of `at`, the rows it lies between; runs of equal
            `right` share one interval (its polynomial is built once).

    Raises:
        ValueError: an interval of zero length (two solved poses at one driver value).
    """
    starts = np.flatnonzero(np.concatenate(([True], right[1:] != right[:-1])))
    counts = np.diff(np.append(starts, len(right)))
    i, j = left[starts], right[starts]
    h = (x[j] - x[i])[:, None]
    if np.any(h == 0):
        raise ValueError("two solved poses at the same driver value: no interval to interpolate in")
    coeffs = _coefficients(h * d1[i], h * h * d2[i], difference_many(model, q[i], q[j]), h * d1[j], h * h * d2[j])
    hw = np.repeat(h, counts, axis=0)
    s = (at[:, None] - x[left][:, None]) / hw
    c1, c2, c3, c4, c5 = (np.repeat(c, counts, axis=0) for c in coeffs)
    p = s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5))))  # Horner
    dp = c1 + s * (2 * c2 + s * (3 * c3 + s * (4 * c4 + s * 5 * c5)))
    ddp = 2 * c2 + s * (6 * c3 + s * (12 * c4 + s * 20 * c5))
    return integrate_many(model, q[left], p), dp / hw, ddp / (hw * hw)


def _coefficients(v0: np.ndarray, a0: np.ndarray, delta: np.ndarray, v1: np.ndarray,
                  a1: np.ndarray) -> tuple[np.ndarray, ...]:
    """c1..c5 of p(s) = c1 s + ... + c5 s^5 on [0, 1] with p(0) = 0, p'(0) = v0,
    p''(0) = a0, p(1) = delta, p'(1) = v1, p''(1) = a1."""
    c3 = 10 * delta - 6 * v0 - 4 * v1 - 1.5 * a0 + 0.5 * a1
    c4 = -15 * delta + 8 * v0 + 7 * v1 + 1.5 * a0 - a1
    c5 = 6 * delta - 3 * v0 - 3 * v1 - 0.5 * a0 + 0.5 * a1
    return v0, 0.5 * a0, c3, c4, c5
