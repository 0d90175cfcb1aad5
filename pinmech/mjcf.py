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
* an `axisangle` axis that is not of unit length is used as is (MuJoCo normalises it): pinmech
  normalises every one before parsing;
* equality types pinmech cannot close (`joint`, `tendon`, `flex`), inactive equalities, and
  `weld` with `relpose` are refused, never dropped;
* default classes (`<default>`, `class`, `childclass`) are applied only in part (a joint's or
  a site's `pos`, a site's orientation, a geom's `mass`, `pos` and `euler` are dropped, and
  `class="main"` crashes the parser): pinmech writes every default onto its element, as
  MuJoCo resolves them, and hands Pinocchio a file without defaults;
* `euler` under an `eulerseq` with upper-case (extrinsic) axes is misread (4 degrees off for
  euler="0.1 0.2 0.3" rad): pinmech turns every `euler` into the quaternion MuJoCo computes;
* a site given by `fromto` keeps its body's axes (MuJoCo turns its z axis along fromto):
  pinmech writes it as `pos` and `quat`;
* masses the parser does not compute as MuJoCo (a mesh geom's inertia is 1 kg m², compiler
  options such as `settotalmass`) and joint damping, stiffness and friction loss (passive
  forces MuJoCo adds) become the mechanism's `force_caveats`: kinematics do not need them,
  forces refuse to run on them (`ForceSolver`).

Ball joints (nq 4, nv 3) work in loops: pinmech moves along the tangent space.
"""

from __future__ import annotations

import hashlib
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinmech.directions import unit_vector
from pinmech.exceptions import ModelError
from pinmech.mechanism import Mechanism, pinocchio_build, read_xml

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
    _apply_defaults(root, str(path))
    _check_spelling(root, str(path))
    _check_numbers(root, str(path))
    _eulers_as_quaternions(root, str(path))
    _fromto_sites(root, str(path))
    return root


def mjcf_joint_types(path: str | Path) -> dict[str, str]:
    """Joint name -> "revolute", "prismatic", "ball" or "free", read from the XML (default
    classes applied)."""
    root = _parse(Path(path))
    return {j.get("name"): _TYPES.get(j.get("type", "hinge"), "other") for j in root.iter("joint")
            if j.get("name") and j.get("type", "hinge") in _TYPES}


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


# ---------------------------------------------------------------- orientations
def _numbers(el: ET.Element, key: str, count: int, source: str) -> list[float]:
    text = el.get(key, "")
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != count or not all(np.isfinite(values)):
        raise ModelError(f"{key}=\"{text}\" is not {count} finite numbers", path=source,
                         element=f"<{el.tag} name=\"{el.get('name', '')}\">")
    return values


def _quaternion_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a b, quaternions w x y z."""
    return np.array([a[0] * b[0] - a[1:] @ b[1:], *(a[0] * b[1:] + b[0] * a[1:] + np.cross(a[1:], b[1:]))])


def _eulers_as_quaternions(root: ET.Element, source: str) -> None:
    """Every `euler` written as the `quat` MuJoCo's compiler makes of it: for each axis of
    `eulerseq` in turn, the rotation about it multiplied on the right (a lower-case,
    moving axis) or on the left (an upper-case, fixed axis); angles in the compiler's unit."""
    sequence, degrees = "xyz", True
    for compiler in root.findall("compiler"):
        sequence = compiler.get("eulerseq", sequence)
        degrees = compiler.get("angle", "degree" if degrees else "radian") == "degree"
    if len(sequence) != 3 or any(c not in "xyzXYZ" for c in sequence):
        raise ModelError(f"eulerseq=\"{sequence}\" is not three of x, y, z, X, Y, Z", path=source,
                         element="<compiler>")
    axes = {"x": np.array([1.0, 0, 0]), "y": np.array([0, 1.0, 0]), "z": np.array([0, 0, 1.0])}
    for el in root.iter():
        if el.get("euler") is None or el.tag == "compiler":
            continue
        angles = np.array(_numbers(el, "euler", 3, source))
        if degrees:
            angles = np.radians(angles)
        q = np.array([1.0, 0, 0, 0])
        for letter, angle in zip(sequence, angles):
            turn = np.array([np.cos(angle / 2), *(np.sin(angle / 2) * axes[letter.lower()])])
            q = _quaternion_product(q, turn) if letter.islower() else _quaternion_product(turn, q)
        del el.attrib["euler"]
        el.set("quat", " ".join(repr(float(x)) for x in q))


