"""Loop cuts: how many equations each gives, and that the compiled core's rows are exact
at every level, on each cut type, planar and spatial.

The core's pose error and velocity rows are the textbook relative motion of C in P from
Pinocchio's own placements and frame velocities; its Newton Jacobian is the derivative
of its residual and its drift the derivative of J v along the motion (finite differences
on the configuration manifold); the rows' change along the frames' motions is the
derivative of the textbook velocity and acceleration formulas.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech import Mechanism
from pinmech.model.closure_core import ClosureRows, closure_rows, cut_rows_change
from pinmech.model.closures import Closure
from tests._mechanisms import (
    four_bar_urdf,
    slider_crank_prismatic_cut_urdf,
    spatial_rsur_revolute_cut_urdf,
    spatial_rsur_urdf,
    write,
)
from tests.tolerance import rounding


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
    np.testing.assert_allclose(S @ S.T, np.eye(expected_rows), atol=rounding(1.0))


def _random_state(model, seed):
    rng = np.random.default_rng(seed)
    q = pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv))
    return q, rng.normal(size=model.nv)


def _tilted(x: float, y: float, z: float, planar: bool) -> pin.SE3:
    R = np.eye(3) if planar else pin.rpy.rpyToMatrix(0.3, -0.2, 0.4)
    return pin.SE3(R, np.array([x, y, 0.0 if planar else z]))


def _two_chains(cut_type: str, planar: bool) -> tuple[pin.Model, Closure]:
    """Two two-hinge chains from the ground, the cut frame P at the end of one and C at the
    end of the other; hinges about z (planar) or about tilted axes (spatial). The cut is
    open at a random q: every check below holds at any q, closed or not."""
    model = pin.Model()
    hinge = pin.JointModelRZ
    a = model.addJoint(0, hinge(), _tilted(0.0, 0.0, 0.0, planar), "a1")
    a = model.addJoint(a, hinge() if planar else pin.JointModelRY(), _tilted(0.1, 0.02, 0.03, planar), "a2")
    b = model.addJoint(0, hinge(), _tilted(0.3, 0.05, -0.02, planar), "b1")
    b = model.addJoint(b, hinge() if planar else pin.JointModelRX(), _tilted(0.12, -0.04, 0.05, planar), "b2")
    P = model.addFrame(pin.Frame("P", a, _tilted(0.09, 0.01, 0.02, planar), pin.FrameType.OP_FRAME))
    C = model.addFrame(pin.Frame("C", b, _tilted(0.05, 0.07, -0.01, planar), pin.FrameType.OP_FRAME))
    axis = np.array([0.0, 0.0, 1.0]) if planar else np.array([0.36, 0.48, 0.8])
    return model, Closure("cut", cut_type, P, C, axis, axis, length_scale=0.25)


def _relative6(model: pin.Model, data: pin.Data, closure: Closure) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's own frame motion (data after forwardKinematics(q, v, 0)), the textbook
    relative velocity of C in P in P's axes: R_P^T (v_C - v_P - w_P x (p_C - p_P)) and
    R_P^T (w_C - w_P); and the pose error R_P^T (p_C - p_P) [m]."""
    pin.updateFramePlacements(model, data)
    M_P, M_C = data.oMf[closure.parent_frame], data.oMf[closure.child_frame]
    V_P = pin.getFrameVelocity(model, data, closure.parent_frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    V_C = pin.getFrameVelocity(model, data, closure.child_frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    delta = M_C.translation - M_P.translation
    R_T = M_P.rotation.T
    velocity = np.concatenate((R_T @ (V_C.linear - V_P.linear - np.cross(V_P.angular, delta)),
                               R_T @ (V_C.angular - V_P.angular)))
    return velocity, R_T @ delta


CUT_CASES = [(t, planar) for t in ("revolute", "prismatic", "spherical", "fixed") for planar in (True, False)]


@pytest.mark.parametrize("cut_type, planar", CUT_CASES, ids=[f"{t}-{'planar' if p else 'spatial'}" for t, p in CUT_CASES])
def test_the_cores_closure_rows_are_the_textbook_relative_motion(cut_type, planar):
    """At three seeded open poses: the core's position error is Pinocchio's R_P^T (p_C - p_P)
    (to 1e-15, rounding of numbers of 0.3); its orientation error is a_P x (R a_C) for a
    revolute cut, log3(R_P^T R_C) for a prismatic or fixed one (closed forms on Pinocchio's
    placements, 1e-14); its velocity rows J v are rows6 times the textbook relative
    velocity from Pinocchio's frame velocities (1e-13 for numbers of order 1)."""
    model, closure = _two_chains(cut_type, planar)
    rows, data = ClosureRows(model, [closure]), model.createData()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, v = pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv)), rng.normal(size=model.nv)
        pin.forwardKinematics(model, data, q, v)
        velocity, position = _relative6(model, data, closure)
        error = rows.errors6(q)[0]
        np.testing.assert_allclose(error[:3], position, rtol=0, atol=rounding(0.3))
        R_rel = data.oMf[closure.parent_frame].rotation.T @ data.oMf[closure.child_frame].rotation
        if cut_type == "revolute":
            np.testing.assert_allclose(error[3:], np.cross(closure.axis, R_rel @ closure.child_axis), atol=rounding(1.0))
        elif cut_type != "spherical":
            np.testing.assert_allclose(error[3:], pin.log3(R_rel), atol=rounding(1.0))
        np.testing.assert_allclose(rows.jacobian(q) @ v, closure.rows6 @ velocity, rtol=0, atol=1e-13)


