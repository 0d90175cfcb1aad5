"""What a URDF says about its joints beyond Pinocchio's model: `<mimic>` and `<limit>`.

Pinocchio builds `<mimic>` joints (a joint with no freedom of its own, following another:
q = multiplier * q_leader + offset) when asked; this module reads them to report their
coordinates and to lock them with their leaders, and reads the position limits that
pinmech checks solved poses against (limits.py).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from pinmech.exceptions import ModelError


@dataclass(frozen=True)
class JointLimit:
    """A joint's position limits [rad, or m when not angular], and the element of the model
    file that states them (`element`, as a message names it: "URDF <limit>", "MJCF range")."""

    lower: float
    upper: float
    angular: bool
    element: str = "URDF <limit>"


@dataclass(frozen=True)
class MimicJoint:
    """A URDF `<mimic>` joint: its coordinate is `multiplier * q_leader + offset`, and its
    rates follow [rad or m, and per second]. Pinocchio builds it as a joint with no
    degree of freedom of its own, so every position, Jacobian and rate honours it."""

    name: str
    leader: str
    multiplier: float
    offset: float
    kind: str  # the URDF type of the follower: "revolute", "continuous" or "prismatic"


def joint_limits(root: ET.Element, source: str) -> dict[str, JointLimit]:
    """Position limits `<limit lower="..." upper="..."/>` of revolute and prismatic joints
    (a continuous joint has none; a bound left out is no bound).

    Raises:
        ModelError: a bound that is not a number, or lower > upper.
    """
    out = {}
    for joint in root.findall("joint"):
        element = joint.find("limit")
        if element is None or joint.get("type") not in ("revolute", "prismatic"):
            continue
        if element.get("lower") is None and element.get("upper") is None:
            continue
        where = f"<joint name=\"{joint.get('name')}\"> <limit>"
        bounds = []
        for key, default in (("lower", "-inf"), ("upper", "inf")):
            try:
                bounds.append(float(element.get(key, default)))
            except ValueError:
                raise ModelError(f"{key}=\"{element.get(key)}\" is not a number", path=source, element=where) from None
        if not bounds[0] <= bounds[1]:
            raise ModelError(f"lower=\"{element.get('lower')}\" is above upper=\"{element.get('upper')}\"",
                             path=source, element=where)
        out[joint.get("name")] = JointLimit(bounds[0], bounds[1], joint.get("type") == "revolute")
    return out


def mimic_joints(root: ET.Element, source: str) -> dict[str, MimicJoint]:
    """The joints with a `<mimic joint="..." multiplier="..." offset="..."/>` element.

    Raises:
        ModelError: a leader that is not a one-dof joint of the file, itself a follower,
            or numbers that are not finite.
    """
    types = {j.get("name"): j.get("type") for j in root.findall("joint")}
    out = {}
    for joint in root.findall("joint"):
        element = joint.find("mimic")
        if element is None or joint.get("type") not in ("revolute", "continuous", "prismatic"):
            continue  # a fixed joint has no coordinate to follow with (Talos's grippers)
        name, leader = joint.get("name"), element.get("joint")
        where = f"<joint name=\"{name}\"> <mimic>"
        numbers = {}
        for key, default in (("multiplier", "1"), ("offset", "0")):
            try:
                numbers[key] = float(element.get(key, default))
            except ValueError:
                numbers[key] = float("nan")
            if not np.isfinite(numbers[key]):
                raise ModelError(f"{key}=\"{element.get(key)}\" is not a finite number", path=source, element=where)
        if leader == name or types.get(leader) not in ("revolute", "continuous", "prismatic"):
            raise ModelError(f"joint=\"{leader}\" is not another revolute or prismatic joint of the file",
                             path=source, element=where)
        if "continuous" in (types.get(name), types.get(leader)):
            raise ModelError(f"'{name if types.get(name) == 'continuous' else leader}' is a continuous joint (its "
                             "configuration is cos, sin): Pinocchio cannot make one follow another; declare both "
                             "revolute (with <limit>) or prismatic", path=source, element=where)
        out[name] = MimicJoint(name, leader, numbers["multiplier"], numbers["offset"], str(types.get(name)))
    for m in out.values():
        if m.leader in out:
            raise ModelError(f"follows '{m.leader}', which itself follows '{out[m.leader].leader}': "
                             "make both follow the same joint", path=source, element=f"<joint name=\"{m.name}\"> <mimic>")
    return out


def with_followers(locked: dict[str, float], mimics: dict[str, MimicJoint], source: str) -> dict[str, float]:
    """Locked joints, with every follower of a locked leader locked where it must be.

    Raises:
        ModelError: a follower locked while its leader moves, or locked at another value
            than its leader gives.
    """
    for m in mimics.values():
        follows = m.multiplier * locked[m.leader] + m.offset if m.leader in locked else None
        if m.name in locked and follows is None:
            raise ModelError(f"joint '{m.name}' follows '{m.leader}' (URDF <mimic>) and cannot be locked while "
                             f"{m.leader} moves: lock {m.leader} instead", path=source)
        if m.name in locked and abs(locked[m.name] - follows) > 1e-9 * max(1.0, abs(follows)):
            raise ModelError(f"joint '{m.name}' is locked at {locked[m.name]:.9g} but follows '{m.leader}' "
                             f"(URDF <mimic>): {m.multiplier:g} x {locked[m.leader]:.9g} + {m.offset:g} = "
                             f"{follows:.9g}", path=source)
        if follows is not None:
            locked[m.name] = follows
    return locked
