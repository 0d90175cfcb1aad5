"""Exact first-order sensitivities of speeds to the parameters: the implicit-function
theorem on the velocity closure equations, after the configuration's (sensitivity.py).

Each cut's velocity rows are G = rows6 [R_P^T (v_C - v_P - w_P x delta); R_P^T (w_C - w_P)]
(the compiled core's closure Jacobian times v), zero on every variant with the drivers' speeds
held. Along a parameter p_k the pose moves by S_k = dq/dp_k and the frames it carries
translate by u (params.Placement); with v held,

    dG/dp_k = rows6 [R_P^T (da - w'_P x a); R_P^T (db - w'_P x b)],   a, b: the brackets above
    da = dv_C - dv_P - dw_P x delta - w_P x d(delta),   d(delta) = (J_C - J_P)_lin S_k + u_C - u_P
    dv_X = (dv_X/dq) S_k + w_body x u_X                  (the frame carried by its body's motion)
    dw_X = (dw_X/dq) S_k,   w'_P = (J_P)_ang S_k          (a translation turns nothing)

with (dv_X/dq) S from the world Jacobian's time variation at q_dot = S (_FrameRates). Then
C_dep dv_dep/dp_k = -dG/dp_k (the driver's speed held), and an output's speed derivative
follows: a slider's ds_dot/dp = dv/dp at its index; a link's d(omega)/dp =
n . ((dw_f/dq) S_k + J_f,ang dv/dp_k).

A drawn linkage's param (drawn_params.py) moves no frame by a translation u; it changes
the placements themselves, so dG/dp_k and each frame's velocity at fixed q and v gain the
drawing's own change, the central differences of J(q) v over the drawings at p +- STEP.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.directions import cross as _cross
from pinmech.model.closure_core import closure_rows, cut_rows_change

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class _FrameRates:
    """Frames' world-aligned velocities at (q, v) and their change along a pose change S.

    d(velocity)/dS comes from the world (spatial) Jacobian's time variation at q_dot = S,
    which is the exact derivative of its columns (each joint's spatial axis moved by its
    parent's motion): dV_s = dJ_s v; the velocity of the frame's origin x is then
    d(v_s + w x x) = dv_s + dw x x + w x dx, dx = J_x,lin S.
    """

    def __init__(self, model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> None:
        self.model, self.data, self.q, self.v = model, data, q, v
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        self._at = {}  # frame -> (velocity (6,), Jacobian (6, nv)), world-aligned at the origin
        self._S = None

    def __call__(self, frame: int) -> tuple[np.ndarray, np.ndarray]:
        """(velocity (6,) [linear; angular], Jacobian (6, nv)), world-aligned axes."""
        if frame not in self._at:
            J = pin.getFrameJacobian(self.model, self.data, frame, _LWA).reshape(6, -1)
            self._at[frame] = (J @ self.v, J)
        return self._at[frame]

    def joint_omega(self, joint: int) -> np.ndarray:
        """World angular velocity [rad/s] of a joint's body."""
        return pin.getJointJacobian(self.model, self.data, joint, pin.WORLD).reshape(6, -1)[3:] @ self.v

    def along(self, S: np.ndarray) -> None:
        """Set the pose change S (nv,) that `change` differentiates along."""
        for frame in list(self._at):
            self(frame)
        pin.computeJointJacobiansTimeVariation(self.model, self.data, self.q, S)
        self._S = S

    def change(self, frame: int) -> np.ndarray:
        """d(velocity)/dS (6,) of a frame at fixed v, along the S of `along`."""
        V, J = self(frame)
        dVs = pin.getFrameJacobianTimeVariation(self.model, self.data, frame, pin.WORLD).reshape(6, -1) @ self.v
        x = self.data.oMf[frame].translation
        dv = dVs[:3] + _cross(dVs[3:], x) + _cross(V[3:], J[:3] @ self._S)
        return np.concatenate((dv, dVs[3:]))


def velocity_sensitivity(sm, q: np.ndarray, v: np.ndarray, dq_dp: np.ndarray,
                         frames: list[int] = ()) -> tuple[np.ndarray, np.ndarray]:
    """dv/dp (nv, n_par) at the closed pose q with joint velocities v [per s / m], the
    drivers' speeds held; and d(velocity)/dp at fixed v of `frames` along each dq/dp_k
    (len(frames), 6, n_par), for the outputs."""
    model, mech, solver = sm.model, sm.mechanism, sm.solver
    data = sm.data
    rates = _FrameRates(model, data, q, v)
    driven = {mech.driver_index(n) for n in solver.drivers}
    dep = [i for i in range(model.nv) if i not in driven]
    J = closure_rows(mech).jacobian(q)
    carried = [rates.joint_omega(_written_in(sm, place)) for place in sm.placements]
    n_par = len(sm.placements)
    dG, dV = np.zeros((len(J), n_par)), np.zeros((len(frames), 6, n_par))
    for k, place in enumerate(sm.placements):
        u = place.direction(data)
        rates.along(dq_dp[:, k])
        dG[:, k] = np.concatenate([_cut_rows(sm, c, rates, dq_dp[:, k], place, u, carried[k])
                                   for c in mech.closures])
        for i, f in enumerate(frames):
            dV[i, :, k] = rates.change(f)
        if place.drawn:  # the drawing's own change at fixed q and v: its central differences
            dG[:, k] += place.column(lambda: _jacobians(sm, q, None) @ v)
            for i, f in enumerate(frames):
                dV[i, :, k] += place.column(lambda f=f: _jacobians(sm, q, f) @ v)
    dv = np.zeros((model.nv, n_par))
    dv[dep] = -np.linalg.solve(J[:, dep], dG)
    return dv, dV


def link_omega_sensitivity(sm, frame: int, normal: np.ndarray, dV: np.ndarray, dv_dp: np.ndarray) -> np.ndarray:
    """d(omega)/dp (n_par,) of a link frame's angular speed about the plane normal [rad/s/m]:
    its change at fixed v (dV (6, n_par)) plus J_ang dv/dp."""
    J = pin.getFrameJacobian(sm.model, sm.data, frame, _LWA).reshape(6, -1)
    return normal @ (dV[3:] + J[3:] @ dv_dp)


def _jacobians(sm, q: np.ndarray, frame: int | None) -> np.ndarray:
    """The closure's velocity rows (frame None) or a frame's world-aligned Jacobian (6, nv)
    at q with the placements now in the model (a Data of its own)."""
    if not hasattr(sm, "_fd_data"):
        sm._fd_data = sm.model.createData()
    data = sm._fd_data
    pin.computeJointJacobians(sm.model, data, q)
    pin.updateFramePlacements(sm.model, data)
    if frame is None:
        return closure_rows(sm.mechanism).jacobian(q)
    return pin.getFrameJacobian(sm.model, data, frame, _LWA).reshape(6, -1)


def _cut_rows(sm, cut, rates: _FrameRates, S: np.ndarray, place, u: np.ndarray, moved: np.ndarray) -> np.ndarray:
    """dG/dp_k of one cut's velocity rows at fixed v (the module's formula, in the core's
    `cut_rows_change`): each frame moves by dx = J_lin S + u, its velocity by the change at
    fixed v plus moved x u, turns by J_ang S; u: the world direction the parameter moves
    what it moves, `moved`: the carrying body's angular velocity."""
    motion, change = [], []
    for frame in (cut.parent_frame, cut.child_frame):
        M, (V, J) = sm.data.oMf[frame], rates(frame)
        u_f = u if place.moves_frame(frame, sm.subtree) else np.zeros(3)
        dV = rates.change(frame)
        motion.append(np.vstack([M.translation, V[:3], V[3:], np.zeros((2, 3)), M.rotation]))
        change.append(np.vstack([J[:3] @ S + u_f, dV[:3] + _cross(moved, u_f), dV[3:], np.zeros((2, 3)), J[3:] @ S]))
    return cut_rows_change(cut, 1, motion[0], motion[1], change[0], change[1])


def _written_in(sm, place) -> int:
    """The joint whose body carries what a parameter moves (the parent joint for a joint
    origin, the frame's joint for a cut frame)."""
    return place.written_in
