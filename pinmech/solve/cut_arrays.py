"""One closure's rows for many poses at once: the batched twin of `CutEvaluator`.

`BatchSolver` (solve_batch.py) calls Pinocchio pose by pose and has each cut store what
it needs of the results: `read_positions` after `pin.computeJointJacobians(q)`, and
`read_rates` after `pin.forwardKinematics(q, v, 0)`. The rows (residual, Jacobian, drift)
are then computed for all the poses at once.

`ArrayCut` (cuts whose independent rows are positions only: planar revolute cuts,
spherical cuts) stores raw frame quantities and applies `CutEvaluator`'s formulas to
stacks; `RowCut` (orientation rows: prismatic, fixed, spatial revolute cuts) evaluates
`CutEvaluator` pose by pose and stacks its rows.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.model.closures import CutEvaluator

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _skew(x: np.ndarray) -> np.ndarray:
    """(N, 3, 3) cross-product matrices of (N, 3) vectors."""
    S = np.zeros((len(x), 3, 3))
    S[:, 0, 1], S[:, 0, 2], S[:, 1, 2] = -x[:, 2], x[:, 1], -x[:, 0]
    S[:, 1, 0], S[:, 2, 0], S[:, 2, 1] = x[:, 2], -x[:, 1], x[:, 0]
    return S


class ArrayCut:
    """A cut with position rows only: frame quantities stored per pose, rows on arrays.

    The formulas are those of `CutEvaluator` (and `Closure`), written for stacks.
    """

    def __init__(self, ev: CutEvaluator) -> None:
        self.ev = ev
        self.model = ev.model
        self.fP, self.fC = ev.closure.parent_frame, ev.closure.child_frame
        self.ground = ev._ground
        self.revolute = ev._revolute

    def allocate(self, n: int, nv: int) -> None:
        self.H_C, self.J_C, self.a_C = np.empty((n, 4, 4)), np.empty((n, 6, nv)), np.empty((n, 6))
        if not self.ground:
            self.H_P, self.J_P = np.empty((n, 4, 4)), np.empty((n, 6, nv))
            self.v_P, self.v_C, self.a_P = np.empty((n, 6)), np.empty((n, 6)), np.empty((n, 6))

    # placements as 4x4 matrices: one read and one store each (half the cost of R and p)
    p_C = property(lambda self: self.H_C[:, :3, 3])
    R_C = property(lambda self: self.H_C[:, :3, :3])
    p_P = property(lambda self: self.H_P[:, :3, 3])
    R_P = property(lambda self: self.H_P[:, :3, :3])

    def read_positions(self, data: pin.Data, i: int) -> None:
        model = self.model
        self.H_C[i] = pin.updateFramePlacement(model, data, self.fC).homogeneous
        self.J_C[i] = pin.getFrameJacobian(model, data, self.fC, _LWA)
        if not self.ground:
            self.H_P[i] = pin.updateFramePlacement(model, data, self.fP).homogeneous
            self.J_P[i] = pin.getFrameJacobian(model, data, self.fP, _LWA)

    def read_rates(self, data: pin.Data, i: int) -> None:
        model = self.model
        self.a_C[i] = pin.getFrameClassicalAcceleration(model, data, self.fC, _LWA).vector
        if not self.ground:
            self.v_P[i] = pin.getFrameVelocity(model, data, self.fP, _LWA).vector
            self.v_C[i] = pin.getFrameVelocity(model, data, self.fC, _LWA).vector
            self.a_P[i] = pin.getFrameClassicalAcceleration(model, data, self.fP, _LWA).vector

    # -- rows (formulas of CutEvaluator, on stacks)
    def _delta(self) -> np.ndarray:
        return self.p_C - (self.ev._p_P if self.ground else self.p_P)

    def _in_parent(self, x: np.ndarray) -> np.ndarray:
        """R_P^T x per pose (on the ground R_P^T is already in the row matrices)."""
        return x if self.ground else np.einsum("nji,nj->ni", self.R_P, x)

    def _W(self) -> np.ndarray:
        """(N, rows, 6): rows6 diag(R_P^T, R_P^T) per pose (one matrix on the ground)."""
        if self.ground:
            return self.ev._W[None]
        R_T = np.swapaxes(self.R_P, 1, 2)[:, None]
        return (self.ev._K3[None] @ R_T).reshape(len(self.R_P), self.ev.rows, 6)

    def residual(self) -> np.ndarray:
        if self.ground:
            return self._delta() @ self.ev._W_lin.T
        return self._in_parent(self._delta()) @ self.ev._K3[:, 0].T

    def full_residual(self) -> np.ndarray:
        full = self._in_parent(self._delta()) @ self.ev._full_lin.T
        if self.revolute:
            full += self._in_parent(self.R_C @ self.ev.closure.child_axis) @ self.ev._full_axis.T
        return np.abs(full).max(axis=1, initial=0.0)

    def jacobian(self) -> np.ndarray:
        W = self._W()
        if self.ground:
            return W @ self.J_C
        J = W @ (self.J_C - self.J_P)
        J += (W[:, :, :3] @ _skew(self._delta())) @ self.J_P[:, 3:]
        return J

    newton_jacobian = jacobian  # exact for position rows

    def drift(self) -> np.ndarray:
        W = self._W()
        if self.ground:
            return self.a_C @ self.ev._W.T
        w_P, delta = self.v_P[:, 3:], self._delta()
        dv = self.v_C[:, :3] - self.v_P[:, :3]
        d = dv - np.cross(w_P, delta)
        d_dot = self.a_C[:, :3] - self.a_P[:, :3] - np.cross(self.a_P[:, 3:], delta) - np.cross(w_P, dv)
        angular = self.a_C[:, 3:] - self.a_P[:, 3:] - np.cross(w_P, self.v_C[:, 3:] - w_P)
        return (np.einsum("nkj,nj->nk", W[:, :, :3], d_dot - np.cross(w_P, d))
                + np.einsum("nkj,nj->nk", W[:, :, 3:], angular))


class RowCut:
    """A cut with orientation rows: `CutEvaluator` per pose, rows stored."""

    def __init__(self, ev: CutEvaluator) -> None:
        self.ev = ev

    def allocate(self, n: int, nv: int) -> None:
        k = self.ev.rows
        self._r, self._full = np.empty((n, k)), np.empty(n)
        self._J, self._Jn, self._drift = np.empty((n, k, nv)), np.empty((n, k, nv)), np.empty((n, k))

    def read_positions(self, data: pin.Data, i: int) -> None:
        ev = self.ev
        ev.place(data)
        self._r[i], self._full[i] = ev.residual(), ev.full_residual()
        self._J[i], self._Jn[i] = ev.jacobian(data), ev.newton_jacobian(data)

    def read_rates(self, data: pin.Data, i: int) -> None:
        self.ev.place(data)
        self._drift[i] = self.ev.drift(data)

    def residual(self) -> np.ndarray:
        return self._r

    def full_residual(self) -> np.ndarray:
        return self._full

    def jacobian(self) -> np.ndarray:
        return self._J

    def newton_jacobian(self) -> np.ndarray:
        return self._Jn

    def drift(self) -> np.ndarray:
        return self._drift
