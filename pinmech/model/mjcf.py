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

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError
from pinmech.model.closure_core import closure_rows
from pinmech.model.frame_names import frame_named
from pinmech.model.inertia_check import check_mjcf_inertias
from pinmech.model.mjcf_composite import place_composites_as_mujoco
from pinmech.model.mjcf_checks import (_check_keywords, _check_names, _check_numbers, _check_spelling,
                                      _force_caveats)
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


def _wrapped(root: ET.Element, source: str) -> tuple[Path, dict]:
    """The file with every top-level body under one fixed wrapper body at the origin (cached),
    and what was moved off jointless bodies (mjcf_frames.hoist_to_moving_bodies)."""
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
    written_on = hoist_to_moving_bodies(root, wrapper, source)
    return cached_text("mjcf", ".xml", ET.tostring(root, encoding="unicode")), written_on  # read back only if ours


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
    wrapped, written_on = _wrapped(root, source)
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
    mech.written_frames = _written_frames(mech, written_on, elements, connects + welds)
    mech.force_caveats = mech.force_caveats + _force_caveats(root)
    mech.limits = {n: lu for n, lu in mjcf_limits(root, source).items() if n in mech.joints or n in mech.locked}
    return mech


def _written_frames(mech: Mechanism, written_on: dict, elements: list[ET.Element], names: list[str]) -> dict:
    """("point", site) or ("cut", name, side) -> the placement [m] in its joint of the
    jointless body a site or an anchor was written on (before it was moved onto a moving one)."""
    connects = [el for el in elements if el.tag == "connect"]
    name_of = {id(el): name for el, name in zip(connects + [el for el in elements if el.tag == "weld"], names)}
    out = {}
    for key, (carrier, pos, rotation) in written_on.items():
        if carrier not in mech.links:
            continue
        placement = mech.model.frames[mech.links[carrier]].placement * pin.SE3(rotation, pos)
        out[("point", key[1]) if key[0] == "site" else ("cut", name_of[id(key[0])], key[1])] = placement
    return out


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
    rows = closure_rows(mech)
    residual = rows.residual(mech.neutral())
    for closure, at in zip(mech.closures, rows.slices):
        gap = float(np.max(np.abs(residual[at]), initial=0.0))
        if gap > _CLOSE_TOL:
            raise ModelError(f"the loop {closure.name} is open by {gap:.3g} (of the size {mech.length_scale:.4g} m) "
                             "at qpos0 as Pinocchio read it", path=source, element=f"<equality> {closure.name}")


def mjcf_visuals(path: str | Path, model: pin.Model) -> pin.GeometryModel:
    """The visual geometry of an MJCF file (the wrapped one the model was built from)."""
    return pin.buildGeomFromMJCF(model, str(path), pin.GeometryType.VISUAL)
