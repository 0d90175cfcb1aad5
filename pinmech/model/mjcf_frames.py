"""MJCF placements as MuJoCo's compiler makes them, in the forms Pinocchio's parser reads right.

Pinocchio's MJCF parser reads `pos` and a unit `quat` correctly; its own readings of the
other forms and of nested bodies are where it departs from MuJoCo. So before parsing:

* every orientation (`quat`, `axisangle`, `euler`, `xyaxes`, `zaxis`) of a body, site, geom
  or inertial is written as the unit quaternion MuJoCo's compiler makes of it, and what
  MuJoCo refuses is refused here with the element and the numbers: two orientations on one
  element, a zero quaternion, a zero axis, parallel `xyaxes`;
* angles (`axisangle`, `euler`, a hinge's `ref`, `springref` and `range`, a ball's `range`)
  are turned into radians, and the compiler told so; `angle` is "degree" or "radian" only,
  as MuJoCo reads it (case-sensitive);
* a site on a body without joints is moved onto the nearest body that moves, and a connect
  or weld naming such a body names that one instead, their placements composed: Pinocchio's
  parser places a site two or more jointless bodies below a joint as if only the innermost
  offset applied (a site 50 mm out put at 1 mm), and a connect's anchor on any jointless
  body as if the body sat on its joint (another linkage). Bodies stay where they are;
* a site given by `fromto` is written as `pos` and `quat` (MuJoCo turns its z axis along it).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from pinmech.directions import unit_vector

from pinmech.exceptions import ModelError

ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
_TURNED = ("body", "site", "geom", "inertial", "camera", "light")
_EPS = 1e-14  # MuJoCo's mjEPS: a vector shorter than this is "too small" (user_util.cc)
_ANGLES = ("degree", "radian")


def where(el: ET.Element) -> str:
    return f"<{el.tag} name=\"{el.get('name', '')}\">"


def numbers(el: ET.Element, key: str, count: int, source: str) -> np.ndarray:
    """The `count` finite numbers of an attribute, else a ModelError naming the element."""
    text = el.get(key, "")
    try:
        values = np.array([float(v) for v in text.split()])
    except ValueError:
        values = np.array([])
    if values.shape != (count,) or not np.all(np.isfinite(values)):
        raise ModelError(f"{key}=\"{text}\" is not {count} finite numbers", path=source, element=where(el))
    return values


def compiler_units(root: ET.Element, source: str) -> tuple[bool, str]:
    """(angles in degrees?, eulerseq) of the file's `<compiler>` (the last one that says).

    Raises:
        ModelError: an `angle` other than "degree" or "radian" (MuJoCo refuses "DEGREE"),
            an `eulerseq` that is not three of x, y, z, X, Y, Z.
    """
    degrees, sequence = True, "xyz"
    for compiler in root.findall("compiler"):
        angle = compiler.get("angle")
        if angle is not None and angle not in _ANGLES:
            raise ModelError(f"angle=\"{angle}\" is not \"degree\" or \"radian\" (MuJoCo reads these keywords "
                             "only, in lower case)", path=source, element="<compiler>")
        degrees = degrees if angle is None else angle == "degree"
        sequence = compiler.get("eulerseq", sequence)
    if len(sequence) != 3 or any(c not in "xyzXYZ" for c in sequence):
        raise ModelError(f"eulerseq=\"{sequence}\" is not three of x, y, z, X, Y, Z", path=source,
                         element="<compiler>")
    return degrees, sequence


# ---------------------------------------------------------------- quaternions (w x y z)
def _product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a b, quaternions w x y z."""
    return np.array([a[0] * b[0] - a[1:] @ b[1:], *(a[0] * b[1:] + b[0] * a[1:] + np.cross(a[1:], b[1:]))])


