"""Frames looked up by name and kind: a joint, a body and a site may share a name.

MJCF keeps a namespace per kind (every MuJoCo Menagerie file names its joints after their
bodies), and so does a URDF between its links and joints. Pinocchio's by-name look-ups
(`getFrameId(name)`, and `buildReducedModel`, which finds frames by name) then fail with
"Several frames match the filter". pinmech looks every frame up with its kind.
"""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError

#: The kinds a named point or frame is looked for in, first to last: a site (OP_FRAME)
#: before the body, then a fixed joint's frame, then a moving joint's.
POINT_KINDS = (pin.FrameType.OP_FRAME, pin.FrameType.BODY, pin.FrameType.FIXED_JOINT, pin.FrameType.JOINT)
_TAG = re.compile(r"__pm[jf]#\d+$")


def frame_named(model: pin.Model, name: str, kinds: tuple = POINT_KINDS, source: str = "<model>") -> int | None:
    """Id of the frame called `name` of the first of `kinds` that has one; None if none.

    Raises:
        ModelError: two frames of the same kind share the name (which one is meant?).
    """
    for kind in kinds:
        ids = [i for i, f in enumerate(model.frames) if f.name == name and f.type == kind]
        if len(ids) > 1:
            raise ModelError(f"{len(ids)} frames of kind {kind.name} are called '{name}' (ids "
                             f"{', '.join(map(str, ids))}): name them apart", path=source)
        if ids:
            return ids[0]
    return None


def frames_of_kind(model: pin.Model, kind: pin.FrameType, source: str = "<model>") -> dict[str, int]:
    """Name -> id of every frame of one kind.

    Raises:
        ModelError: two frames of that kind share a name.
    """
    out: dict[str, int] = {}
    for i, frame in enumerate(model.frames):
        if frame.type == kind:
            if frame.name in out:
                raise ModelError(f"two frames of kind {kind.name} are called '{frame.name}' (ids {out[frame.name]} "
                                 f"and {i}): name them apart", path=source)
            out[frame.name] = i
    return out


def reduced_model(model: pin.Model, joint_ids: list[int], q_ref: np.ndarray) -> pin.Model:
    """`pin.buildReducedModel(model, joint_ids, q_ref)`, also when frames of several kinds
    share a name: every joint and frame carries a unique name while Pinocchio reduces the
    model (it finds frames by name), and gets its own back after."""
    model = pin.Model(model)
    joint_of_name = {}
    for jid in range(1, model.njoints):
        joint_of_name[(model.names[jid], jid)] = f"{model.names[jid]}__pmj#{jid}"
        model.names[jid] = joint_of_name[(model.names[jid], jid)]
    for i, frame in enumerate(model.frames):
        key = (frame.name, frame.parentJoint)
        if frame.type == pin.FrameType.JOINT and key in joint_of_name:
            frame.name = joint_of_name[key]
        else:
            frame.name = f"{frame.name}__pmf#{i}"
    reduced = pin.buildReducedModel(model, list(joint_ids), q_ref)
    for jid in range(reduced.njoints):
        reduced.names[jid] = _TAG.sub("", reduced.names[jid])
    for frame in reduced.frames:
        frame.name = _TAG.sub("", frame.name)
    return reduced
