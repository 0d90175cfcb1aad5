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

from pinmech.closures import Closure
from pinmech.exceptions import ModelError


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
