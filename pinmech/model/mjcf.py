"""MJCF (MuJoCo) files with `<equality>` loops -> a Mechanism, Pinocchio's parser's traps handled.

Pinocchio 4.1's `buildModelAndConstraintsFromMJCF` returns the kinematic tree with each
`<connect>` as a point anchor (a spherical cut) and each `<weld>` as a frame anchor (a
fixed cut). Its known traps, each handled here or refused in one line:

* a second top-level body of `<worldbody>` is silently dropped (stack-of-tasks/pinocchio
  #2364), and a fixed top body's `pos` is lost: every top-level body is put under one
  wrapper body at the world origin before parsing, so all of them and their placements stay;
* a `connect` anchor is taken at the reference pose (qpos0), as MuJoCo does: the loop is
  the one that is closed at qpos0, so a model drawn open at qpos0 is refused where it can be
  seen (sites given to `connect` that do not meet at qpos0) and otherwise documented;
* a floating base (a `<freejoint>` on a top-level body, as Cassie's pelvis) is held at its
  qpos0 pose: pinmech computes the mechanism's motion relative to its base;
* orientations, angle units, and sites or anchors on jointless bodies are misread in ways
  mjcf_frames.py lists: every orientation is written as MuJoCo's unit quaternion, every
  angle in radians, and sites and anchors moved onto the nearest body that moves;
* equality types pinmech cannot close (`joint`, `tendon`, `flex`), inactive equalities, and
  `weld` with `relpose` are refused, never dropped;
* default classes (`<default>`, `class`, `childclass`) are applied only in part (a joint's or
  a site's `pos`, a site's orientation, a geom's `mass`, `pos` and `euler` are dropped, and
  `class="main"` crashes the parser): pinmech writes every default onto its element, as
  MuJoCo resolves them, and hands Pinocchio a file without defaults;
* keywords MuJoCo refuses (active="0", angle="DEGREE", type="Hinge") and nesting deeper than
  MuJoCo reads are refused, not read another way;
* joint limits (`range`, `limited`, `autolimits`) are read as MuJoCo reads them (mjcf_limits.py)
  and checked as a URDF's `<limit>` are;
* masses the parser does not compute as MuJoCo (a mesh geom's inertia is 1 kg m², compiler
  options such as `settotalmass`) and joint damping, stiffness and friction loss (passive
  forces MuJoCo adds) become the mechanism's `force_caveats`: kinematics do not need them,
  forces refuse to run on them (`ForceSolver`).

Ball joints (nq 4, nv 3) work in loops: pinmech moves along the tangent space.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError
from pinmech.model.frame_names import frame_named
from pinmech.model.inertia_check import check_mjcf_inertias
from pinmech.model.mjcf_composite import place_composites_as_mujoco
from pinmech.model.mjcf_limits import mjcf_limits
from pinmech.model.mjcf_frames import (angles_in_radians, fromto_sites, hoist_to_moving_bodies, orientations_as_quaternions,
                                 sites_on)
from pinmech.model.mechanism import Mechanism
from pinmech.model.pinocchio_build import pinocchio_build
from pinmech.model.urdf_xml import read_xml
from pinmech.user_cache import cached_text

_CLOSE_TOL = 1e-9  # [m] gap of a connect at qpos0 read as open (parsers print 6-9 digits)
_TYPES = {"hinge": "revolute", "slide": "prismatic", "ball": "ball", "free": "free"}
WRAPPER = "pinmech_world"


def _parse(path: Path) -> ET.Element:
    """The file's XML with its defaults written out, its `euler` angles as quaternions
    and its `fromto` sites as `pos` and `quat`: what MuJoCo's compiler reads, in the
    forms Pinocchio's parser reads right."""
    root = read_xml(path, "mujoco", "MJCF")
    if root.find("include") is not None or root.find(".//include") is not None:
        raise ModelError("<include> is not supported: give pinmech the whole model in one file", path=str(path))
    _check_depth(root, str(path))
    _apply_defaults(root, str(path))
    _check_spelling(root, str(path))
    _check_names(root, str(path))
    _check_keywords(root, str(path))
    _check_numbers(root, str(path))
    check_mjcf_inertias(root, str(path))
    orientations_as_quaternions(root, str(path))
    angles_in_radians(root, str(path))
    fromto_sites(root, str(path))
    return root


def mjcf_joint_types(path: str | Path) -> dict[str, str]:
    """Joint name -> "revolute", "prismatic", "ball" or "free", read from the XML (default
    classes applied)."""
    root = _parse(Path(path))
    return {j.get("name"): _TYPES.get(j.get("type", "hinge"), "other") for j in root.iter("joint")
            if j.get("name") and j.get("type", "hinge") in _TYPES}


