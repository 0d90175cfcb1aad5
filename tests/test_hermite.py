"""Quintic Hermite of closed poses: exact for motions of degree five in the joint
coordinates (the tangent spaces of one-dof joints are all the same), and of order six."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech import Mechanism
from pinmech.solve.hermite import interpolate_poses


def _poses(model, coeffs, x):
    """q(x) = q0 (+) P(x) with P a polynomial (coefficients per degree), and P', P''."""
    powers = np.arange(coeffs.shape[0])
    P = np.polynomial.polynomial.polyval(x, coeffs).T
    P1 = np.polynomial.polynomial.polyval(x, (coeffs * powers[:, None])[1:]).T
    P2 = np.polynomial.polynomial.polyval(x, (coeffs * (powers * (powers - 1))[:, None])[2:]).T
    q = np.array([pin.integrate(model, pin.neutral(model), p) for p in P])
    return q, P1, P2


@pytest.mark.parametrize("degree, atol", [(5, 1e-13), (7, None)])
def test_exact_to_degree_five_and_sixth_order_beyond(models_dir, degree, atol):
    model = Mechanism.from_urdf(models_dir / "r_rtr.urdf").model  # two continuous joints, one prismatic
    coeffs = np.random.default_rng(degree).normal(size=(degree + 1, model.nv))
    x = np.array([0.0, 0.3])
    q, d1, d2 = _poses(model, coeffs, x)
    at = np.linspace(0.0, 0.3, 7)
    left, right = np.zeros(7, dtype=int), np.ones(7, dtype=int)
    Q, D1, D2 = interpolate_poses(model, x, q, d1, d2, left, right, at)
    q_true, d1_true, d2_true = _poses(model, coeffs, at)
    error = np.abs(np.array([pin.difference(model, a, b) for a, b in zip(Q, q_true)])).max()
    if atol is not None:
        assert error < atol
        np.testing.assert_allclose(D1, d1_true, atol=atol * 10)
        np.testing.assert_allclose(D2, d2_true, atol=atol * 100)
    else:  # halving the interval divides the position error by about 2^6
        Qh, _, _ = interpolate_poses(model, np.array([0.0, 0.15]), *_poses(model, coeffs, np.array([0.0, 0.15])),
                                     left, right, at / 2)
        q_half = _poses(model, coeffs, at / 2)[0]
        error_half = np.abs(np.array([pin.difference(model, a, b) for a, b in zip(Qh, q_half)])).max()
        assert 40 < error / error_half < 90


def test_two_poses_at_one_value_have_no_interval(models_dir):
    model = Mechanism.from_urdf(models_dir / "r_rtr.urdf").model
    q = np.tile(pin.neutral(model), (2, 1))
    d = np.zeros((2, model.nv))
    with pytest.raises(ValueError, match="same driver value"):
        interpolate_poses(model, np.zeros(2), q, d, d, np.array([0]), np.array([1]), np.array([0.0]))
