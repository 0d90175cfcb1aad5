"""One loop cut: its closure residual, its constraint Jacobian rows and their drift.

A cut joins a frame on a parent link (P) to a frame on a child link (C). Everything is
written as the motion of C relative to P, expressed in P:

    r = R_P^T (p_C - p_P)                    relative position           [m]
    r_dot = R_P^T (v_C - v_P - w_P x (p_C - p_P))   relative velocity    [m/s]
    w = R_P^T (w_C - w_P)                    relative angular velocity   [rad/s]

and their time derivatives (classical accelerations of both frames). A cut type selects
rows of this 6-vector (linear first, then angular):

    spherical  3 rows: r = 0
    revolute   5 rows: r = 0, and w has no component across the joint axis
    prismatic  5 rows: w = 0, and r has no component across the joint axis
    fixed      6 rows: r = 0, w = 0

Because the selected directions are fixed in P, the same selection applies exactly at
the position, velocity and acceleration levels. Rows that vanish identically (a planar
loop has no out-of-plane motion to constrain) are removed by `mechanism.py`, which
hands each closure a constant row basis `T`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

CUT_TYPES = ("revolute", "prismatic", "spherical", "fixed")
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for 3-vectors; np.cross costs ~10 us per call, this ~1 us (hot path)."""
    return np.array((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))


