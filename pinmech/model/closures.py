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
