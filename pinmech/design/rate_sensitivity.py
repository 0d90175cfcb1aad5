"""Exact first-order sensitivities of speeds to the parameters: the implicit-function
theorem on the velocity closure equations, after the configuration's (sensitivity.py).

Each cut's velocity rows are G = rows6 [R_P^T (v_C - v_P - w_P x delta); R_P^T (w_C - w_P)]
(`Closure.relative_jacobian6` times v), zero on every variant with the drivers' speeds
held. Along a parameter p_k the pose moves by S_k = dq/dp_k and the frames it carries
translate by u (study_params.Placement); with v held,

    dG/dp_k = rows6 [R_P^T (da - w'_P x a); R_P^T (db - w'_P x b)],   a, b: the brackets above
    da = dv_C - dv_P - dw_P x delta - w_P x d(delta),   d(delta) = (J_C - J_P)_lin S_k + u_C - u_P
    dv_X = (dv_X/dq) S_k + w_body x u_X                  (the frame carried by its body's motion)
    dw_X = (dw_X/dq) S_k,   w'_P = (J_P)_ang S_k          (a translation turns nothing)

with dv_X/dq from Pinocchio's `getFrameVelocityDerivatives` (world-aligned axes). Then
C_dep dv_dep/dp_k = -dG/dp_k (the driver's speed held), and an output's speed derivative
follows: a slider's ds_dot/dp = dv/dp at its index; a link's d(omega)/dp =
n . ((dw_f/dq) S_k + J_f,ang dv/dp_k).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.model.closures import _cross

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class _FrameRates:
    """World-aligned velocity, its q-derivative and Jacobian of frames at (q, v), cached."""

    def __init__(self, model: pin.Model, data: pin.Data) -> None:
        self.model, self.data, self._seen = model, data, {}

    def __call__(self, frame: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(velocity (6,) [linear; angular], d velocity / dq (6, nv), Jacobian (6, nv))."""
        if frame not in self._seen:
            model, data = self.model, self.data
            dv_dq, J = pin.getFrameVelocityDerivatives(model, data, frame, _LWA)
            self._seen[frame] = (pin.getFrameVelocity(model, data, frame, _LWA).vector,
                                 np.asarray(dv_dq).reshape(6, -1), np.asarray(J).reshape(6, -1))
        return self._seen[frame]


def velocity_sensitivity(sm, q: np.ndarray, v: np.ndarray, dq_dp: np.ndarray) -> tuple[np.ndarray, _FrameRates]:
    """dv/dp (nv, n_par) at the closed pose q with joint velocities v [per s / m], the
    drivers' speeds held; and the frames' rates at (q, v) for the outputs."""
    model, mech, solver = sm.model, sm.mechanism, sm.solver
    data = sm.data
    pin.computeForwardKinematicsDerivatives(model, data, q, v, np.zeros(model.nv))
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    rates = _FrameRates(model, data)
    driven = {mech.driver_index(n) for n in solver.drivers}
    dep = [i for i in range(model.nv) if i not in driven]
    J = np.vstack([c.jacobian(model, data) for c in mech.closures])
    dG = np.column_stack([np.concatenate([_cut_rows(sm, c, rates, dq_dp[:, k], place)
                                          for c in mech.closures]) for k, place in enumerate(sm.placements)])
    dv = np.zeros((model.nv, len(sm.placements)))
    dv[dep] = -np.linalg.solve(J[:, dep], dG.reshape(len(J), -1))
    return dv, rates


def link_omega_sensitivity(rates: _FrameRates, frame: int, normal: np.ndarray, dq_dp: np.ndarray,
                           dv_dp: np.ndarray) -> np.ndarray:
    """d(omega)/dp (n_par,) of a link frame's angular speed about the plane normal [rad/s/m]."""
    _, dV_dq, J = rates(frame)
    return normal @ (dV_dq[3:] @ dq_dp + J[3:] @ dv_dp)


def _cut_rows(sm, cut, rates: _FrameRates, S: np.ndarray, place) -> np.ndarray:
    """dG/dp_k of one cut's velocity rows at fixed v (the module's formula)."""
    data = sm.data
    u = place.direction(data)
    moved = _carried(sm, place, data)
    M_P, M_C = data.oMf[cut.parent_frame], data.oMf[cut.child_frame]
    (V_P, dVP, JP), (V_C, dVC, JC) = rates(cut.parent_frame), rates(cut.child_frame)
    u_P = u if place.moves_frame(cut.parent_frame, sm.subtree) else np.zeros(3)
    u_C = u if place.moves_frame(cut.child_frame, sm.subtree) else np.zeros(3)
    w_P, delta = V_P[3:], M_C.translation - M_P.translation
    a = V_C[:3] - V_P[:3] - _cross(w_P, delta)
    b = V_C[3:] - w_P
    dV_P, dV_C = dVP @ S, dVC @ S
    dv_P = dV_P[:3] + (_cross(moved, u_P) if u_P.any() else 0.0)
    dv_C = dV_C[:3] + (_cross(moved, u_C) if u_C.any() else 0.0)
    d_delta = (JC[:3] - JP[:3]) @ S + u_C - u_P
    da = dv_C - dv_P - _cross(dV_P[3:], delta) - _cross(w_P, d_delta)
    db = dV_C[3:] - dV_P[3:]
    turn = JP[3:] @ S
    R_T = M_P.rotation.T
    return cut._rows6 @ np.concatenate((R_T @ (da - _cross(turn, a)), R_T @ (db - _cross(turn, b))))


def _carried(sm, place, data: pin.Data) -> np.ndarray:
    """World angular velocity [rad/s] of the body a parameter's placement is written in (the
    parent joint's for a joint origin, the frame's joint for a cut frame)."""
    written_in = sm.model.parents[place.joint] if place.frame < 0 else place.joint
    return data.oMi[written_in].rotation @ data.v[written_in].angular
