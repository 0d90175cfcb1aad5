"""A cut's closure frames, the closure rows that do not vanish identically, and the motion
plane of a planar mechanism: found once, on seeded sample configurations."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.model.closure_core import ClosureRows
from pinmech.model.closures import Closure
from pinmech.model.joint_info import _body_frame
from pinmech.model.urdf_xml import _Cut
from pinmech.seeded import Seeded

#: Singular values below this fraction of the largest mark a row as structurally zero.
STRUCTURAL_RANK_TOL = 1e-9
_SAMPLES = 4


def _make_closure(model: pin.Model, cut: _Cut) -> Closure:
    """The closure of a cut, with one frame added per side; its size is set by `_length_scale`."""
    frame_ids = []
    for side, link, origin in (("parent", cut.parent_link, cut.parent_origin), ("child", cut.child_link, cut.child_origin)):
        body_id = _body_frame(model, link)
        body = model.frames[body_id]
        frame = pin.Frame(f"{cut.name}__{side}", body.parentJoint, body_id, body.placement * origin,
                          pin.FrameType.OP_FRAME)
        frame_ids.append(model.addFrame(frame, False))
    return Closure(cut.name, cut.cut_type, frame_ids[0], frame_ids[1], cut.parent_axis, cut.child_axis,
                   parent_link=cut.parent_link, child_link=cut.child_link)



def _sample_configurations(model: pin.Model, count: int, scale: np.ndarray | float = 1.0) -> list[np.ndarray]:
    """Seeded random configurations: about a radian, or `scale` metres for a slide, from neutral."""
    rng = Seeded(20261122)
    q0 = pin.neutral(model)
    return [pin.integrate(model, q0, scale * rng.normal(size=model.nv)) for _ in range(count)]


def _reduce_rows(model: pin.Model, closures: list[Closure], columns: np.ndarray) -> None:
    """Give each closure a constant basis of the rows that do not vanish identically.

    `columns`: the mechanism's velocity scale (`Mechanism.velocity_scale`), so that rows and
    columns are dimensionless and the rank is the same at any size.
    """
    if not closures:
        return
    every = ClosureRows(model, closures, selected=True)
    jacobians = [every.jacobian(q) * columns for q in _sample_configurations(model, _SAMPLES, columns)]
    for rows, closure in zip(every.slices, closures):
        U, s, _ = np.linalg.svd(np.hstack([J[rows] for J in jacobians]), full_matrices=False)
        rank = int(np.sum(s > STRUCTURAL_RANK_TOL * max(s[0], 1e-300))) if s.size else 0
        closure.basis = _readable_basis(U[:, :rank])


def _readable_basis(U: np.ndarray) -> np.ndarray:
    """Rows of the identity when they span the same space as U's columns, else U^T.

    A planar revolute cut then keeps "x" and "y" rather than two mixed combinations,
    so its residual reads in the cut frame's own axes.
    """
    inside = np.linalg.norm(U.T, axis=0) > 1 - 1e-12  # identity rows lying in span(U)
    if int(inside.sum()) == U.shape[1]:
        return np.eye(U.shape[0])[inside]
    return U.T.copy()


def _plane_normal(model: pin.Model, columns: np.ndarray, length_scale: float) -> np.ndarray | None:
    """The common normal of a planar mechanism: every link turns about it, none moves along it.

    `columns`: the velocity scale, as in `_reduce_rows`; `length_scale`: the mechanism's size [m].
    """
    if model.nv == 0:
        return None
    data = model.createData()
    angular, linear = [], []
    for q in _sample_configurations(model, 3, columns):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for fid in range(model.nframes):
            J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            J = J.reshape(6, model.nv) * columns  # Pinocchio gives a 6 x 1 Jacobian as a vector
            angular.append(J[3:])
            linear.append(J[:3] / length_scale)
    # A = hstack(angular) is 3 x (frames * nv). A = R^T Q^T, so A's U and s are those of the
    # 3 x 3 R^T: same accuracy, and LAPACK's SVD of the wide A took 30 ms on a floating Talos.
    R = np.linalg.qr(np.hstack(angular).T, mode="r")
    U, s, _ = np.linalg.svd(R.T)
    if s[0] == 0 or (len(s) > 1 and s[1] > STRUCTURAL_RANK_TOL * s[0]):
        return None
    normal = U[:, 0] * np.sign(U[np.argmax(np.abs(U[:, 0])), 0])
    lin = np.hstack(linear)
    if np.linalg.norm(normal @ lin) > STRUCTURAL_RANK_TOL * max(np.linalg.norm(lin), 1e-300):
        return None
    return normal


def close_loops(mech: Any, closures: list[Closure]) -> None:
    """Give a Mechanism its closures, with their sizes, independent rows and the motion plane."""
    from pinmech.model.loop_size import _length_scale

    mech.closures = closures
    mech.length_scale = _length_scale(mech.model, closures, mech.source)
    _reduce_rows(mech.model, closures, mech.velocity_scale())
    mech.plane_normal = _plane_normal(mech.model, mech.velocity_scale(), mech.length_scale)
