"""Several joints in one MJCF body (one composite joint in Pinocchio) placed as MuJoCo places them.

MuJoCo draws every body where the file puts it at qpos0, each joint at its `ref`. Pinocchio 4.1's
parser subtracts the `ref` of a single joint, and of every part of a composite but the first:
the first part's `ref` stays in the composite's placement, so at qpos0 the body is turned
(hinge) or shifted (slide) by it. This module takes it out of the placement again:
composite placement ← placement · P0 · X0(−ref) · P0⁻¹, P0 the first part's own placement and
X0 its motion, which commutes with itself, so every later qpos is MuJoCo's too. A loop
cut's second placement was computed by the parser from the misplaced body at qpos0: it is
computed again, as MuJoCo takes a `connect` or `weld` at qpos0.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError

_ONE_FREEDOM = ("hinge", "slide")


def _first_refs(root: ET.Element) -> dict[str, tuple[str, float]]:
    """Body name -> (its first joint's name, that joint's `ref` [rad or m]) for each body with
    several joints whose first has a nonzero `ref` (angles already in radians)."""
    out = {}
    for body in root.iter("body"):
        joints = body.findall("joint")
        if len(joints) > 1 and joints[0].get("type", "hinge") in _ONE_FREEDOM:
            ref = float(joints[0].get("ref", "0"))
            if ref != 0.0:
                out[body.get("name", "")] = (joints[0].get("name", ""), ref)
    return out


def place_composites_as_mujoco(model: pin.Model, cuts: list, root: ET.Element, source: str) -> None:
    """Take each composite's first `ref` out of its joint placement, and place each cut's
    second side again where its first side is at qpos0 (both in place).

    Raises:
        ModelError: a body with several joints, the first with a `ref`, whose composite
            joint Pinocchio's model does not hold under `Composite_<first joint>`.
    """
    for body, (first, ref) in _first_refs(root).items():
        name = f"Composite_{first}"
        if not first or not model.existJointName(name):
            raise ModelError(f"the first of its joints has ref=\"{ref:.17g}\" and no composite joint {name} was "
                             "found to place it as MuJoCo does (name the body's joints)", path=source,
                             element=f"<body name=\"{body}\">")
        jid = model.getJointId(name)
        composite = model.joints[jid].extract()
        part, placement = composite.joints[0], composite.jointPlacements[0]
        motion, q = part.createData(), np.zeros(model.nq)  # the part reads q at its own index
        q[part.idx_q] = -ref
        part.calc(motion, q)
        model.jointPlacements[jid] = model.jointPlacements[jid] * placement * motion.M * placement.inverse()
    if _first_refs(root):
        _cuts_at_qpos0(model, cuts)


def _cuts_at_qpos0(model: pin.Model, cuts: list) -> None:
    """joint2_placement of each cut: where its joint1 side is at qpos0, in joint2's frame."""
    data = model.createData()
    q0 = model.referenceConfigurations["qpos0"] if "qpos0" in model.referenceConfigurations else pin.neutral(model)
    pin.forwardKinematics(model, data, q0)
    for cut in cuts:
        side1 = data.oMi[cut.joint1_id] * cut.joint1_placement
        cut.joint2_placement = data.oMi[cut.joint2_id].inverse() * side1
