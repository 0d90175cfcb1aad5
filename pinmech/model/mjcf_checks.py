"""An MJCF file checked before Pinocchio reads it: near-miss spellings, repeated names,
keywords and numbers MuJoCo would refuse (Pinocchio's parser skips or misreads them), and
what MuJoCo computes otherwise for forces (masses, passive joint forces)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from pinmech.exceptions import ModelError


# ---------------------------------------------------------------- spelling
#: attributes the kinematics and masses are read from: a near miss of one of these is a typo
_READ = ("pos", "quat", "axisangle", "euler", "xyaxes", "zaxis", "axis", "ref", "type", "anchor", "body1",
         "body2", "site1", "site2", "mass", "density", "diaginertia", "fullinertia", "fromto", "size", "name",
         "class", "childclass", "active", "relpose", "mesh")
#: other attributes of MuJoCo's body, joint, geom, site, inertial, connect and weld
_OTHER = frozenset((
    "group", "springdamper", "limited", "actuatorfrclimited", "solreflimit", "solimplimit", "solreffriction",
    "solimpfriction", "stiffness", "range", "actuatorfrcrange", "actuatorgravcomp", "margin", "springref",
    "armature", "damping", "frictionloss", "user", "contype", "conaffinity", "condim", "priority", "material",
    "friction", "shellinertia", "solmix", "solref", "solimp", "gap", "hfield", "fitscale", "rgba", "fluidshape",
    "fluidcoef", "gravcomp", "mocap", "torquescale", "polycoef", "joint1", "joint2", "align"))
_SPELLED = ("body", "joint", "geom", "site", "inertial", "connect", "weld")


def _check_spelling(root: ET.Element, source: str) -> None:
    """An attribute of a body, joint, geom, site, inertial, connect or weld that is not
    MuJoCo's but a near miss of one the kinematics or masses are read from (`anchr`,
    `eular`, `mas`) is refused: Pinocchio's parser skips it, and a connect's anchor
    then sits at the body's origin (another linkage), a mass comes from the density.
    MuJoCo itself refuses any unknown attribute; attributes far from these are left to
    it, as a newer MuJoCo may know them."""
    import difflib

    for section in root.findall("worldbody") + root.findall("equality"):
        for el in section.iter():
            if el.tag not in _SPELLED:
                continue
            for key in el.attrib:
                if key in _READ or key in _OTHER:
                    continue
                near = difflib.get_close_matches(key, _READ, n=1, cutoff=0.7)
                if near:
                    raise ModelError(f"unknown attribute {key}=\"{el.get(key)}\": did you mean {near[0]}? "
                                     "(Pinocchio's parser would skip it)", path=source,
                                     element=f"<{el.tag} name=\"{el.get('name', '')}\">")


_NAMED = ("body", "joint", "site", "geom", "connect", "weld")


def _check_names(root: ET.Element, source: str) -> None:
    """Names unique per kind of element, and no joint after a ball joint in one body, as
    MuJoCo's compiler requires (Pinocchio's parser took both: `[drivers.h]` or a point
    then picked one of two elements in silence, and a ball then a hinge made a joint
    MuJoCo has no model of)."""
    for tag in _NAMED:
        seen: set[str] = set()
        for el in root.iter(tag):
            name = el.get("name")
            if name and name in seen:
                raise ModelError(f"repeated name '{name}' in <{tag}> (MuJoCo refuses it; name each once)",
                                 path=source, element=f"<{tag} name=\"{name}\">")
            seen.add(name)
    for body in root.iter("body"):
        kinds = [j.get("type", "hinge") for j in body.findall("joint")]
        if "ball" in kinds[:-1]:
            raise ModelError(f"a ball joint followed by another joint ({', '.join(kinds)}; MuJoCo refuses it): "
                             "put the ball joint last", path=source, element=f"<body name=\"{body.get('name', '')}\">")


# ---------------------------------------------------------------- keywords
#: (element, attribute) -> the keywords MuJoCo takes there (case-sensitive); anything else it refuses
_KEYWORDS = {
    ("compiler", "autolimits"): ("true", "false"), ("compiler", "inertiafromgeom"): ("false", "true", "auto"),
    ("compiler", "coordinate"): ("local",), ("joint", "type"): ("hinge", "slide", "ball", "free"),
    ("joint", "limited"): ("true", "false", "auto"), ("connect", "active"): ("true", "false"),
    ("weld", "active"): ("true", "false"),
    ("geom", "type"): ("plane", "hfield", "sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh", "sdf"),
}


def _check_keywords(root: ET.Element, source: str) -> None:
    """Every keyword attribute pinmech or Pinocchio's parser reads is one MuJoCo takes
    (active="0" was read as active, coordinate="global" as local): refused otherwise."""
    for el in root.iter():
        for key, value in el.attrib.items():
            allowed = _KEYWORDS.get((el.tag, key))
            if allowed is not None and value not in allowed:
                raise ModelError(f"{key}=\"{value}\" is not one of {', '.join(allowed)} (MuJoCo refuses it; "
                                 "keywords are lower case)", path=source,
                                 element=f"<{el.tag} name=\"{el.get('name', '')}\">")


# ---------------------------------------------------------------- numbers
#: attributes of placements, axes and masses -> how many numbers each holds
_COUNTS = {"pos": (3,), "quat": (4,), "axisangle": (4,), "euler": (3,), "xyaxes": (6,), "zaxis": (3,),
           "axis": (3,), "fromto": (6,), "anchor": (3,), "mass": (1,), "density": (1,), "diaginertia": (3,),
           "fullinertia": (6,), "ref": (1,), "size": (1, 2, 3)}


def _check_numbers(root: ET.Element, source: str) -> None:
    """Every placement, axis and mass attribute of the bodies and equalities holds as many
    finite numbers as MuJoCo reads: Pinocchio's parser reads pos="0.16, 0.05, 0" (a
    comma) or "0.16 0.05" as garbage (z = -2e243 was seen) and "0 0 nan" as given."""
    for section in root.findall("worldbody") + root.findall("equality"):
        for el in section.iter():
            for key, counts in _COUNTS.items():
                text = el.get(key)
                if text is None:
                    continue
                try:
                    values = [float(v) for v in text.split()]
                except ValueError:
                    values = []
                if len(values) not in counts or not all(math.isfinite(v) for v in values):
                    want = " or ".join(str(c) for c in counts)
                    raise ModelError(f"{key}=\"{text}\" is not {want} finite numbers (separated by spaces)",
                                     path=source, element=f"<{el.tag} name=\"{el.get('name', '')}\">")


# ---------------------------------------------------------------- what forces need
_MASS_OPTIONS = ("inertiafromgeom", "settotalmass", "boundmass", "boundinertia", "balanceinertia",
                 "inertiagrouprange", "exactmeshinertia")
_PASSIVE = ("damping", "stiffness", "frictionloss")


def _force_caveats(root: ET.Element) -> tuple[str, ...]:
    """Why the forces of this file are not those of Pinocchio's model of it: masses the
    parser does not compute as MuJoCo, and passive joint forces MuJoCo adds."""
    out = []
    for compiler in root.findall("compiler"):
        for key in _MASS_OPTIONS:
            value = compiler.get(key)
            if value is not None and not (key == "inertiafromgeom" and value == "auto"):
                out.append(f"<compiler {key}=\"{value}\"> sets masses in MuJoCo that Pinocchio's parser "
                           "computes otherwise: remove it and give the bodies <inertial> elements")
    for world in root.findall("worldbody"):
        for body in world.iter("body"):
            if body.find("inertial") is not None:
                continue
            for geom in body.findall("geom"):
                kind = geom.get("type", "mesh" if geom.get("mesh") else "sphere")
                if geom.get("mass") in ("0", "0.0") or geom.get("density") in ("0", "0.0"):
                    continue
                if kind in ("mesh", "hfield", "sdf"):
                    out.append(f"<body name=\"{body.get('name', '')}\"> has no <inertial> and a {kind} geom: "
                               "Pinocchio's parser gives it 1 kg m^2 about each axis, not MuJoCo's inertia; "
                               "give the body an <inertial> element")
                elif not 0 <= int(float(geom.get("group", "0"))) <= 5:
                    out.append(f"<body name=\"{body.get('name', '')}\"> has no <inertial> and a geom of group "
                               f"{geom.get('group')}, which MuJoCo leaves out of its mass; give the body an "
                               "<inertial> element")
        for joint in world.iter("joint"):
            for key in _PASSIVE:
                text = joint.get(key, "0")
                try:
                    nonzero = any(float(v) != 0 for v in text.split())
                except ValueError:
                    nonzero = True
                if nonzero:
                    out.append(f"<joint name=\"{joint.get('name', '')}\"> has {key}=\"{text}\": MuJoCo adds "
                               "that passive force, pinmech's forces are those of ideal joints; remove it to "
                               "compute forces")
    return tuple(out)