def _rotation(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of a unit quaternion w x y z."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _from_matrix(R: np.ndarray) -> np.ndarray:
    """The unit quaternion (w >= 0) of a rotation matrix (Shepperd's method, MuJoCo's mju_mat2Quat)."""
    trace = np.trace(R)
    if trace > 0:
        s = 2 * np.sqrt(1 + trace)
        q = np.array([s / 4, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s])
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2 * np.sqrt(1 + R[i, i] - R[j, j] - R[k, k])
        q = np.zeros(4)
        q[0] = (R[k, j] - R[j, k]) / s
        q[1 + i], q[1 + j], q[1 + k] = s / 4, (R[j, i] + R[i, j]) / s, (R[k, i] + R[i, k]) / s
    return q / np.linalg.norm(q)


def z_to(vector: np.ndarray) -> np.ndarray:
    """The quaternion turning z onto `vector` by the shortest way, as MuJoCo's mjuu_z2quat
    (a half turn about x for -z)."""
    axis = np.cross([0.0, 0.0, 1.0], vector)
    sine = np.linalg.norm(axis)
    axis = np.array([1.0, 0, 0]) if sine < 1e-10 else axis / sine
    angle = np.arctan2(sine, vector[2])
    return np.array([np.cos(angle / 2), *(np.sin(angle / 2) * axis)])


def _too_small(el: ET.Element, key: str, what: str, source: str) -> ModelError:
    return ModelError(f"{key}=\"{el.get(key)}\": {what} (MuJoCo refuses it: no rotation is defined)",
                      path=source, element=where(el))


def _quaternion(el: ET.Element, key: str, degrees: bool, sequence: str, source: str) -> np.ndarray:
    """The unit quaternion MuJoCo's compiler makes of one orientation attribute."""
    if key == "quat":
        q = unit_vector(numbers(el, key, 4, source))  # MuJoCo refuses only the zero quaternion
        if q is None:
            raise _too_small(el, key, "a zero quaternion", source)
        return q
    if key == "axisangle":
        values = numbers(el, key, 4, source)
        axis, angle = values[:3], np.radians(values[3]) if degrees else values[3]
        if not np.linalg.norm(axis) >= _EPS:
            raise _too_small(el, key, "the axis has no length", source)
        return np.array([np.cos(angle / 2), *(np.sin(angle / 2) * unit_vector(axis))])
    if key == "zaxis":
        z = numbers(el, key, 3, source)
        if not np.linalg.norm(z) >= _EPS:
            raise _too_small(el, key, "the z axis has no length", source)
        return z_to(unit_vector(z))
    if key == "xyaxes":
        values = numbers(el, key, 6, source)
        x, y = values[:3], values[3:]
        if not np.linalg.norm(x) >= _EPS:
            raise _too_small(el, key, "the x axis has no length", source)
        x = unit_vector(x)
        y = y - x * (x @ y)  # y made orthogonal to x, as MuJoCo does
        if not np.linalg.norm(y) >= _EPS:
            raise _too_small(el, key, "the y axis is parallel to the x axis (or has no length)", source)
        y = unit_vector(y)
        return _from_matrix(np.column_stack([x, y, np.cross(x, y)]))
    angles = numbers(el, key, 3, source)  # euler: each axis of eulerseq in turn, moving (lower) or fixed (upper)
    angles = np.radians(angles) if degrees else angles
    q = np.array([1.0, 0, 0, 0])
    for letter, angle in zip(sequence, angles):
        turn = np.zeros(4)
        turn[0], turn[1 + "xyz".index(letter.lower())] = np.cos(angle / 2), np.sin(angle / 2)
        q = _product(q, turn) if letter.islower() else _product(turn, q)
    return q


def _text(values) -> str:
    return " ".join(repr(float(x)) for x in values)


def orientations_as_quaternions(root: ET.Element, source: str) -> None:
    """Every orientation of a body, site, geom or inertial written as MuJoCo's unit `quat`.

    Raises:
        ModelError: two orientations on one element, a site with both `pos` and `fromto`,
            a degenerate orientation (a zero quaternion or axis, parallel `xyaxes`).
    """
    degrees, sequence = compiler_units(root, source)
    for world in root.findall("worldbody"):
        for el in world.iter():
            if el.tag not in _TURNED:
                continue
            given = [k for k in ORIENTATIONS if el.get(k) is not None]
            if len(given) > 1:
                said = " and ".join(f'{k}="{el.get(k)}"' for k in given)
                raise ModelError(f"{said} both orient it: MuJoCo "
                                 "refuses several orientations on one element; keep one", path=source,
                                 element=where(el))
            if el.tag == "site" and el.get("fromto") is not None and el.get("pos") is not None:
                raise ModelError(f"pos=\"{el.get('pos')}\" and fromto=\"{el.get('fromto')}\" both place it: "
                                 "MuJoCo refuses that; keep one", path=source, element=where(el))
            if given and not (el.tag == "geom" and el.get("fromto") is not None):
                q = _quaternion(el, given[0], degrees, sequence, source)
                del el.attrib[given[0]]
                el.set("quat", _text(q))


def angles_in_radians(root: ET.Element, source: str) -> None:
    """Every joint angle (a hinge's `ref`, `springref` and `range`, a ball's `range`) in
    radians, and every `<compiler>` told angle="radian" (orientations are quaternions by then)."""
    degrees, _ = compiler_units(root, source)
    for world in root.findall("worldbody"):
        for joint in world.iter("joint"):
            kind = joint.get("type", "hinge")
            keys = ("ref", "springref", "range") if kind == "hinge" else ("range",) if kind == "ball" else ()
            for key in keys:
                if joint.get(key) is not None and degrees:
                    values = numbers(joint, key, 2 if key == "range" else 1, source)
                    joint.set(key, _text(np.radians(values)))
    compilers = root.findall("compiler") or [ET.Element("compiler")]
    if compilers[0] not in list(root):
        root.insert(0, compilers[0])
    for compiler in compilers:
        compiler.set("angle", "radian")


def fromto_sites(root: ET.Element, source: str) -> None:
    """A site given by `fromto` sits at its middle with its z axis from its second end to
    its first (MuJoCo's compiler): written as `pos` and `quat`."""
    for world in root.findall("worldbody"):
        for site in world.iter("site"):
            if site.get("fromto") is None:
                continue
            ends = numbers(site, "fromto", 6, source)
            del site.attrib["fromto"]
            site.attrib.pop("quat", None)
            site.set("pos", _text((ends[:3] + ends[3:]) / 2))
            site.set("quat", _text(z_to(ends[:3] - ends[3:])))


# ---------------------------------------------------------------- sites and anchors on jointless bodies
def _moves(body: ET.Element) -> bool:
    return body.find("joint") is not None or body.find("freejoint") is not None


def _pose(el: ET.Element, source: str) -> tuple[np.ndarray, np.ndarray]:
    """An element's (pos, quat) in its body's frame (orientations are quaternions by then)."""
    pos = numbers(el, "pos", 3, source) if el.get("pos") is not None else np.zeros(3)
    quat = numbers(el, "quat", 4, source) if el.get("quat") is not None else np.array([1.0, 0, 0, 0])
    return pos, quat


def _carrier(body: ET.Element, top: ET.Element, parent_of: dict, source: str):
    """The nearest body at or above `body` that moves (or `top`), and `body`'s pose in it."""
    pos, quat = np.zeros(3), np.array([1.0, 0, 0, 0])
    while body is not top and body.tag == "body" and not _moves(body):
        p, r = _pose(body, source)
        pos, quat = p + _rotation(r) @ pos, _product(r, quat)
        body = parent_of[body]
    return body, pos, quat


def hoist_to_moving_bodies(root: ET.Element, top: ET.Element, source: str) -> dict:
    """Sites, and the bodies a connect or weld names, moved from bodies without joints onto
    the nearest body that moves (or `top`, the world's wrapper), their placements composed:
    Pinocchio's parser places a site two or more jointless bodies below a joint, and a
    connect anchor on any jointless body, as if the bodies between had no offset.

    Returns: what was written on a jointless body, by ("site", name) or (equality element,
    "parent" or "child": the side its anchor is on): (the moving body's name, the jointless
    body's pos [m] and rotation (3, 3) in it), the frame a study reads the site's or the
    anchor's pos in."""
    parent_of = {child: parent for parent in root.iter() for child in parent}
    bodies = {b.get("name"): b for b in root.iter("body") if b.get("name")}
    written_on = {}
    for site in [s for s in root.iter("site")]:
        body = parent_of[site]
        carrier, pos, quat = _carrier(body, top, parent_of, source)
        if carrier is body:
            continue
        p, r = _pose(site, source)
        site.set("pos", _text(pos + _rotation(quat) @ p))
        site.set("quat", _text(_product(quat, r)))
        body.remove(site)
        carrier.append(site)
        written_on[("site", site.get("name"))] = (carrier.get("name"), pos, _rotation(quat))
    for equality in root.findall("equality"):
        for el in equality:
            for key in ("body1", "body2"):
                body = bodies.get(el.get(key))
                if body is None:
                    continue
                carrier, pos, quat = _carrier(body, top, parent_of, source)
                if carrier is body:
                    continue
                if (el.tag, key) in (("connect", "body1"), ("weld", "body2")):  # the anchor is in this body's frame
                    anchor = numbers(el, "anchor", 3, source) if el.get("anchor") is not None else np.zeros(3)
                    el.set("anchor", _text(pos + _rotation(quat) @ anchor))
                    side = "parent" if key == "body1" else "child"
                    written_on[(el, side)] = (carrier.get("name"), pos, _rotation(quat))
                el.set(key, carrier.get("name"))
    return written_on


def sites_on(top: ET.Element, source: str) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, pos [m], rotation matrix) of each named site carried by `top` (the world's wrapper
    at the origin): sites that never move, which Pinocchio's parser drops."""
    out = []
    for site in top.findall("site"):
        if site.get("name"):
            pos, quat = _pose(site, source)
            out.append((site.get("name"), pos, _rotation(quat)))
    return out