#: Deepest element MuJoCo's XML reader (tinyxml2) takes, the root counting 1: 496 nested bodies
MAX_DEPTH = 499


def _check_depth(root: ET.Element, source: str) -> None:
    """Elements nested no deeper than MuJoCo reads them (it refuses 'Element nesting is too
    deep'); checked without recursion, before anything recurses over the tree."""
    stack = [(root, 1)]
    while stack:
        el, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise ModelError(f"elements are nested more than {MAX_DEPTH} deep (MuJoCo refuses 'Element nesting is "
                             "too deep')", path=source, element=f"<{el.tag} name=\"{el.get('name', '')}\">")
        stack.extend((child, depth + 1) for child in el)


# ---------------------------------------------------------------- default classes
_ORIENTATION = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
#: elements of a body that take a default class, and the default element each reads
_BODY_ELEMENTS = ("joint", "geom", "site", "camera", "light")
_ASSET_ELEMENTS = ("mesh", "material", "texture", "hfield")


def _merged(base: dict[str, str], own: dict[str, str]) -> dict[str, str]:
    """Attributes `own` over `base`, MuJoCo's way: one orientation given replaces any other
    form of it, and a `fromto` replaces `pos` and the orientation."""
    out = dict(base)
    if any(k in own for k in _ORIENTATION) or "fromto" in own:
        for key in _ORIENTATION:
            out.pop(key, None)
    if "fromto" in own:
        out.pop("pos", None)
    out.update(own)
    return out


def _default_classes(root: ET.Element, source: str) -> dict[str, dict[str, dict[str, str]]]:
    """Class name -> element tag -> attributes, each class holding its ancestors' too."""
    classes: dict[str, dict[str, dict[str, str]]] = {}

    def walk(node: ET.Element, inherited: dict[str, dict[str, str]], name: str) -> None:
        if name in classes and name != "main":
            raise ModelError(f"two default classes are called \"{name}\"", path=source,
                             element=f"<default class=\"{name}\">")
        own = {tag: dict(attrs) for tag, attrs in inherited.items()}
        for child in node:
            if child.tag != "default":
                own[child.tag] = _merged(own.get(child.tag, {}), {k: v for k, v in child.attrib.items()
                                                                  if k != "class"})
        classes[name] = own
        for child in node.findall("default"):
            if not child.get("class"):
                raise ModelError("a <default> inside another needs a class name", path=source,
                                 element=f"<default class=\"{name}\"> <default>")
            walk(child, own, child.get("class"))

    classes["main"] = {}
    for top in root.findall("default"):  # several top-level ones all add to "main", as MuJoCo reads them
        if top.get("class", "main") != "main":
            raise ModelError(f"the top-level <default> is class \"main\", not \"{top.get('class')}\"",
                             path=source, element="<default>")
        walk(top, classes["main"], "main")
    return classes


def _apply_defaults(root: ET.Element, source: str) -> None:
    """Every attribute an element takes from its default class written on it (its `class`,
    else the nearest `childclass` of the bodies around it, else "main"), then the
    `<default>` elements and the class attributes removed: Pinocchio's parser then reads
    only what is written on each element."""
    classes = _default_classes(root, source)

    def resolve(el: ET.Element, name: str, tag: str) -> None:
        if name not in classes:
            raise ModelError(f"no default class \"{name}\"", path=source,
                             element=f"<{el.tag} name=\"{el.get('name', '')}\">")
        attrs = _merged(classes[name].get(tag, {}), {k: v for k, v in el.attrib.items() if k != "class"})
        el.attrib.clear()
        el.attrib.update(attrs)

    def in_body(body: ET.Element, childclass: str) -> None:
        for child in body:
            if child.tag in ("body", "frame"):
                in_body(child, child.get("childclass", childclass))
            elif child.tag in _BODY_ELEMENTS:
                resolve(child, child.get("class", childclass), child.tag)

    for world in root.findall("worldbody"):
        in_body(world, "main")
    for equality in root.findall("equality"):
        for el in equality:
            resolve(el, el.get("class", "main"), "equality")
    for asset in root.findall("asset"):
        for el in asset:
            if el.tag in _ASSET_ELEMENTS:
                resolve(el, el.get("class", "main"), el.tag)
    for top in root.findall("default"):
        root.remove(top)
    for el in root.iter():
        el.attrib.pop("class", None)
        el.attrib.pop("childclass", None)


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


