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
  `weld` with `relpose` are refused, never dropped.

Ball joints (nq 4, nv 3) work in loops: pinmech moves along the tangent space.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError
from pinmech.mechanism import Mechanism, pinocchio_build, read_xml

_CLOSE_TOL = 1e-9  # [m] gap of a connect at qpos0 read as open (parsers print 6-9 digits)
_TYPES = {"hinge": "revolute", "slide": "prismatic", "ball": "ball", "free": "free"}
WRAPPER = "pinmech_world"


def _parse(path: Path) -> ET.Element:
    root = read_xml(path, "mujoco", "MJCF")
    if root.find("include") is not None or root.find(".//include") is not None:
        raise ModelError("<include> is not supported: give pinmech the whole model in one file", path=str(path))
    return root


def mjcf_joint_types(path: str | Path) -> dict[str, str]:
    """Joint name -> "revolute", "prismatic", "ball" or "free", read from the XML."""
    root = _parse(Path(path))
    return {j.get("name"): _TYPES.get(j.get("type", "hinge"), "other") for j in root.iter("joint")
            if j.get("name") and j.get("type", "hinge") in _TYPES}


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
    typed_defaults = any(j.get("type") for d in root.findall("default") for j in d.iter("joint"))
    freedoms = sum(_DOFS.get(j.get("type", "hinge"), 0) for j in root.find("worldbody").iter("joint"))
    if not typed_defaults and freedoms != model.nv:  # (a default class may set a joint's type)
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
