"""A URDF with `<constraint>` loop cuts read into a Mechanism (`Mechanism.from_urdf`): the
XML checked, Pinocchio's model built and locked, the cuts made closures."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pinocchio as pin

from pinmech.arguments import file_path
from pinmech.exceptions import ModelError
from pinmech.model.closure_rows import _make_closure, close_loops
from pinmech.model.inertia_check import urdf_inertia_caveats
from pinmech.model.joint_info import _body_frame, _joint_infos
from pinmech.model.pinocchio_build import _build_model, _check_locked, _check_size, _lock_joints
from pinmech.model.urdf_joints import joint_limits, mimic_joints, with_followers
from pinmech.model.urdf_xml import (_check_urdf_spelling, _joint_links, _link_names, _parse_constraint, _parse_xml,
                                    _point_links)


def mechanism_from_urdf(cls: type, path: str | Path, *, locked: dict[str, float] | None = None,
                        root_joint: str | None = None, reference: dict[str, float] | None = None) -> Any:
    """A `cls` (Mechanism) from a URDF file; the arguments and errors of `Mechanism.from_urdf`."""
    path = file_path(path, "the URDF")
    source = str(path)
    root = _parse_xml(path)
    _check_urdf_spelling(root, source)
    _check_locked(locked or {}, source)
    mimics = mimic_joints(root, source)
    full = _build_model(source, root_joint, mimic=bool(mimics))
    locked = with_followers(dict(locked or {}), mimics, source)
    model = _lock_joints(full, locked, source)
    _check_size(model, source)
    if model.nv == 0:
        held = f" once {', '.join(locked)} are locked" if locked else ""
        raise ModelError(f"no joint of the model moves{held}: nothing to solve", path=source)
    links_xml = _link_names(root)
    point_names = _point_links(root)
    joint_links = _joint_links(root)
    cuts = [_parse_constraint(c, model, links_xml, source) for c in root.findall("constraint")]
    names = [c.name for c in cuts]
    for name in names:
        if names.count(name) > 1:
            raise ModelError("two <constraint> elements share this name", path=source,
                             element=f"<constraint name=\"{name}\">")
    mech = cls(
        model=model,
        closures=[],
        joints=_joint_infos(model, joint_links, source),
        links={n: _body_frame(model, n) for n in links_xml if n not in point_names and model.existBodyName(n)},
        points={n: _body_frame(model, n) for n in point_names if model.existBodyName(n)},
        length_scale=1.0,
        plane_normal=None,
        source=source,
        locked=dict(locked or {}),
        mimics={n: m for n, m in mimics.items() if n not in (locked or {})},
        force_caveats=tuple(urdf_inertia_caveats(root, source)),
    )
    mech.limits = {n: lu for n, lu in joint_limits(root, source).items() if n in mech.joints or n in mech.locked}
    close_loops(mech, [_make_closure(model, c) for c in cuts])
    if reference:
        q = pin.neutral(model)
        for name, value in reference.items():
            if name in mech.joints:
                mech.set_coordinate(q, name, value)
        mech.reference = q
    return mech