def _equalities(root: ET.Element, source: str) -> tuple[list[str], list[str], list[ET.Element]]:
    """Names of the connects and welds, in file order; refuse what pinmech cannot close."""
    connects, welds, elements = [], [], []
    for eq in root.findall("equality"):
        for el in eq:
            where = f"<equality><{el.tag} name=\"{el.get('name', '')}\">"
            if el.tag not in ("connect", "weld"):
                raise ModelError(f"<{el.tag}> equalities are not loop closures pinmech can solve (only connect "
                                 "and weld): remove it or lock the joints it couples", path=source, element=where)
            if el.get("active", "true") == "false":
                raise ModelError("an inactive equality (active=\"false\") is neither a loop nor nothing: remove it "
                                 "or make it active", path=source, element=where)
            if el.tag == "weld" and el.get("relpose") is not None:
                raise ModelError(f"relpose=\"{el.get('relpose')}\" is not read by Pinocchio's parser: remove it and "
                                 "assemble the weld at qpos0", path=source, element=where)
            names = connects if el.tag == "connect" else welds
            names.append(el.get("name") or f"{el.tag}{len(names) + 1}")
            elements.append(el)
    return connects, welds, elements


def _wrapped(root: ET.Element, source: str) -> Path:
    """The file with every top-level body under one fixed wrapper body at the origin (cached)."""
    world = root.find("worldbody")
    if world is None:
        raise ModelError("no <worldbody>", path=source)
    bodies = world.findall("body")
    if not bodies:
        raise ModelError("<worldbody> has no <body>: nothing moves", path=source)
    if any(b.get("name") == WRAPPER for b in root.iter("body")):
        raise ModelError(f"a body is called {WRAPPER}, the name pinmech gives its wrapper", path=source)
    compiler = root.find("compiler")  # (angles_in_radians made one)
    folder_of = Path(source).resolve().parent
    for key in ("meshdir", "texturedir", "assetdir"):  # the copy lives elsewhere: absolute folders
        compiler.set(key, str(folder_of / compiler.get(key, "")) + os.sep)
    wrapper = ET.Element("body", {"name": WRAPPER})
    for body in bodies:  # a floating base is held where qpos0 puts it: motion relative to it
        for joint in body.findall("freejoint") + [j for j in body.findall("joint") if j.get("type") == "free"]:
            body.remove(joint)

        world.remove(body)
        wrapper.append(body)
    for site in world.findall("site"):  # a site of the world is one of the wrapper at the origin
        world.remove(site)
        wrapper.append(site)
    world.append(wrapper)
    for eq in root.findall("equality"):  # Pinocchio knows no body "world": the wrapper is fixed to it
        for el in eq:
            if el.get("site1") is None:
                for key in ("body1", "body2"):
                    if el.get(key) in (None, "world"):
                        el.set(key, WRAPPER)
    hoist_to_moving_bodies(root, wrapper, source)
    return cached_text("mjcf", ".xml", ET.tostring(root, encoding="unicode"))  # read back only if it is ours


def _build(path: Path, source: str) -> tuple[pin.Model, list, list]:
    model, points, frames = pinocchio_build(lambda: pin.buildModelAndConstraintsFromMJCF(str(path)), source)
    return model, list(points), list(frames)


def load_mjcf(path: str | Path, *, locked: dict[str, float] | None = None) -> Mechanism:
    """An MJCF file as a Mechanism: `<connect>` -> spherical cuts, `<weld>` -> fixed cuts.

    The reference configuration is MuJoCo's qpos0 (joint `ref` values), where the loops close.

    Raises:
        ModelError: a malformed file, an equality pinmech cannot close, a connect whose sites
            do not meet at qpos0, a tree Pinocchio cannot build, a locked ball joint.
    """
    path = Path(path)
    source = str(path)
    root = _parse(path)
    connects, welds, elements = _equalities(root, source)
    if root.find("worldbody") is not None and root.find("worldbody").find(".//frame") is not None:
        raise ModelError("Pinocchio's parser drops a <frame> with every body in it: write those bodies without "
                         "the <frame> (its pos and orientation composed into theirs)", path=source,
                         element="<worldbody> <frame>")
    wrapped = _wrapped(root, source)
    model, points, frames = _build(wrapped, source)
    _check_everything_read(root, model, source)
    place_composites_as_mujoco(model, points + frames, root, source)
    _add_fixed_sites(model, root, source)
    if len(points) != len(connects) or len(frames) != len(welds):
        raise ModelError(f"Pinocchio read {len(points)} connect and {len(frames)} weld constraints, the file has "
                         f"{len(connects)} and {len(welds)}", path=source, element="<equality>")
    qpos0 = _qpos0(model)
    mech = Mechanism.from_model(model, points + frames, names=connects + welds, source=source,
                                reference=qpos0, urdf_path=str(wrapped))
    _check_sites(mech, elements, source)
    _check_closed(mech, source)
    if locked:  # checked as drawn; then the joints the scene holds are locked out
        mech = Mechanism.from_model(model, points + frames, names=connects + welds, source=source,
                                    reference=qpos0, urdf_path=str(wrapped), locked=locked)
    mech.force_caveats = mech.force_caveats + _force_caveats(root)
    mech.limits = {n: lu for n, lu in mjcf_limits(root, source).items() if n in mech.joints or n in mech.locked}
    return mech


