"""Masses and inertia tensors that no body has, wherever they enter.

A body's rotational inertia about its centre of mass is a symmetric tensor whose principal
moments A, B, C are not negative and satisfy the triangle inequality A + B >= C (each is a
sum of m (y^2 + z^2)-like terms); a mass is not negative. Pinocchio takes any numbers, and
forces then came out finite and wrong. Kinematics do not use masses, so a URDF's or a
model's impossible inertia becomes one of the mechanism's `force_caveats` (naming the link
and the numbers): `ForceSolver` refuses to run on it. An MJCF `<inertial>` that MuJoCo's
compiler refuses is refused when the file is read, as MuJoCo refuses it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError

#: Relative slack on the moments [of the largest one]: files print inertias to about six
#: significant digits, so a flat plate's exact A + B = C is off by ~1e-6 after rounding.
ROUNDING = 1e-6


def inertia_problem(mass: float, tensor: np.ndarray, slack: float = 0.0) -> str | None:
    """Why a mass [kg] and a rotational inertia about the centre of mass [kg m^2] (3 x 3)
    belong to no body, or None when they do; `slack` [kg m^2] is added to the rounding allowed."""
    tensor = np.asarray(tensor, dtype=float)
    if not (np.isfinite(mass) and np.all(np.isfinite(tensor))):
        return f"mass {mass:g} kg and inertia {np.round(tensor, 12).tolist()} kg m^2 are not all finite"
    if mass < 0:
        return f"a mass of {mass:g} kg: a mass must be a positive number (or zero for a massless link)"
    scale = float(np.max(np.abs(tensor), initial=0.0))
    allowed = ROUNDING * scale + slack
    if not np.allclose(tensor, tensor.T, rtol=0, atol=allowed):
        return f"the inertia tensor {tensor.tolist()} kg m^2 is not symmetric"
    moments = np.linalg.eigvalsh((tensor + tensor.T) / 2)
    said = ", ".join(f"{m:.6g}" for m in moments)
    if moments[0] < -allowed:
        return f"principal moments of inertia ({said}) kg m^2: a negative moment (the tensor is not positive)"
    if moments[0] + moments[1] < moments[2] - allowed:
        return (f"principal moments of inertia ({said}) kg m^2 break the triangle inequality: "
                f"{moments[0]:.6g} + {moments[1]:.6g} < {moments[2]:.6g}, which no body has")
    return None


def model_inertia_caveats(model: pin.Model) -> list[str]:
    """What is impossible about every joint's inertia (the bodies it carries) and every
    frame's own inertia, naming the body or frame and the numbers. The joint's inertia is a
    sum Pinocchio computed, so its rounding (about eps m r^2 of the parts) is allowed for by
    1e-14 m kg m^2 (parts within 7 m of the centre)."""
    out = []
    for jid in range(1, model.njoints):
        inertia = model.inertias[jid]
        problem = inertia_problem(inertia.mass, inertia.inertia, slack=1e-14 * abs(inertia.mass))
        if problem:
            body = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == jid),
                        model.names[jid])
            out.append(f"body {body} (moved by joint {model.names[jid]}): {problem}")
    for frame in model.frames:
        problem = inertia_problem(frame.inertia.mass, frame.inertia.inertia, slack=1e-14 * abs(frame.inertia.mass))
        if problem:
            out.append(f"frame {frame.name}: {problem}")
    return out


def _floats(el: ET.Element, keys: tuple[str, ...], where: str, source: str) -> list[float]:
    try:
        return [float(el.get(k, "0")) for k in keys]
    except ValueError:
        raise ModelError(f"{', '.join(f'{k}={el.get(k)!r}' for k in keys)} are not all numbers", path=source,
                         element=where) from None


def urdf_inertia_caveats(root: ET.Element, source: str) -> list[str]:
    """What is impossible about each link's `<inertial>` (`<mass value>`, `<inertia ixx .. izz>`),
    naming the link and the numbers.

    Raises:
        ModelError: a value that is not a number.
    """
    out = []
    for link in root.iter("link"):
        for inertial in link.findall("inertial"):
            where = f"<link name=\"{link.get('name', '')}\"> <inertial>"
            mass_el, tensor_el = inertial.find("mass"), inertial.find("inertia")
            mass = _floats(mass_el, ("value",), where, source)[0] if mass_el is not None else 0.0
            xx, xy, xz, yy, yz, zz = (_floats(tensor_el, ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), where, source)
                                      if tensor_el is not None else [0.0] * 6)
            problem = inertia_problem(mass, np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
            if problem:
                out.append(f"{where}: {problem}; correct it (kinematics do not need it, forces do)")
    return out


def check_mjcf_inertias(root: ET.Element, source: str) -> None:
    """Every body's `<inertial>`: `mass` with `diaginertia` or `fullinertia` (xx yy zz xy xz yz).

    Raises:
        ModelError: naming the body and the numbers.
    """
    for body in root.iter("body"):
        for inertial in body.findall("inertial"):
            where = f"<body name=\"{body.get('name', '')}\"> <inertial>"
            mass = _floats(inertial, ("mass",), where, source)[0]
            if inertial.get("fullinertia") is not None:
                xx, yy, zz, xy, xz, yz = (float(v) for v in inertial.get("fullinertia").split())
                tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
            elif inertial.get("diaginertia") is not None:
                tensor = np.diag([float(v) for v in inertial.get("diaginertia").split()])
            else:
                tensor = np.zeros((3, 3))
            problem = inertia_problem(mass, tensor)
            if problem:
                raise ModelError(f"{problem} (MuJoCo refuses it)", path=source, element=where)
