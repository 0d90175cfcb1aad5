"""A drawn linkage's pins as places a scene can name: `[report] points = ["B"]` for pin B.

A pin joins two or more links at one point, so its centre moves as a point of each of
them. A tree pin whose joint keeps the pin's name has that joint's frame there already;
every other pin (a loop cut, a pin joining three links, a slot's pin, a ball) gets one
frame of its own, named as the pin, fixed on the first link that lists it. These frames
are found by name (`Mechanism.frame_id`) but are not among the points reported by default.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.model.mechanism import Mechanism


def pin_places(mech: Mechanism, pins: dict[str, np.ndarray], links: dict[str, list[str]]
               ) -> dict[str, tuple[str, pin.SE3]]:
    """Pin name -> (its link, the pin's place in that link's body frame), for the pins no
    frame of the model names.

    Args:
        mech: the unlocked model, closed at its reference (the drawn pose).
        pins: each pin's centre at the drawn pose, world frame [m].
        links: link name -> the names it lists (the linkage file's links).
    """
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.reference)
    places = {}
    for name, at in pins.items():
        carriers = [link for link, names in links.items() if name in names and link in mech.links]
        if not carriers or mech.model.existFrame(name):
            continue
        moving = [c for c in carriers if mech.model.frames[mech.links[c]].parentJoint != 0]
        link = (moving or carriers)[0]
        world = np.append(at, 0.0) if at.size == 2 else at
        local = data.oMf[mech.links[link]].actInv(world)
        places[name] = (link, pin.SE3(np.eye(3), local))
    return places


def add_pin_frames(mech: Mechanism, places: dict[str, tuple[str, pin.SE3]]) -> None:
    """One frame per pin, at its place on its link (before any solver makes its Data)."""
    model = mech.model
    for name, (link, offset) in places.items():
        body = model.frames[mech.links[link]]
        model.addFrame(pin.Frame(name, body.parentJoint, mech.links[link], body.placement * offset,
                                 pin.FrameType.OP_FRAME), False)