_DOFS = {"hinge": 1, "slide": 1, "ball": 3}


def _check_everything_read(root: ET.Element, model: pin.Model, source: str) -> None:
    """Every named body and every joint freedom of the file is in Pinocchio's model."""
    bodies = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    for body in root.find("worldbody").iter("body"):
        name = body.get("name")
        if name and name not in bodies:
            raise ModelError("Pinocchio's parser left this body out of the model", path=source,
                             element=f"<body name=\"{name}\">")
    freedoms = sum(_DOFS.get(j.get("type", "hinge"), 0) for j in root.find("worldbody").iter("joint"))
    unnamed = [b for b in root.find("worldbody").iter("body") if not b.get("name") and b.find("joint") is not None]
    if freedoms != model.nv and unnamed:
        raise ModelError("a body with joints has no name, and Pinocchio's parser leaves such a body's joints out: "
                         "name it", path=source, element=f"<body> of <joint name=\"{unnamed[0].find('joint').get('name', '')}\">")
    if freedoms != model.nv:  # (default classes are written out: every type is on its joint)
        raise ModelError(f"the file's joints have {freedoms} freedoms, Pinocchio's model {model.nv}", path=source,
                         element="<joint>")


def _add_fixed_sites(model: pin.Model, root: ET.Element, source: str) -> None:
    """The sites that never move (of the world, or on jointless bodies hung from it), which
    Pinocchio's parser drops, as frames of the wrapper body (in place)."""
    wrapper = next(b for b in root.find("worldbody").findall("body") if b.get("name") == WRAPPER)
    parent = model.getFrameId(WRAPPER, pin.FrameType.BODY)
    for name, pos, rotation in sites_on(wrapper, source):
        if not any(f.name == name and f.type == pin.FrameType.OP_FRAME for f in model.frames):
            model.addFrame(pin.Frame(name, 0, parent, pin.SE3(rotation, pos), pin.FrameType.OP_FRAME))


def _qpos0(model: pin.Model) -> np.ndarray:
    """MuJoCo's qpos0 as Pinocchio's parser stores it (joint `ref` values), else neutral."""
    configs = model.referenceConfigurations
    if "qpos0" in configs:
        return np.array(configs["qpos0"], dtype=float)
    return pin.neutral(model)


def _check_sites(mech: Mechanism, elements: list[ET.Element], source: str) -> None:
    """A connect between two sites must have them coincide at qpos0, or it is another linkage."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    for el in elements:
        site1, site2 = el.get("site1"), el.get("site2")
        if el.tag != "connect" or not (site1 and site2):
            continue
        ids = [frame_named(mech.model, s, (pin.FrameType.OP_FRAME,), source) for s in (site1, site2)]
        if None in ids:
            raise ModelError(f"site1/site2 {site1}, {site2} are not both sites Pinocchio read", path=source,
                             element=f"<connect name=\"{el.get('name', '')}\">")
        gap = float(np.linalg.norm(data.oMf[ids[0]].translation - data.oMf[ids[1]].translation))
        if gap > _CLOSE_TOL * max(1.0, mech.length_scale):
            raise ModelError(f"sites {site1} and {site2} are {gap:.6g} m apart at qpos0; Pinocchio's parser joins "
                             "the points that coincide at qpos0, so the loop would close elsewhere than MuJoCo's: "
                             "assemble the model at qpos0 (joint ref values)", path=source,
                             element=f"<connect name=\"{el.get('name', '')}\">")


def _check_closed(mech: Mechanism, source: str) -> None:
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    for closure in mech.closures:
        gap = float(np.max(np.abs(closure.residual(data)), initial=0.0))
        if gap > _CLOSE_TOL:
            raise ModelError(f"the loop {closure.name} is open by {gap:.3g} (of the size {mech.length_scale:.4g} m) "
                             "at qpos0 as Pinocchio read it", path=source, element=f"<equality> {closure.name}")


def mjcf_visuals(path: str | Path, model: pin.Model) -> pin.GeometryModel:
    """The visual geometry of an MJCF file (the wrapped one the model was built from)."""
    return pin.buildGeomFromMJCF(model, str(path), pin.GeometryType.VISUAL)