def _perpendicular_basis(axis: np.ndarray) -> np.ndarray:
    """Two unit vectors (rows) spanning the plane normal to a unit `axis`."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    e1 = helper - axis * (axis @ helper)
    e1 /= np.linalg.norm(e1)
    return np.vstack([e1, np.cross(axis, e1)])


def selection_matrix(cut_type: str, axis: np.ndarray) -> np.ndarray:
    """Rows of the relative 6-vector (linear, angular) that a cut of this type constrains."""
    eye, zero = np.eye(3), np.zeros((3, 3))
    if cut_type == "spherical":
        return np.hstack([eye, zero])
    if cut_type == "fixed":
        return np.eye(6)
    across = _perpendicular_basis(axis)
    if cut_type == "revolute":
        return np.vstack([np.hstack([eye, zero]), np.hstack([np.zeros((2, 3)), across])])
    if cut_type == "prismatic":
        return np.vstack([np.hstack([across, np.zeros((2, 3))]), np.hstack([zero, eye])])
    raise ValueError(f"unknown cut type {cut_type!r}")


@dataclass
class Closure:
    """A loop cut between two frames of the Pinocchio model.

    Attributes:
        name: the `<constraint name=...>` of the URDF.
        cut_type: "revolute", "prismatic", "spherical" or "fixed".
        parent_frame: Pinocchio frame id of the cut frame P on the parent link.
        child_frame: Pinocchio frame id of the cut frame C on the child link.
        axis: joint axis in P (unit), for revolute and prismatic cuts.
        child_axis: joint axis in C (unit); equals `axis` once the loop is closed.
        basis: (k, n_sel) constant row basis of the independent rows (set by mechanism.py).
        length_scale: the loop's size [m] (mechanism.py): position rows are divided by it
            so rows are dimensionless, and the closure tolerance is relative to it.
        joints: ids of the Pinocchio joints on the loop (set by mechanism.py).
    """

    name: str
    cut_type: str
    parent_frame: int
    child_frame: int
    axis: np.ndarray
    child_axis: np.ndarray
    parent_link: str = ""
    child_link: str = ""
    basis: np.ndarray | None = None
    length_scale: float = 1.0
    joints: tuple[int, ...] = ()
    _select: np.ndarray = field(init=False, repr=False)
    _rows6: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        for name in ("axis", "child_axis"):  # own read-only copies: the rows are built from them
            axis = np.array(getattr(self, name), dtype=float)
            axis.flags.writeable = False
            super().__setattr__(name, axis)
        self._select = selection_matrix(self.cut_type, self.axis)
        self.basis = np.eye(self._select.shape[0]) if self.basis is None else self.basis  # sets _rows6

    def __setattr__(self, name: str, value: object) -> None:
        if self.__dict__.get("_in_use"):
            raise AttributeError(f"closure '{self.name}' is in use by a solver: its {name} cannot change "
                                 "(the solver's rows are built from it); load the mechanism again instead")
        super().__setattr__(name, value)
        if name in ("basis", "length_scale") and hasattr(self, "_select") and self.basis is not None:
            # basis @ selection @ diag(scale), once: the map from a relative 6-vector to rows
            super().__setattr__("_rows6", self.basis @ self._select @ np.diag(self._scale()))

    @property
    def rows(self) -> int:
        """Number of independent constraint rows this cut contributes."""
        return int(self.basis.shape[0])

    @property
    def selected(self) -> np.ndarray:
        """(n_sel, 6) selection of the relative motion 6-vector, before reduction."""
        return self._select

    def _scale(self) -> np.ndarray:
        return np.concatenate((np.full(3, 1.0 / self.length_scale), np.ones(3)))

    def residual6(self, data: pin.Data) -> np.ndarray:
        """Relative pose error as a 6-vector in P (position [m], orientation [rad]).

        Needs frame placements up to date (`pin.updateFramePlacements`).
        """
        M_P, M_C = data.oMf[self.parent_frame], data.oMf[self.child_frame]
        R_rel = M_P.rotation.T @ M_C.rotation
        linear = M_P.rotation.T @ (M_C.translation - M_P.translation)
        if self.cut_type == "revolute":
            angular = _cross(self.axis, R_rel @ self.child_axis)
        elif self.cut_type == "spherical":
            angular = np.zeros(3)
        else:
            angular = pin.log3(R_rel)
        return np.concatenate((linear, angular))

    def full_residual(self, data: pin.Data) -> np.ndarray:
        """All selected rows of the scaled pose error, reduced or not (dimensionless)."""
        return self._select @ (self._scale() * self.residual6(data))

    def residual(self, data: pin.Data) -> np.ndarray:
        """Independent rows of the scaled pose error (dimensionless)."""
        return self._rows6 @ self.residual6(data)

    def relative_jacobian6(self, model: pin.Model, data: pin.Data) -> np.ndarray:
        """(6, nv) map from joint velocities to (r_dot, w) in P.

        Needs `pin.computeJointJacobians` and `pin.updateFramePlacements` at q.
        """
        M_P, M_C = data.oMf[self.parent_frame], data.oMf[self.child_frame]
        # (6, nv) even for a one-dof model, where Pinocchio returns a (6,) vector
        J_P = pin.getFrameJacobian(model, data, self.parent_frame, _LWA).reshape(6, -1)
        J_C = pin.getFrameJacobian(model, data, self.child_frame, _LWA).reshape(6, -1)
        delta = M_C.translation - M_P.translation
        R_T = M_P.rotation.T
        linear = R_T @ (J_C[:3] - J_P[:3] + pin.skew(delta) @ J_P[3:])
        angular = R_T @ (J_C[3:] - J_P[3:])
        return np.vstack([linear, angular])

    def residual_jacobian(self, model: pin.Model, data: pin.Data) -> np.ndarray:
        """(rows, nv) exact derivative of `residual` at any q, closed or not (for Newton).

        Position rows are those of `jacobian`; orientation rows carry the derivative of
        their error measure (a_P x R a_C, or log3 R), which equals the velocity rows only
        once the loop is closed.
        """
        J6 = self.relative_jacobian6(model, data)
        if self.cut_type != "spherical":
            M_P, M_C = data.oMf[self.parent_frame], data.oMf[self.child_frame]
            R_rel = M_P.rotation.T @ M_C.rotation
            if self.cut_type == "revolute":
                J6[3:] = -pin.skew(self.axis) @ pin.skew(R_rel @ self.child_axis) @ J6[3:]
            else:
                J6[3:] = pin.Jlog3(R_rel) @ R_rel.T @ J6[3:]
        return self._rows6 @ J6

    def jacobian(self, model: pin.Model, data: pin.Data) -> np.ndarray:
        """(rows, nv) constraint Jacobian of the independent rows (dimensionless rows)."""
        return self._rows6 @ self.relative_jacobian6(model, data)

    def drift(self, model: pin.Model, data: pin.Data) -> np.ndarray:
        """Constraint acceleration at zero joint acceleration, d/dt(J) q_dot (rows,).

        Needs `pin.forwardKinematics(model, data, q, v, 0)` and frame placements.
        """
        M_P, M_C = data.oMf[self.parent_frame], data.oMf[self.child_frame]
        v_P = pin.getFrameVelocity(model, data, self.parent_frame, _LWA)
        v_C = pin.getFrameVelocity(model, data, self.child_frame, _LWA)
        a_P = pin.getFrameClassicalAcceleration(model, data, self.parent_frame, _LWA)
        a_C = pin.getFrameClassicalAcceleration(model, data, self.child_frame, _LWA)
        w_P, w_C = v_P.angular, v_C.angular
        delta = M_C.translation - M_P.translation
        d = v_C.linear - v_P.linear - _cross(w_P, delta)
        d_dot = a_C.linear - a_P.linear - _cross(a_P.angular, delta) - _cross(w_P, v_C.linear - v_P.linear)
        R_T = M_P.rotation.T
        linear = R_T @ (d_dot - _cross(w_P, d))
        angular = R_T @ (a_C.angular - a_P.angular - _cross(w_P, w_C - w_P))
        return self._rows6 @ np.concatenate((linear, angular))


class CutEvaluator:
    """The hot path of one closure: the numbers of `Closure.residual`, `jacobian`,
    `residual_jacobian`, `full_residual` and `drift`, with few numpy calls per pose.

    A solver evaluates these at every pose, where a numpy call costs about a microsecond
    and a Pinocchio call a quarter of one, so the products of the constant selection,
    basis and scale matrices with the parent frame's rotation are taken once per pose
    (`place`), and a cut frame on the ground (constant placement, no Jacobian) turns the
    rows into one constant matrix times the other frame's Jacobian.

    Order of calls at a pose: `place` after `pin.computeJointJacobians(q)`; then any of
    `residual`, `full_residual`, `jacobian`, `newton_jacobian`; and after
    `pin.forwardKinematics(q, v, 0)`, `drift`. tests/test_closures.py checks every number
    against `Closure`'s own methods.
    """

    def __init__(self, closure: Closure, model: pin.Model) -> None:
        closure.__dict__["_in_use"] = True  # what the rows below are built from stays as it is
        self.closure = closure
        self.model = model
        rows6 = closure._rows6
        self.rows = rows6.shape[0]
        self._K3 = rows6.reshape(self.rows, 2, 3)  # per row: (linear, angular) halves
        self._has_angular = bool(np.any(rows6[:, 3:]))
        full = closure.selected * closure._scale()  # all selected rows, scaled
        self._full_lin, self._full_ang = full[:, :3].copy(), full[:, 3:].copy()
        self._revolute = closure.cut_type == "revolute"
        self._ang_axis = self._full_axis = None
        if self._revolute:  # rows of axis x (.), as matrices: K_ang skew(axis)
            self._ang_axis = rows6[:, 3:] @ pin.skew(closure.axis)
            self._full_axis = self._full_ang @ pin.skew(closure.axis)
        self._ground = model.frames[closure.parent_frame].parentJoint == 0
        if self._ground:  # a frame on the universe joint: its placement is the world one
            self._row_mats = (self._full_lin, self._ang_axis, self._full_axis)
            self._fold(model.frames[closure.parent_frame].placement.copy())

    def _fold(self, M_P: pin.SE3) -> None:
        """A ground cut frame's placement folded into the row matrices (R_P^T once)."""
        self._M_ground = M_P
        self._set_parent(M_P.rotation.copy(), M_P.translation.copy())
        full_lin, ang_axis, full_axis = self._row_mats
        self._full_lin = full_lin @ M_P.rotation.T
        if self._revolute:
            self._ang_axis = ang_axis @ M_P.rotation.T
            self._full_axis = full_axis @ M_P.rotation.T

    def refresh(self) -> bool:
        """Fold a ground cut frame's placement again if the model's frame was moved since
        (nothing is cached that the model can change); True when it was. Solvers call it
        once per call of their public methods (under a microsecond), not per pose."""
        if not self._ground:
            return False
        placement = self.model.frames[self.closure.parent_frame].placement  # by index: frames may be added
        if placement == self._M_ground:
            return False
        self._fold(placement.copy())
        return True

    def _set_parent(self, R_P: np.ndarray, p_P: np.ndarray) -> None:
        self._R_P, self._p_P = R_P, p_P
        self._W = (self._K3 @ R_P.T).reshape(self.rows, 6)  # rows6 @ diag(R_P^T, R_P^T)
        self._W_lin = self._W[:, :3]

    def place(self, data: pin.Data) -> None:
        """Read the cut frames' placements (needs joint placements at q)."""
        c = self.closure
        self._M_C = pin.updateFramePlacement(self.model, data, c.child_frame)
        if self._ground:
            if self._has_angular:  # Closure.residual_jacobian reads data.oMf of both frames
                pin.updateFramePlacement(self.model, data, c.parent_frame)
        else:
            self._M_P = pin.updateFramePlacement(self.model, data, c.parent_frame)
            self._set_parent(self._M_P.rotation, self._M_P.translation)
        self._delta = self._M_C.translation - self._p_P

    def _in_parent(self, x: np.ndarray) -> np.ndarray:
        """R_P^T x, except on the ground, where R_P^T is folded into the row matrices."""
        return x if self._ground else x @ self._R_P

    def _angular(self, rows_axis: np.ndarray, rows_ang: np.ndarray) -> np.ndarray:
        """Orientation error of `Closure.residual6`, mapped by the rows' angular half:
        axis x (R_rel child_axis) for a revolute cut, log3(R_rel) for prismatic and fixed."""
        if self._revolute:
            return rows_axis @ self._in_parent(self._M_C.rotation @ self.closure.child_axis)
        return rows_ang @ pin.log3(self._R_P.T @ self._M_C.rotation)

    def residual(self) -> np.ndarray:
        """Independent rows of the scaled pose error (dimensionless)."""
        r = self._W_lin @ self._delta
        if self._has_angular:
            r += self._angular(self._ang_axis, self._K3[:, 1])
        return r

    def full_residual(self) -> float:
        """Largest error over all selected rows, the reduced-away ones included."""
        full = self._full_lin @ self._in_parent(self._delta)
        if self.closure.cut_type != "spherical":
            full += self._angular(self._full_axis, self._full_ang)
        return max(map(abs, full.tolist()), default=0.0)

    def jacobian(self, data: pin.Data) -> np.ndarray:
        """(rows, nv) constraint Jacobian (needs `pin.computeJointJacobians` at q)."""
        c = self.closure
        J_C = pin.getFrameJacobian(self.model, data, c.child_frame, _LWA)
        if self._ground:
            return self._W @ J_C
        J_P = pin.getFrameJacobian(self.model, data, c.parent_frame, _LWA)
        J = self._W @ (J_C - J_P)
        J += (self._W_lin @ pin.skew(self._delta)) @ J_P[3:]
        return J

    def newton_jacobian(self, data: pin.Data) -> np.ndarray:
        """Exact derivative of `residual` (orientation rows differ from `jacobian` off closure)."""
        if self._has_angular:
            return self.closure.residual_jacobian(self.model, data)
        return self.jacobian(data)

    def drift(self, data: pin.Data) -> np.ndarray:
        """d/dt(J) q_dot (needs `pin.forwardKinematics(q, v, 0)`, and `place` at q)."""
        c, model = self.closure, self.model
        a_C = pin.getFrameClassicalAcceleration(model, data, c.child_frame, _LWA)
        if self._ground:
            return self._W @ a_C.vector
        v_P = pin.getFrameVelocity(model, data, c.parent_frame, _LWA)
        v_C = pin.getFrameVelocity(model, data, c.child_frame, _LWA)
        a_P = pin.getFrameClassicalAcceleration(model, data, c.parent_frame, _LWA)
        w_P, delta = v_P.angular, self._delta
        dv = v_C.linear - v_P.linear
        d = dv - _cross(w_P, delta)
        d_dot = a_C.linear - a_P.linear - _cross(a_P.angular, delta) - _cross(w_P, dv)
        angular = a_C.angular - a_P.angular - _cross(w_P, v_C.angular - w_P)
        return self._W_lin @ (d_dot - _cross(w_P, d)) + self._W[:, 3:] @ angular
