"""A URDF's XML as pinmech reads it: `<constraint>` loop cuts, named points, near-miss spellings.

Pinocchio ignores `<constraint>`; these functions read it (checked element by element), find
the named points (massless leaf links on fixed joints), and refuse a misspelled element or
attribute that urdfdom would skip in silence.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinmech.directions import unit_vector
from pinmech.exceptions import ModelError
from pinmech.file_limits import file_bytes
from pinmech.model.closures import CUT_TYPES
from pinmech.model.urdf_joints import mimic_joints


def urdf_joint_types(path: str | Path) -> dict[str, str]:
    """Joint name -> URDF joint type ("revolute", "prismatic", ...), read from the XML."""
    root = _parse_xml(Path(path))
    return {j.get("name"): j.get("type") for j in root.findall("joint")}


def urdf_mimic_leaders(path: str | Path) -> dict[str, str]:
    """Follower -> leader of the URDF's `<mimic>` joints, read from the XML."""
    return {n: m.leader for n, m in mimic_joints(_parse_xml(Path(path)), str(path)).items()}


def read_xml(path: Path, root_tag: str, kind: str) -> ET.Element:
    """The root element of a model file (`kind`: "URDF", "MJCF"), checked to be <root_tag>.

    Raises:
        ModelError: a missing file, malformed XML or another root element, naming the file.
    """
    data = file_bytes(path, kind, ModelError)  # missing or over file_limits' size: refused first
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise ModelError(f"malformed XML: {exc}", path=str(path)) from exc
    if root.tag != root_tag:
        raise ModelError(f"root element is <{root.tag}>, expected <{root_tag}>", path=str(path))
    return root


def _parse_xml(path: Path) -> ET.Element:
    return read_xml(path, "robot", "URDF")


def _link_names(root: ET.Element) -> list[str]:
    return [link.get("name") for link in root.findall("link")]


def _joint_links(root: ET.Element) -> dict[str, tuple[str, str]]:
    """Joint name -> (parent link, child link), as the URDF writes them."""
    return {
        j.get("name"): (j.find("parent").get("link"), j.find("child").get("link"))
        for j in root.findall("joint")
        if j.find("parent") is not None and j.find("child") is not None
    }


def _point_links(root: ET.Element) -> list[str]:
    """Massless leaf links hung on fixed joints: the URDF's named points."""
    parents = {j.find("parent").get("link") for j in root.findall("joint") if j.find("parent") is not None}
    fixed_children = {
        j.find("child").get("link")
        for j in root.findall("joint")
        if j.get("type") == "fixed" and j.find("child") is not None
    }
    empty = {
        link.get("name")
        for link in root.findall("link")
        if not any(link.find(tag) is not None for tag in ("inertial", "visual", "collision"))
    }
    return [n for n in _link_names(root) if n in fixed_children and n in empty and n not in parents]


def _vector(element: ET.Element | None, attr: str, default: str, where: str, source: str) -> np.ndarray:
    text = default if element is None else element.get(attr, default)
    try:
        values = np.array([float(x) for x in text.split()])
    except ValueError:
        raise ModelError(f"{attr}=\"{text}\" is not three numbers", path=source, element=where) from None
    if values.shape != (3,) or not np.all(np.isfinite(values)):
        raise ModelError(f"{attr}=\"{text}\" is not three finite numbers", path=source, element=where)
    return values


@dataclass(frozen=True)
class _Cut:
    name: str
    cut_type: str
    parent_link: str
    child_link: str
    parent_origin: pin.SE3
    child_origin: pin.SE3
    parent_axis: np.ndarray
    child_axis: np.ndarray
    source: str


def _parse_constraint(el: ET.Element, model: pin.Model, links: list[str], source: str) -> _Cut:
    name = el.get("name") or "<unnamed>"
    where = f"<constraint name=\"{name}\">"
    _check_known(el, where, source)
    cut_type = el.get("type")
    if cut_type not in CUT_TYPES:
        raise ModelError(f"type=\"{cut_type}\" is not one of {', '.join(CUT_TYPES)}", path=source, element=where)
    sides = {}
    for side in ("parent", "child"):
        link_el = el.find(side)
        link = None if link_el is None else link_el.get("link")
        if link is None:
            raise ModelError(f"missing <{side} link=\"...\"/>", path=source, element=where)
        if link not in links:
            raise ModelError(f"<{side} link=\"{link}\"/> names no link of the model", path=source, element=where)
        if not model.existBodyName(link):
            raise ModelError(f"<{side} link=\"{link}\"/> is not connected to the tree of joints from the root link",
                             path=source, element=where)
        origin = el.find(f"{side}_origin")
        xyz = _vector(origin, "xyz", "0 0 0", where, source)
        rpy = _vector(origin, "rpy", "0 0 0", where, source)
        axis = _vector(el.find(f"{side}_axis"), "xyz", "0 0 1", where, source)
        unit = unit_vector(axis)
        if unit is None:
            raise ModelError(f"<{side}_axis xyz=\"{el.find(f'{side}_axis').get('xyz')}\"/> is not a direction",
                             path=source, element=where)
        sides[side] = (link, pin.SE3(pin.rpy.rpyToMatrix(rpy), xyz), unit)
    return _Cut(name, cut_type, sides["parent"][0], sides["child"][0], sides["parent"][1], sides["child"][1],
                sides["parent"][2], sides["child"][2], source)


