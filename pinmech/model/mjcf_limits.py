"""MJCF joint limits (`range`, `limited`, `<compiler autolimits>`) as MuJoCo's compiler reads them.

A hinge or slide joint is limited when `limited="true"`, or when `limited="auto"` (the
default) and it has a `range` while `autolimits` is on (MuJoCo's default); a `range` with
`limited="auto"` and autolimits off is refused, as MuJoCo refuses it. A ball joint's `range`
is "0 max": the largest angle it may turn [rad]. Angles are in radians by the time this
reads them (mjcf_frames.angles_in_radians); slides are in metres.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from pinmech.exceptions import ModelError
from pinmech.model.mjcf_frames import numbers, where
from pinmech.model.urdf_joints import JointLimit


def _autolimits(root: ET.Element) -> bool:
    on = True
    for compiler in root.findall("compiler"):
        on = compiler.get("autolimits", "true" if on else "false") == "true"
    return on


def mjcf_limits(root: ET.Element, source: str) -> dict[str, JointLimit]:
    """Joint name -> limits [rad or m] of the limited hinge, slide and ball joints.

    Raises:
        ModelError: a range that is not two numbers, lower not below upper on a limited joint,
            a ball's range not starting at 0, a range without `limited` under autolimits="false".
    """
    auto = _autolimits(root)
    out = {}
    for world in root.findall("worldbody"):
        for joint in world.iter("joint"):
            kind, limited = joint.get("type", "hinge"), joint.get("limited", "auto")
            if kind not in ("hinge", "slide", "ball") or limited == "false":
                continue
            if joint.get("range") is None:
                if limited == "true":
                    raise ModelError("limited=\"true\" without a range (MuJoCo refuses it)", path=source,
                                     element=where(joint))
                continue
            if limited == "auto" and not auto:
                raise ModelError(f"range=\"{joint.get('range')}\" without limited=\"true\" or \"false\" under "
                                 "<compiler autolimits=\"false\"> (MuJoCo refuses it)", path=source,
                                 element=where(joint))
            lower, upper = numbers(joint, "range", 2, source)
            if kind == "ball" and lower != 0:
                raise ModelError(f"range=\"{joint.get('range')}\": a ball joint's range is \"0 max\" (MuJoCo "
                                 "refuses another lower bound)", path=source, element=where(joint))
            if not lower < upper:
                raise ModelError(f"range=\"{joint.get('range')}\": the lower bound is not below the upper one",
                                 path=source, element=where(joint))
            out[joint.get("name", "")] = JointLimit(float(lower), float(upper), kind != "slide", "MJCF range")
    return out