@pytest.mark.parametrize("cut_type, planar", CUT_CASES, ids=[f"{t}-{'planar' if p else 'spatial'}" for t, p in CUT_CASES])
def test_the_cores_jacobians_and_drift_are_finite_differences(cut_type, planar):
    """At three seeded open poses, central differences on the manifold (pin.integrate),
    h = 1e-6 (truncation h^2 ~ 1e-12, rounding eps / h ~ 1e-10; atol 1e-8 for rows of order 1):
    the Newton Jacobian is d(residual)/dq in every row; the velocity Jacobian's position rows
    are too (its orientation rows are the relative angular velocity, checked above); the
    drift is d/dt (J v) along q (+) t v; `translation_rows` is d(residual)/d(eps) with the
    child cut frame moved eps along each world axis in the model (minus it for the parent)."""
    model, closure = _two_chains(cut_type, planar)
    rows, h = ClosureRows(model, [closure]), 1e-6
    linear = np.abs(closure.rows6[:, :3]).sum(axis=1) > 0
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, v = pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv)), rng.normal(size=model.nv)
        fd = np.column_stack([(rows.residual(pin.integrate(model, q, h * e)) - rows.residual(pin.integrate(model, q, -h * e)))
                              / (2 * h) for e in np.eye(model.nv)])
        np.testing.assert_allclose(rows.jacobian(q, newton=True), fd, rtol=0, atol=1e-8)
        np.testing.assert_allclose(rows.jacobian(q)[linear], fd[linear], rtol=0, atol=1e-8)
        Jv = [rows.jacobian(pin.integrate(model, q, s * h * v)) @ v for s in (1, -1)]
        np.testing.assert_allclose(rows.drift(q, v), (Jv[0] - Jv[1]) / (2 * h), rtol=0, atol=1e-8)
        D = rows.translation_rows(q)
        for frame, sign in ((closure.child_frame, 1.0), (closure.parent_frame, -1.0)):
            np.testing.assert_allclose(sign * D, _moved_frame_differences(model, rows, frame, q, h), atol=1e-8)


def _moved_frame_differences(model, rows, frame: int, q: np.ndarray, h: float) -> np.ndarray:
    """(rows, 3): central differences of the residual with `frame` translated along each
    world axis (its placement moved in the model, then put back)."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    R_joint = data.oMi[model.frames[frame].parentJoint].rotation
    start = model.frames[frame].placement.copy()
    out = []
    for e in np.eye(3):
        values = []
        for s in (h, -h):
            moved = start.copy()
            moved.translation = start.translation + R_joint.T @ (s * e)
            model.frames[frame].placement = moved
            values.append(rows.residual(q))
        model.frames[frame].placement = start
        out.append((values[0] - values[1]) / (2 * h))
    return np.column_stack(out)


def _velocity6(m: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The relative velocity 6-vector of C in P from their world motions (rows x, v, w, acc,
    alpha, R): R_P^T (v_C - v_P - w_P x delta), R_P^T (w_C - w_P)."""
    R_T, delta = m[5:].T, c[0] - m[0]
    return np.concatenate((R_T @ (c[1] - m[1] - np.cross(m[2], delta)), R_T @ (c[2] - m[2])))


