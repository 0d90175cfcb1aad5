"""The joints and points of a model as a user names them: kind, coordinates, axis, links."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.directions import unit_vector
from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.model.frame_names import frame_named, frames_of_kind


@dataclass(frozen=True)
class JointInfo:
    """A one-degree-of-freedom (or other) joint of the model, as a user names it.

    Attributes:
        kind: "revolute", "continuous" (stored as cos/sin), "prismatic" or "other".
        idx_q, idx_v: first index in the configuration and velocity vectors.
    """

    name: str
    id: int
    kind: str
    idx_q: int
    idx_v: int
    nq: int
    nv: int
    parent_link: str
    child_link: str
    axis: np.ndarray  # in the joint frame

    @property
    def is_angular(self) -> bool:
        return self.kind in ("revolute", "continuous")

    def coordinate(self, q: Sequence[float]) -> float:
        """Its coordinate in configuration q [rad or m] (a one-dof joint's; a continuous
        joint's angle in (-pi, pi] from its (cos, sin) pair)."""
        if self.kind == "continuous":
            return math.atan2(q[self.idx_q + 1], q[self.idx_q])  # libm's atan2, as numpy's for one pair
        return float(q[self.idx_q])



def _joint_kind(joint: pin.JointModel) -> str:
    short = joint.shortname()
    if joint.nv != 1:
        return "other"
    if joint.nq == 2:
        return "continuous"
    if "Prismatic" in short or short.startswith("JointModelP"):
        return "prismatic"
    if "Revolute" in short or short.startswith("JointModelR"):
        return "revolute"
    return "other"


def _written_axis(source: str, name: str) -> str | None:
    """The axis a URDF (`<axis xyz>`) or MJCF (`axis`) file writes for joint `name`, as written
    (`xyz="0 0 1e-200"`), or None (no such file or joint, or not three numbers)."""
    try:
        root = ET.parse(source).getroot()
    except (OSError, ET.ParseError):
        return None
    for joint in root.iter("joint"):
        if joint.get("name") == name:
            axis = joint.find("axis")
            key, text = ("xyz", axis.get("xyz")) if axis is not None else ("axis", joint.get("axis"))
            try:
                return f'{key}="{text}"' if text is not None and len([float(v) for v in text.split()]) == 3 else None
            except ValueError:
                return None
    return None


def _joint_axis(joint: pin.JointModel, name: str, source: str) -> np.ndarray:
    """Unit axis of a one-dof joint in its own frame (motion subspace).

    Raises:
        ModelError: an axis of zero length (or not finite): the joint would move nothing.
    """
    if joint.nv != 1:
        return np.zeros(3)
    data = joint.createData()
    q = np.zeros(joint.nq)
    if joint.nq == 2:
        q[0] = 1.0
    joint.calc(data, q)
    S = np.array(data.S).reshape(6, 1)[:, 0]
    part = S[3:] if np.linalg.norm(S[3:]) > 0 else S[:3]
    norm = float(np.linalg.norm(part))
    if not (norm > 0 and np.isfinite(norm)):
        text = _written_axis(source, name)
        if text is not None and unit_vector([float(v) for v in text.split("\"")[1].split()]) is not None:
            raise ModelError(f"{text} is a direction Pinocchio's reader cannot normalise (its length "
                             "under- or overflows in double precision, the axis read as [0, 0, 0]): write it as a "
                             "unit vector", path=source, element=f"<joint name=\"{name}\"> <axis>")
        raise ModelError(f"the axis of joint {name} is {np.round(part, 6).tolist()}: not a direction, the joint "
                         "would move nothing", path=source, element=f"<joint name=\"{name}\"> <axis>")
    return part / norm


def _joint_infos(model: pin.Model, joint_links: dict[str, tuple[str, str]], source: str) -> dict[str, JointInfo]:
    infos = {}
    for jid in range(1, model.njoints):
        joint, name = model.joints[jid], model.names[jid]
        parent, child = joint_links.get(name, (model.names[model.parents[jid]], name))
        infos[name] = JointInfo(name, jid, _joint_kind(joint), joint.idx_q, joint.idx_v, joint.nq, joint.nv,
                                parent, child, _joint_axis(joint, name, source))
    return infos


def _tree_joint_links(model: pin.Model) -> dict[str, tuple[str, str]]:
    """Joint name -> (parent link, child link) of a model built in code: the BODY frames on
    either side of each joint ("universe" above the root)."""
    joint_links = {}
    for jid in range(1, model.njoints):
        child = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == jid),
                     model.names[jid])
        parent = next((f.name for f in model.frames if f.type == pin.FrameType.BODY
                       and f.parentJoint == model.parents[jid]), "universe")
        joint_links[model.names[jid]] = (parent, child)
    return joint_links


def _named_points(model: pin.Model, names: Sequence[str] | None, source: str) -> dict[str, int]:
    """Name -> frame id of the named points: the frames called so (a site before a body or
    a joint of the same name), by default every OP_FRAME (MJCF sites).

    Raises:
        FrameNotFound: a name no frame has.
    """
    if names is None:
        return frames_of_kind(model, pin.FrameType.OP_FRAME, source)
    out = {}
    for name in names:
        fid = frame_named(model, name, source=source)
        if fid is None:
            raise FrameNotFound("point", name, sorted({f.name for f in model.frames}), path=source)
        out[name] = fid
    return out


def _body_frame(model: pin.Model, link: str) -> int:
    return frame_named(model, link, (pin.FrameType.BODY,))