#: URDF elements whose children and attributes pinmech's kinematics and masses depend on,
#: with what they hold (urdfdom skips anything else: a misspelled <orign> leaves the joint
#: at the identity, another mechanism)
_URDF_CHILDREN = {"joint": ("origin", "parent", "child", "axis", "calibration", "dynamics", "limit", "mimic",
                            "safety_controller"),
                  "inertial": ("origin", "mass", "inertia")}
_URDF_ATTRIBUTES = {"origin": ("xyz", "rpy"), "axis": ("xyz",), "mass": ("value",),
                    "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), "parent": ("link",), "child": ("link",),
                    "joint": ("name", "type")}


def _check_urdf_spelling(root: ET.Element, source: str) -> None:
    """A child of a <joint> or <inertial>, or an attribute of the elements the kinematics
    and masses are read from, that is a near miss of a URDF name (<orgin>, xzy=) is
    refused with the likely spelling; urdfdom would skip it in silence. Names far from
    these are left alone (URDF files carry extensions)."""

    def near(name: str, known: tuple[str, ...]) -> str | None:
        if name in known or not known:  # not known: an element whose attributes are not checked
            return None
        swapped = [k for k in known if sorted(k) == sorted(name)]  # xzy for xyz
        if swapped:
            return swapped[0]
        import difflib  # only for a name that is not a URDF one (a file without them does not load it)

        match = difflib.get_close_matches(name, known, n=1, cutoff=0.7)
        return match[0] if match else None

    elements = [(j, "joint", f"<joint name=\"{j.get('name', '')}\">") for j in root.iter("joint")]
    elements += [(i, "inertial", f"<link name=\"{link.get('name', '')}\"> <inertial>")
                 for link in root.iter("link") for i in link.findall("inertial")]
    for el, parent_tag, where in elements:
        for child in el:
            if not isinstance(child.tag, str):  # a comment
                continue
            guess = near(child.tag, _URDF_CHILDREN[parent_tag])
            if guess:
                raise ModelError(f"unknown element <{child.tag}>: did you mean <{guess}>? (the URDF parser would "
                                 "skip it)", path=source, element=where)
            for key in child.attrib:
                guess = near(key, _URDF_ATTRIBUTES.get(child.tag, ()))
                if guess:
                    raise ModelError(f"unknown attribute {key}=\"{child.get(key)}\" of <{child.tag}>: did you "
                                     f"mean {guess}?", path=source, element=where)


#: what a <constraint> holds: its attributes, and each child element with its attributes
_CONSTRAINT_ATTRIBUTES = {"name", "type"}
_CONSTRAINT_CHILDREN = {"parent": {"link"}, "child": {"link"}, "parent_origin": {"xyz", "rpy"},
                        "child_origin": {"xyz", "rpy"}, "parent_axis": {"xyz"}, "child_axis": {"xyz"}}


def _check_known(el: ET.Element, where: str, source: str) -> None:
    """Every attribute and child of a <constraint> is one pinmech reads: a misspelled
    <parent_orgin> was skipped, its origin taken as 0 0 0, and another mechanism solved."""
    for key in el.attrib:
        if key not in _CONSTRAINT_ATTRIBUTES:
            raise ModelError(f"unknown attribute {key}=\"{el.get(key)}\" (a <constraint> has "
                             f"{', '.join(sorted(_CONSTRAINT_ATTRIBUTES))})", path=source, element=where)
    seen = set()
    for child in el:
        if not isinstance(child.tag, str):  # a comment
            continue
        if child.tag not in _CONSTRAINT_CHILDREN:
            raise ModelError(f"unknown element <{child.tag}> (a <constraint> holds "
                             f"{', '.join(f'<{t}>' for t in _CONSTRAINT_CHILDREN)})", path=source, element=where)
        if child.tag in seen:
            raise ModelError(f"<{child.tag}> is given twice", path=source, element=where)
        seen.add(child.tag)
        for key in child.attrib:
            if key not in _CONSTRAINT_CHILDREN[child.tag]:
                raise ModelError(f"unknown attribute {key}=\"{child.get(key)}\" of <{child.tag}> (it has "
                                 f"{', '.join(sorted(_CONSTRAINT_CHILDREN[child.tag]))})", path=source, element=where)

