"""Gepetto's extended URDF: a URDF plus a `robot.yaml` sidecar naming its loops and motors.

The format of example-parallel-robots / toolbox-parallel-robots (arXiv 2504.04767):

    closed_loop: [['closedloop1_A', 'closedloop1_B']]   # pairs of frames made to coincide
    type: ['3d']                                         # 3d: positions (a ball joint), 6d: placements
    name_mot: ['mot1', 'mot2']                           # actuated joints: pinmech's default drivers
    joint_name: ['elbow']                                # optional: joints to change...
    joint_type: ['CARDAN']                               # ...into SPHERICAL, CARDAN (RX then RY) or FIXED

Each pair becomes a loop cut between the two frames (3d: spherical, 6d: fixed), named by
them with an en dash ("closedloop1_A–closedloop1_B"; an `assembly` table may write a hyphen), built as
Pinocchio `RigidConstraintModel`s exactly as Gepetto's loader does, then handed to
`Mechanism.from_model`. A missing `type` entry means 6d, as there.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pinocchio as pin

from pinmech.exceptions import ModelError
from pinmech.file_limits import check_nesting, file_text, nested_too_deep
from pinmech.known_keys import unknown_keys
from pinmech.model.frame_names import frame_named, reduced_model
from pinmech.model.inertia_check import urdf_inertia_caveats
from pinmech.model.mechanism import Mechanism
from pinmech.model.pinocchio_build import _build_model
from pinmech.model.urdf_xml import _parse_xml, _point_links
from pinmech.model.urdf_joints import joint_limits, mimic_joints, with_followers

_KEYS = {"closed_loop", "type", "name_mot", "joint_name", "joint_type"}
_JOINT_TYPES = ("SPHERICAL", "CARDAN", "FIXED")


def read_sidecar(path: str | Path) -> dict[str, Any]:
    """The sidecar's content, checked: lists of names, pairs, types in {3d, 6d}.

    Raises:
        ModelError: a missing or malformed file, an unknown key, a pair that is not two names.
        ImportError: PyYAML missing (pip install "pinmech[yaml]").
    """
    try:
        import yaml
    except ImportError as exc:  # pragma: no cover - PyYAML is in the test extra
        raise ImportError('reading robot.yaml needs PyYAML: pip install "pinmech[yaml]"') from exc
    path = Path(path)
    source = str(path)
    try:
        content = yaml.safe_load(file_text(path, "sidecar", ModelError)) or {}
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise ModelError(f"malformed YAML: {' '.join(str(exc).split())}", path=source) from exc
    except RecursionError:
        raise nested_too_deep("sidecar", path, ModelError) from None
    check_nesting(content, "sidecar", path, ModelError)
    if not isinstance(content, dict):
        raise ModelError("expected keys closed_loop, type, name_mot", path=source)
    message = unknown_keys(content, sorted(_KEYS))
    if message:
        raise ModelError(message, path=source)
    out = {key: content.get(key) or [] for key in _KEYS}
    for key in _KEYS:
        if not isinstance(out[key], list):
            raise ModelError(f"must be a list, got {out[key]!r:.80}", path=source, element=key)
    for key in ("type", "name_mot", "joint_name", "joint_type"):
        for i, entry in enumerate(out[key]):
            if not isinstance(entry, str):
                raise ModelError(f"entry {i + 1} must be a name (text), got {entry!r:.80}", path=source, element=key)
    for key in ("name_mot", "joint_name"):
        twice = sorted({n for n in out[key] if out[key].count(n) > 1})
        if twice:
            raise ModelError(f"{', '.join(twice)} listed twice", path=source, element=key)
    for i, pair in enumerate(out["closed_loop"]):
        if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(n, str) for n in pair)):
            raise ModelError(f"entry {i + 1} must be two frame names, got {pair!r:.80}", path=source,
                             element="closed_loop")
        if pair[0] == pair[1]:
            raise ModelError(f"entry {i + 1} joins frame '{pair[0]}' to itself: a loop needs two frames",
                             path=source, element="closed_loop")
    types = [str(t).lower() for t in out["type"]]
    for t in types:
        if t not in ("3d", "6d"):
            raise ModelError(f"'{t}' is not 3d or 6d", path=source, element="type")
    if len(types) > len(out["closed_loop"]):
        raise ModelError(f"{len(types)} types for {len(out['closed_loop'])} closed loops", path=source,
                         element="type")
    out["type"] = types + ["6d"] * (len(out["closed_loop"]) - len(types))
    if len(out["joint_name"]) != len(out["joint_type"]):
        raise ModelError(f"{len(out['joint_name'])} joint_name entries for {len(out['joint_type'])} joint_type",
                         path=source, element="joint_type")
    for t in out["joint_type"]:
        if t not in _JOINT_TYPES:
            raise ModelError(f"joint_type '{t}' is not one of {', '.join(_JOINT_TYPES)}", path=source,
                             element="joint_type")
    return out


def load_extended_urdf(urdf: str | Path, sidecar: str | Path, *,
                       locked: dict[str, float] | None = None) -> Mechanism:
    """A URDF and its robot.yaml as a Mechanism; `mechanism.motors` lists the actuated joints.

    Raises:
        ModelError: naming the sidecar, the key and the frame or joint it names wrongly.
    """
    urdf, sidecar = Path(urdf), Path(sidecar)
    content = read_sidecar(sidecar)
    root = _parse_xml(urdf)
    mimics = mimic_joints(root, str(urdf))
    model = _build_model(str(urdf), mimic=bool(mimics))
    if mimics and content["joint_name"]:
        raise ModelError(f"joint_name/joint_type change joints of a URDF with <mimic> joints "
                         f"({', '.join(mimics)}): pinmech cannot rebuild those; change the URDF itself",
                         path=str(sidecar), element="joint_name")
    model = _changed_joints(model, content["joint_name"], content["joint_type"], str(sidecar))
    locked = with_followers(dict(locked or {}), mimics, str(urdf))
    constraints, names = [], []
    for (a, b), kind in zip(content["closed_loop"], content["type"]):
        ids = [frame_named(model, name, source=str(sidecar)) for name in (a, b)]
        for name, fid in zip((a, b), ids):
            if fid is None:
                raise ModelError(f"frame '{name}' is not in {urdf.name}", path=str(sidecar), element="closed_loop")
        fa, fb = model.frames[ids[0]], model.frames[ids[1]]
        contact = pin.ContactType.CONTACT_3D if kind == "3d" else pin.ContactType.CONTACT_6D
        constraints.append(pin.RigidConstraintModel(contact, model, fa.parentJoint, fa.placement, fb.parentJoint,
                                                    fb.placement, pin.ReferenceFrame.LOCAL))
        names.append(f"{a}\u2013{b}")  # "closedloop1_A–closedloop1_B": an en dash between the two frames
    points = [n for n in _point_links(root) if frame_named(model, n, source=str(urdf)) is not None]
    mech = Mechanism.from_model(model, constraints, names=names, points=points, source=str(urdf),
                                urdf_path=str(urdf), locked=locked)
    mech.mimics = {n: m for n, m in mimics.items() if n not in mech.locked}
    mech.force_caveats = tuple(urdf_inertia_caveats(root, str(urdf))) + mech.force_caveats
    mech.limits = {n: lu for n, lu in joint_limits(root, str(urdf)).items() if n in mech.joints or n in mech.locked}
    held = set(mech.locked)
    for motor in content["name_mot"]:
        if motor not in mech.joints and motor not in held:
            raise ModelError(f"motor '{motor}' is not a joint of {urdf.name} (joints: {', '.join(mech.joints)})",
                             path=str(sidecar), element="name_mot")
    mech.motors = [m for m in content["name_mot"] if m not in held]  # a locked motor drives nothing
    return mech


def _changed_joints(model: pin.Model, names: list[str], types: list[str], source: str) -> pin.Model:
    """The model with the sidecar's joints made SPHERICAL, CARDAN (RX, RY) or FIXED."""
    if not names:
        return model
    for name in names:
        if not model.existJointName(name):
            raise ModelError(f"joint '{name}' is not in the URDF", path=source, element="joint_name")
    change = dict(zip(names, types))
    new = pin.Model()
    new.name = model.name
    renamed = {}
    for jid in range(1, model.njoints):
        name = model.names[jid]
        parent = new.getJointId(renamed.get(model.names[model.parents[jid]], model.names[model.parents[jid]]))
        placement, joint = model.jointPlacements[jid], model.joints[jid]
        kind = change.get(name)
        if kind == "SPHERICAL":
            joint = pin.JointModelSpherical()
        elif kind == "CARDAN":
            parent = new.addJoint(parent, pin.JointModelRX(), placement, f"{name}_X")
            joint, placement = pin.JointModelRY(), pin.SE3.Identity()
            renamed[name] = f"{name}_Y"
            name = f"{name}_Y"
        new_id = new.addJoint(parent, joint, placement, name)
        new.appendBodyToJoint(new_id, model.inertias[jid], pin.SE3.Identity())
    new_frame = {0: 0}  # old frame id -> new (frames of several kinds may share a name)
    for fid, frame in enumerate(list(model.frames)[1:], start=1):
        owner = model.names[frame.parentJoint]
        joint = new.getJointId(renamed.get(owner, owner))
        new_frame[fid] = new.addFrame(pin.Frame(frame.name, joint, new_frame[frame.parentFrame], frame.placement,
                                                frame.type), False)
    fixed = [new.getJointId(n) for n, t in change.items() if t == "FIXED"]
    if fixed:
        new = reduced_model(new, fixed, pin.neutral(new))
    return new

