"""Each slider's place, velocity and acceleration along its guide, for the sweep figures: a
tree prismatic joint's coordinate and rates, or a prismatic loop cut's (a drawn slot: the
pin's block slides in the slotted link), measured between the cut's two frames.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from pinmech.mechanism import Mechanism
    from pinmech.motion import Motion


def slide_values(mechanism: Mechanism, motion: Motion, q: np.ndarray, data: pin.Data,
                 names: list[str]) -> list[tuple[float, float, float]]:
    """(s [m], v_rel [m/s], a_rel [m/s²]) along the guide of each named slider at q.

    A loop cut's s is the child cut frame's origin along the slide from the parent's (0
    where the linkage was drawn), its rates the relative velocity and acceleration of
    `motion.sliders` projected on the slide's axis (world axes at q).
    """
    cuts = {c.name: c for c in mechanism.closures if c.cut_type == "prismatic"}
    if any(n in cuts and n not in motion.joints for n in names):
        pin.framesForwardKinematics(mechanism.model, data, q)
    out = []
    for name in names:
        if name in motion.joints:
            joint = motion.joints[name]
            out.append((joint.q, joint.v, joint.a))
            continue
        cut, slide = cuts[name], motion.sliders[name]
        parent, child = data.oMf[cut.parent_frame], data.oMf[cut.child_frame]
        axis = parent.rotation @ np.asarray(cut.axis, dtype=float)
        out.append((float(axis @ (child.translation - parent.translation)), float(axis @ slide.relative_velocity),
                    float(axis @ slide.relative_acceleration)))
    return out


def slide_link(mechanism: Mechanism, name: str) -> str:
    """The link a slider moves (a tree joint's child link, a cut's child link)."""
    if name in mechanism.joints:
        return mechanism.joint(name).child_link
    return next(c.child_link for c in mechanism.closures if c.name == name)
