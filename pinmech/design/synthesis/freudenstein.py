"""Freudenstein's equation for four-bar function generation, the closed form the search
starts from and the tests check against.

With the ground d from O2 to O4 along x, the crank a at angle theta and the rocker c at
angle phi (both from x), and the coupler b, the loop closes when

    K1 cos(phi) - K2 cos(theta) + K3 = cos(theta - phi),
    K1 = d / a,  K2 = d / c,  K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c),

linear in K1, K2, K3: three precision points (theta_i, phi_i) fix them, more are met in
least squares.
"""

from __future__ import annotations

import math

import numpy as np


def freudenstein_k(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """K1, K2, K3 from 3 precision points (exact) or more (least squares); angles [rad]."""
    theta, phi = np.asarray(theta, dtype=float), np.asarray(phi, dtype=float)
    M = np.stack((np.cos(phi), -np.cos(theta), np.ones_like(theta)), -1)
    return np.linalg.lstsq(M, np.cos(theta - phi), rcond=None)[0]


def link_lengths(k: np.ndarray, ground: float) -> tuple[float, float, float] | None:
    """(crank a, coupler b, rocker c) [m] of K1, K2, K3 for a ground d [m], or None where
    they are no linkage (a or c not positive, b^2 not positive)."""
    k1, k2, k3 = (float(x) for x in k)
    if k1 == 0 or k2 == 0:
        return None
    a, c = ground / k1, ground / k2
    b2 = a * a + c * c + ground * ground - 2 * a * c * k3
    if a <= 0 or c <= 0 or b2 <= 0:
        return None
    return a, math.sqrt(b2), c


def chebyshev_spacing(lower: float, upper: float, n: int) -> np.ndarray:
    """Chebyshev's precision points of [lower, upper]: (lower + upper)/2 - (upper - lower)/2
    cos((2j - 1) pi / 2n), j = 1..n, the spacing that evens out the error between them."""
    j = np.arange(1, n + 1)
    return 0.5 * (lower + upper) - 0.5 * (upper - lower) * np.cos((2 * j - 1) * math.pi / (2 * n))
