"""One loop cut, as a description: its frames, type, axes and the basis of its rows.

A cut joins a frame on a parent link (P) to a frame on a child link (C). Its rows are
written on the motion of C relative to P, expressed in P (linear first, then angular):

    r = R_P^T (p_C - p_P)                    relative position           [m]
    r_dot = R_P^T (v_C - v_P - w_P x (p_C - p_P))   relative velocity    [m/s]
    w = R_P^T (w_C - w_P)                    relative angular velocity   [rad/s]

and their time derivatives. A cut type selects rows of this 6-vector:

    spherical  3 rows: r = 0
    revolute   5 rows: r = 0, and w has no component across the joint axis
    prismatic  5 rows: w = 0, and r has no component across the joint axis
    fixed      6 rows: r = 0, w = 0

Because the selected directions are fixed in P, the same selection applies exactly at
the position, velocity and acceleration levels. Rows that vanish identically (a planar
loop has no out-of-plane motion to constrain) are removed by closure_rows.py, which hands
each closure a constant row basis `T`. The rows themselves are evaluated in one place,
pinmech's compiled core (closure_core.py): this module holds the description only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

CUT_TYPES = ("revolute", "prismatic", "spherical", "fixed")


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

    @property
    def rows6(self) -> np.ndarray:
        """(rows, 6) basis @ selection @ diag(scale): the map from the relative 6-vector
        (position over the loop's size, orientation) to the independent rows."""
        return self._rows6

    @property
    def selected_rows6(self) -> np.ndarray:
        """(n_sel, 6) selection @ diag(scale): every selected row, before the basis."""
        return self._select * self._scale()

    def _scale(self) -> np.ndarray:
        return np.concatenate((np.full(3, 1.0 / self.length_scale), np.ones(3)))
