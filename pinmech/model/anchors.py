"""Pinocchio constraint models (point and frame anchors, RigidConstraintModel) -> loop cuts.

A point anchor joins two points (a ball joint: pinmech's spherical cut), a frame anchor two
frames (a weld: a fixed cut). Each side is a joint and a placement on it; pinmech adds one
frame per side to the model and closes the loop between them, as it does for a URDF's
`<constraint>`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.model.closures import Closure
from pinmech.exceptions import ModelError
from pinmech.model.frame_names import reduced_model


@dataclass(frozen=True)
class AnchorCut:
    """A loop cut given by two joints and a placement on each (Pinocchio's constraint models)."""

    name: str
    cut_type: str
    joint1: int
    placement1: pin.SE3
    joint2: int
    placement2: pin.SE3


_ANCHOR_TYPES = {"PointAnchorConstraintModel": "spherical", "FrameAnchorConstraintModel": "fixed"}


def anchor_cut(constraint: Any, index: int, names: Sequence[str] | None, model: pin.Model, source: str) -> AnchorCut:
    kind = type(constraint).__name__
    if kind == "RigidConstraintModel":
        cut_type = {pin.ContactType.CONTACT_3D: "spherical", pin.ContactType.CONTACT_6D: "fixed"}.get(constraint.type)
    else:
        cut_type = _ANCHOR_TYPES.get(kind)
    if cut_type is None:
        raise ModelError(f"constraint {index + 1} is a {kind} ({getattr(constraint, 'type', '')}); pinmech closes "
                         "loops with point anchors (3D), frame anchors (6D) or RigidConstraintModel of type "
                         "CONTACT_3D or CONTACT_6D", path=source)
    own = str(getattr(constraint, "name", "") or "")
    name = names[index] if names is not None else own or f"loop{index + 1}"
    for jid in (constraint.joint1_id, constraint.joint2_id):
        if not 0 <= jid < model.njoints:
            raise ModelError(f"constraint '{name}' names joint id {jid}; the model has {model.njoints}", path=source)
    return AnchorCut(name, cut_type, int(constraint.joint1_id), pin.SE3(constraint.joint1_placement),
                      int(constraint.joint2_id), pin.SE3(constraint.joint2_placement))


def anchor_closure(model: pin.Model, cut: AnchorCut, length_scale: float) -> Closure:
    frame_ids, links = [], []
    for side, joint, placement in (("parent", cut.joint1, cut.placement1), ("child", cut.joint2, cut.placement2)):
        body = next((i for i, f in enumerate(model.frames) if f.parentJoint == joint
                     and f.type in (pin.FrameType.BODY, pin.FrameType.FIXED_JOINT)), 0)
        frame_ids.append(model.addFrame(pin.Frame(f"{cut.name}__{side}", joint, body, placement,
                                                  pin.FrameType.OP_FRAME), False))
        links.append(model.frames[body].name)
    z = np.array([0.0, 0.0, 1.0])
    return Closure(cut.name, cut.cut_type, frame_ids[0], frame_ids[1], z, z, parent_link=links[0],
                   child_link=links[1], length_scale=length_scale)


def lock_anchored(model: pin.Model, cuts: list[AnchorCut], locked: dict[str, float], reference: np.ndarray | None,
                  source: str) -> tuple[pin.Model, list[AnchorCut], np.ndarray | None]:
    """Lock one-freedom joints out of the model, moving each cut side onto the nearest joint
    left moving (its placement composed at the locked values): the model, cuts, reference.

    Raises:
        FrameNotFound: a locked joint that is not in the model.
        ModelError: a locked joint with several freedoms (a ball, a free joint).
    """
    from pinmech.exceptions import FrameNotFound

    q_full = pin.neutral(model) if reference is None else np.array(reference, dtype=float)
    ids = []
    for name, value in locked.items():
        if not model.existJointName(name):
            raise FrameNotFound("joint to lock", name, list(model.names[1:]), path=source)
        jid = model.getJointId(name)
        joint = model.joints[jid]
        if joint.nq == 0 and "Mimic" in joint.shortname():
            ids.append(jid)  # a follower: its leader, locked with it, sets where it is held
            continue
        if joint.nv != 1:
            raise ModelError(f"joint '{name}' has {joint.nv} freedoms and cannot be locked by one value", path=source)
        q_full[joint.idx_q: joint.idx_q + joint.nq] = (np.cos(value), np.sin(value)) if joint.nq == 2 else value
        ids.append(jid)
    data = model.createData()
    pin.forwardKinematics(model, data, q_full)
    reduced = reduced_model(model, ids, q_full)

    def moved(joint: int, placement: pin.SE3) -> tuple[int, pin.SE3]:
        keep = joint
        while keep in ids:
            keep = model.parents[keep]
        new_id = reduced.getJointId(model.names[keep]) if keep else 0
        return new_id, data.oMi[keep].actInv(data.oMi[joint]) * placement

    new_cuts = []
    for cut in cuts:
        j1, m1 = moved(cut.joint1, cut.placement1)
        j2, m2 = moved(cut.joint2, cut.placement2)
        new_cuts.append(AnchorCut(cut.name, cut.cut_type, j1, m1, j2, m2))
    q_reduced = None
    if reference is not None:
        q_reduced = pin.neutral(reduced)
        for jid in range(1, reduced.njoints):
            old = model.joints[model.getJointId(reduced.names[jid])]
            new = reduced.joints[jid]
            q_reduced[new.idx_q: new.idx_q + new.nq] = q_full[old.idx_q: old.idx_q + old.nq]
    return reduced, new_cuts, q_reduced
