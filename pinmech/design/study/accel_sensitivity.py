"""Exact first-order sensitivities of accelerations to the parameters: the implicit-function
theorem on the acceleration closure rows, after the configuration's (sensitivity.py) and
the velocities' (rate_sensitivity.py).

Each cut's acceleration rows are the time derivative of its velocity rows
G = rows6 [R_P^T a_; R_P^T b], a_ = v_C - v_P - w_P x delta, b = w_C - w_P:

    A = rows6 [R_P^T (acc_C - acc_P - alpha_P x delta - w_P x (v_C - v_P) - w_P x a_);
               R_P^T (alpha_C - alpha_P - w_P x b)]

(acc: a frame origin's classical acceleration, alpha: its angular acceleration, world
axes), zero on every variant with the drivers' accelerations held. Along a parameter p_k
the pose moves by S = dq/dp_k, the speeds by w = dv/dp_k (rate_sensitivity.py), and the
frames a translation parameter carries by u, fixed in the carrying body (angular velocity
w_b, acceleration alpha_b). At fixed a, each frame's quantities change by

    d(spatial acceleration) = (dA/dq) S + (dA/dv) w     (Pinocchio's
        computeForwardKinematicsDerivatives, getFrameAccelerationDerivatives, LOCAL_WORLD_ALIGNED:
        the motion field's change at a point held in place; at the frame's origin, which
        moves by J_lin S, add alpha x J_lin S, and w x J_lin S to the velocity's)
    d(velocity) = (dV/dq) S + w x J_lin S + J w + [w_b x u; 0],   dx = J_lin S + u,   d(theta) = J_ang S
    d(acc) = d(spatial linear) + alpha x J_lin S + dw x v + w x dv_tree + alpha_b x u + w_b x (w_b x u)

and differentiating A term by term (d(R_P^T y) = R_P^T (dy - d(theta_P) x y), the core's
`cut_rows_change`) gives dA/dp_k at fixed a; then J_dep da_dep/dp_k = -dA/dp_k. A link's angular acceleration
alpha_f moves by n . ((d alpha_f at fixed a) + J_f,ang da/dp_k). A drawn linkage's param
(drawn_params.py) translates nothing by u but turns and moves the placements themselves:
A and alpha_f gain the drawing's own change at fixed (q, v, a), their central differences
over the drawings at p +- STEP.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.directions import cross as _cross
from pinmech.model.closure_core import closure_rows, cut_rows_change

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class _Frames:
    """Frames' kinematics at (q, v, a) and their changes along (S, w, u) at fixed a."""

    def __init__(self, sm, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        model = sm.model
        if not hasattr(sm, "_acc_data"):
            sm._acc_data = model.createData()
        self.model, self.data, self.sm = model, sm._acc_data, sm
        pin.computeForwardKinematicsDerivatives(model, self.data, q, v, a)
        pin.updateFramePlacements(model, self.data)
        self._at: dict[int, tuple] = {}

    def __call__(self, f: int) -> tuple:
        """(x, R, v, w, acc, alpha, J, V_dq, A_dq, A_dv) of frame f, world axes."""
        if f not in self._at:
            model, data = self.model, self.data
            M = data.oMf[f]
            V = pin.getFrameVelocity(model, data, f, _LWA)
            A = pin.getFrameAcceleration(model, data, f, _LWA)
            v_dq, a_dq, a_dv, a_da = (np.asarray(x).reshape(6, -1)
                                      for x in pin.getFrameAccelerationDerivatives(model, data, f, _LWA))
            acc = A.linear + _cross(V.angular, V.linear)
            self._at[f] = (M.translation.copy(), M.rotation.copy(), V.linear.copy(), V.angular.copy(), acc,
                           A.angular.copy(), a_da, v_dq, a_dq, a_dv)
        return self._at[f]

    def body(self, joint: int) -> tuple[np.ndarray, np.ndarray]:
        """(angular velocity, angular acceleration) of a joint's body, world axes."""
        R = self.data.oMi[joint].rotation
        return R @ self.data.v[joint].angular, R @ self.data.a[joint].angular

    def change(self, f: int, S: np.ndarray, w: np.ndarray, u: np.ndarray, carrier: tuple) -> tuple:
        """(dx, d_theta, dv, dw, d_acc, d_alpha) of frame f along S, w and the translation u
        carried by a body of (angular velocity, angular acceleration) `carrier`."""
        x, R, v, om, acc, al, J, v_dq, a_dq, a_dv = self(f)
        dV = v_dq @ S + J @ w  # Pinocchio's: the motion field's change at a point held in place
        dA = a_dq @ S + a_dv @ w
        dx_tree = J[:3] @ S
        dv_tree, dw = dV[:3] + _cross(om, dx_tree), dV[3:]  # at the origin, which moves by dx_tree
        d_acc = dA[:3] + _cross(al, dx_tree) + _cross(dw, v) + _cross(om, dv_tree)
        dv = dv_tree
        if u.any():
            w_b, al_b = carrier
            dv = dv + _cross(w_b, u)
            d_acc = d_acc + _cross(al_b, u) + _cross(w_b, _cross(w_b, u))
        return J[:3] @ S + u, J[3:] @ S, dv, dw, d_acc, dA[3:]


def acceleration_sensitivity(sm, q: np.ndarray, v: np.ndarray, a: np.ndarray, dq_dp: np.ndarray,
                             dv_dp: np.ndarray, frames: list[int]) -> np.ndarray:
    """d(alpha . n)/dp (len(frames), n_par) of link frames' angular accelerations about the
    plane normal n at the closed pose (q, v, a) [rad/s^2 per m], the drivers' speeds and
    accelerations held."""
    mech, model = sm.mechanism, sm.model
    fr = _Frames(sm, q, v, a)
    driven = {mech.driver_index(n) for n in sm.solver.drivers}
    dep = [i for i in range(model.nv) if i not in driven]
    J = closure_rows(mech).jacobian(q)
    n_par = len(sm.placements)
    dA, d_alpha = np.zeros((len(J), n_par)), np.zeros((len(frames), 3, n_par))
    for k, place in enumerate(sm.placements):
        u = place.direction(fr.data)
        carrier = fr.body(place.written_in)
        S, w = dq_dp[:, k], dv_dp[:, k]
        moved = lambda f: u if place.moves_frame(f, sm.subtree) else np.zeros(3)  # noqa: E731
        dA[:, k] = np.concatenate([_cut_rows(c, fr, S, w, moved, carrier) for c in mech.closures])
        for i, f in enumerate(frames):
            d_alpha[i, :, k] = fr.change(f, S, w, np.zeros(3), carrier)[5]
        if place.drawn:  # the drawing's own change at fixed q, v, a: its central differences
            dA[:, k] += place.column(lambda: _rows_now(sm, q, v, a, frames)[0])
            d_alpha[:, :, k] += place.column(lambda: _rows_now(sm, q, v, a, frames)[1])
    da = np.zeros((model.nv, n_par))
    da[dep] = -np.linalg.solve(J[:, dep], dA)
    normal = mech.plane_normal
    return np.array([normal @ (d_alpha[i] + fr(f)[6][3:] @ da) for i, f in enumerate(frames)]).reshape(-1, n_par)


def _rows_now(sm, q: np.ndarray, v: np.ndarray, a: np.ndarray, frames: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """The acceleration rows A = J a + drift (rows,) and the frames' angular accelerations
    (F, 3) at (q, v, a) with the placements now in the model (a Data of its own)."""
    rows = closure_rows(sm.mechanism)
    if not hasattr(sm, "_acc_now"):
        sm._acc_now = sm.model.createData()
    model, data = sm.model, sm._acc_now
    pin.forwardKinematics(model, data, q, v, a)
    alphas = [pin.getFrameAcceleration(model, data, f, _LWA).angular for f in frames]
    return rows.jacobian(q) @ a + rows.drift(q, v), np.array(alphas).reshape(-1, 3)


def _cut_rows(cut, fr: _Frames, S, w, moved, carrier) -> np.ndarray:
    """dA/dp_k of one cut's acceleration rows at fixed a (the module's formula, in the
    core's `cut_rows_change`) from both frames' motions and their changes."""
    motion, change = [], []
    for f in (cut.parent_frame, cut.child_frame):
        x, R, v, om, acc, al = fr(f)[:6]
        dx, dth, dv, dw, dacc, dal = fr.change(f, S, w, moved(f), carrier)
        motion.append(np.vstack([x, v, om, acc, al, R]))
        change.append(np.vstack([dx, dv, dw, dacc, dal, dth]))
    return cut_rows_change(cut, 2, motion[0], motion[1], change[0], change[1])