def _z_to(vector: np.ndarray) -> np.ndarray:
    """The quaternion (w x y z) turning z onto `vector` by the shortest way, as MuJoCo's
    mju_quatZ2Vec (a half turn about x for -z)."""
    v = unit_vector(vector)
    if v is None:
        return np.array([1.0, 0, 0, 0])
    axis = np.cross([0.0, 0.0, 1.0], v)
    sine = np.linalg.norm(axis)
    if sine < 1e-15:
        return np.array([1.0, 0, 0, 0]) if v[2] > 0 else np.array([0.0, 1.0, 0, 0])
    angle = np.arctan2(sine, v[2])
    return np.array([np.cos(angle / 2), *(np.sin(angle / 2) * axis / sine)])


def _fromto_sites(root: ET.Element, source: str) -> None:
    """A site given by `fromto` sits at its middle with its z axis from its second end to
    its first (MuJoCo's compiler): written as `pos` and `quat`, which Pinocchio's parser
    reads."""
    for world in root.findall("worldbody"):
        for site in world.iter("site"):
            if site.get("fromto") is None:
                continue
            ends = np.array(_numbers(site, "fromto", 6, source))
            del site.attrib["fromto"]
            for key in _ORIENTATION:
                site.attrib.pop(key, None)
            site.set("pos", " ".join(repr(float(x)) for x in (ends[:3] + ends[3:]) / 2))
            site.set("quat", " ".join(repr(float(x)) for x in _z_to(ends[:3] - ends[3:])))


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
    _normalise_axisangles(root, source)
    compiler = root.find("compiler")
    if compiler is None:
        compiler = ET.Element("compiler")
        root.insert(0, compiler)
    folder_of = Path(source).resolve().parent
    for key in ("meshdir", "texturedir", "assetdir"):  # the copy lives elsewhere: absolute folders
        compiler.set(key, str(folder_of / compiler.get(key, "")) + os.sep)
    wrapper = ET.Element("body", {"name": WRAPPER})
    for body in bodies:  # a floating base is held where qpos0 puts it: motion relative to it
        for joint in body.findall("freejoint") + [j for j in body.findall("joint") if j.get("type") == "free"]:
            body.remove(joint)

        world.remove(body)
        wrapper.append(body)
    world.append(wrapper)
    for eq in root.findall("equality"):  # Pinocchio knows no body "world": the wrapper is fixed to it
        for el in eq:
            if el.get("site1") is None:
                for key in ("body1", "body2"):
                    if el.get(key) in (None, "world"):
                        el.set(key, WRAPPER)
    text = ET.tostring(root, encoding="unicode")
    folder = Path(tempfile.gettempdir()) / f"pinmech-{os.getuid() if hasattr(os, 'getuid') else 'user'}"
    folder.mkdir(mode=0o700, exist_ok=True)
    out = folder / f"mjcf-{hashlib.sha256((source + text).encode()).hexdigest()[:20]}.xml"
    if not out.is_file():
        tmp = out.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, out)
    return out


def _normalise_axisangles(root: ET.Element, source: str) -> None:
    """Unit axes in every `axisangle`: MuJoCo normalises them, Pinocchio's parser does not
    (axisangle="0.3 0.5 0.8 40" turns a body by a wrong rotation there, 0.15 rad off)."""
    for el in root.iter():
        text = el.get("axisangle")
        if text is None:
            continue
        try:
            x, y, z, angle = (float(v) for v in text.split())
        except ValueError:
            raise ModelError(f"axisangle=\"{text}\" is not four numbers", path=source,
                             element=f"<{el.tag} name=\"{el.get('name', '')}\">") from None
        norm = (x * x + y * y + z * z) ** 0.5
        if not norm > 0:
            raise ModelError(f"axisangle=\"{text}\" has no axis", path=source,
                             element=f"<{el.tag} name=\"{el.get('name', '')}\">")
        el.set("axisangle", f"{x / norm!r} {y / norm!r} {z / norm!r} {angle!r}")


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
    mech.force_caveats = _force_caveats(root)
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
    if freedoms != model.nv:  # (default classes are written out: every type is on its joint)
        raise ModelError(f"the file's joints have {freedoms} freedoms, Pinocchio's model {model.nv}", path=source,
                         element="<joint>")


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
        ids = [mech.model.getFrameId(s) if mech.model.existFrame(s) else None for s in (site1, site2)]
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
