"""Loop cuts: how many equations each gives, and that they are exact at every level.

The closure Jacobian must be the derivative of the closure residual (checked by finite
differences along the configuration manifold), and the drift term must be the derivative
of the Jacobian along the motion.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech import Mechanism
from tests._mechanisms import (
    four_bar_urdf,
    slider_crank_prismatic_cut_urdf,
    spatial_rsur_revolute_cut_urdf,
    spatial_rsur_urdf,
    write,
)


@pytest.fixture
def r_rtr(models_dir):
    return Mechanism.from_urdf(models_dir / "r_rtr.urdf")


def test_planar_revolute_cut_gives_two_in_plane_rows(r_rtr):
    (cut,) = r_rtr.closures
    assert cut.cut_type == "revolute"
    assert cut.rows == 2  # x, y: the z row and the two tilt rows vanish identically
    np.testing.assert_array_equal(cut.basis, np.eye(5)[:2])
    assert r_rtr.mobility == 1


def test_planar_mechanism_is_detected(r_rtr):
    np.testing.assert_allclose(r_rtr.plane_normal, [0, 0, 1])


def test_spatial_spherical_cut_keeps_three_rows(tmp_path):
    mech = Mechanism.from_urdf(write(tmp_path, "rsur.urdf", spatial_rsur_urdf()))
    assert mech.closures[0].rows == 3
    assert mech.plane_normal is None
    assert mech.mobility == 1


@pytest.mark.parametrize(
    "cut_type, expected_rows",
    [("revolute", 5), ("prismatic", 5), ("spherical", 3), ("fixed", 6)],
)
def test_selection_rows_per_cut_type(cut_type, expected_rows):
    from pinmech.model.closures import selection_matrix

    S = selection_matrix(cut_type, np.array([0.0, 0.0, 1.0]))
    assert S.shape == (expected_rows, 6)
    np.testing.assert_allclose(S @ S.T, np.eye(expected_rows), atol=1e-15)


def _random_state(model, seed):
    rng = np.random.default_rng(seed)
    q = pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv))
    return q, rng.normal(size=model.nv)


@pytest.mark.parametrize("which", ["r_rtr", "four_bar", "rsur"])
def test_jacobian_is_the_derivative_of_the_residual(which, models_dir, tmp_path):
    """J v = d/dt residual(q + t v): central differences, h = 1e-6.

    Away from a closed pose the angular rows' Jacobian is only approximate (the log map),
    so this checks the position rows exactly and the whole at a closed pose elsewhere.
    Truncation error ~ h^2 |r'''| ~ 1e-12, rounding ~ eps / h ~ 1e-10: rtol 1e-7.
    """
    mech = _mechanism(which, models_dir, tmp_path)
    model, data = mech.model, mech.model.createData()
    q, v = _random_state(model, 1)
    h = 1e-6

    def residual6(qq):
        pin.framesForwardKinematics(model, data, qq)
        return np.concatenate([c._scale()[:3] * c.residual6(data)[:3] for c in mech.closures])

    fd = (residual6(pin.integrate(model, q, h * v)) - residual6(pin.integrate(model, q, -h * v))) / (2 * h)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = np.vstack([c._scale()[:3, None] * c.relative_jacobian6(model, data)[:3] for c in mech.closures])
    np.testing.assert_allclose(J @ v, fd, rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("which", ["r_rtr", "four_bar", "rsur"])
def test_drift_is_the_time_derivative_of_the_jacobian_along_the_motion(which, models_dir, tmp_path):
    """drift(q, v) = d/dt [J(q(t))] v with q(t) = q + t v (q_ddot = 0 on the manifold).

    Central differences of J(q(t)) v with h = 1e-6: error ~ h^2 + eps/h, rtol 1e-6.
    """
    mech = _mechanism(which, models_dir, tmp_path)
    model, data = mech.model, mech.model.createData()
    q, v = _random_state(model, 2)
    h = 1e-6

    def J_v(qq):
        pin.computeJointJacobians(model, data, qq)
        pin.updateFramePlacements(model, data)
        return np.concatenate([c.jacobian(model, data) for c in mech.closures]) @ v

    fd = (J_v(pin.integrate(model, q, h * v)) - J_v(pin.integrate(model, q, -h * v))) / (2 * h)
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    drift = np.concatenate([c.drift(model, data) for c in mech.closures])
    # Only the position rows are exact derivatives away from a closed pose (see above).
    rows = [i for i, r in enumerate(_row_kinds(mech)) if r == "linear"]
    np.testing.assert_allclose(drift[rows], fd[rows], rtol=1e-6, atol=1e-8)


def _row_kinds(mech):
    kinds = []
    for c in mech.closures:
        lin = np.abs(c.basis @ c.selected[:, :3]).sum(axis=1) > 0
        kinds += ["linear" if x else "angular" for x in lin]
    return kinds


def _mechanism(which, models_dir, tmp_path):
    if which == "r_rtr":
        return Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    texts = {"four_bar": four_bar_urdf, "rsur": spatial_rsur_urdf, "rsur_revolute": spatial_rsur_revolute_cut_urdf,
             "prismatic_cut": slider_crank_prismatic_cut_urdf}
    return Mechanism.from_urdf(write(tmp_path, f"{which}.urdf", texts[which]()))