def _acceleration6(m: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Its time derivative with x' = v, v' = acc, w' = alpha, R_P' = [w_P]x R_P."""
    R_T, delta, dv = m[5:].T, c[0] - m[0], c[1] - m[1]
    d = dv - np.cross(m[2], delta)
    d_dot = c[3] - m[3] - np.cross(m[4], delta) - np.cross(m[2], dv)
    return np.concatenate((R_T @ (d_dot - np.cross(m[2], d)), R_T @ (c[4] - m[4] - np.cross(m[2], c[2] - m[2]))))


def _moved(m: np.ndarray, dm: np.ndarray, t: float) -> np.ndarray:
    out = m.copy()
    out[:5] += t * dm[:5]
    out[5:] = pin.exp3(t * dm[5]) @ m[5:]
    return out


def test_the_acceleration_rows_are_the_time_derivative_of_the_velocity_rows():
    """Along a motion of both frames (x' = v, v' = acc, w' = alpha, R' = [w]x R), the
    derivative of the velocity 6-vector is the acceleration 6-vector: central differences
    of the textbook velocity formula, h = 1e-5 (truncation h^2 ~ 1e-10, atol 1e-8)."""
    rng = np.random.default_rng(9)
    m, c = (np.vstack([rng.normal(size=(5, 3)), pin.exp3(rng.normal(size=3))]) for _ in range(2))
    dm, dc = (np.vstack([x[1], x[3], x[4], np.zeros(3), np.zeros(3), x[2]]) for x in (m, c))
    h = 1e-5
    fd = (_velocity6(_moved(m, dm, h), _moved(c, dc, h)) - _velocity6(_moved(m, dm, -h), _moved(c, dc, -h))) / (2 * h)
    np.testing.assert_allclose(_acceleration6(m, c), fd, atol=1e-8)


@pytest.mark.parametrize("order", [1, 2])
def test_the_cores_rows_change_is_the_finite_difference_of_the_rows(order):
    """cut_rows_change: the change of a cut's velocity (order 1) or acceleration (order 2)
    rows along a change of both frames' motions, against central differences of the
    textbook formulas (above), h = 1e-6: truncation ~1e-12, rounding ~1e-10; atol 1e-8."""
    model, closure = _two_chains("revolute", planar=False)
    rng = np.random.default_rng(13 + order)
    m, c = (np.vstack([rng.normal(size=(5, 3)), pin.exp3(rng.normal(size=3))]) for _ in range(2))
    dm, dc = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    formula = _velocity6 if order == 1 else _acceleration6
    h = 1e-6
    fd = closure.rows6 @ (formula(_moved(m, dm, h), _moved(c, dc, h)) - formula(_moved(m, dm, -h), _moved(c, dc, -h)))
    np.testing.assert_allclose(cut_rows_change(closure, order, m, c, dm, dc), fd / (2 * h), rtol=0, atol=1e-8)


@pytest.mark.parametrize("which", ["r_rtr", "four_bar", "rsur", "rsur_revolute", "prismatic_cut"])
def test_a_mechanisms_rows_are_finite_differences(which, models_dir, tmp_path):
    """A mechanism's reduced rows (each cut's basis) on the core, at a seeded open pose:
    d(residual)/dq is the Newton Jacobian and d/dt (J v) the drift; central differences on
    the manifold, h = 1e-6 (truncation ~1e-12, rounding ~1e-10): atol 1e-8."""
    mech = _mechanism(which, models_dir, tmp_path)
    model, rows, h = mech.model, closure_rows(mech), 1e-6
    q, v = _random_state(model, 1)
    fd = np.column_stack([(rows.residual(pin.integrate(model, q, h * e)) - rows.residual(pin.integrate(model, q, -h * e)))
                          / (2 * h) for e in np.eye(model.nv)])
    np.testing.assert_allclose(rows.jacobian(q, newton=True), fd, rtol=0, atol=1e-8)
    Jv = [rows.jacobian(pin.integrate(model, q, s * h * v)) @ v for s in (1, -1)]
    np.testing.assert_allclose(rows.drift(q, v), (Jv[0] - Jv[1]) / (2 * h), rtol=0, atol=1e-8)


def _mechanism(which, models_dir, tmp_path):
    if which == "r_rtr":
        return Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    texts = {"four_bar": four_bar_urdf, "rsur": spatial_rsur_urdf, "rsur_revolute": spatial_rsur_revolute_cut_urdf,
             "prismatic_cut": slider_crank_prismatic_cut_urdf}
    return Mechanism.from_urdf(write(tmp_path, f"{which}.urdf", texts[which]()))
