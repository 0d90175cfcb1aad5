"""How every figure and page names and colours a mechanism's parts: one mapping for all.

Names: a point written `A_pin` in the URDF (a leaf link at pin A) is shown as `A`, as the
textbook letters it; a joint or a link keeps its name. Colours: one per moving link, in the
order of the model's joints (the first moving link red, then blue, green, orange, ...), the
ground grey; a point takes its link's colour. The sweep curves, the paths figure, the 3-D
pages and the polygons all read them here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pinocchio as pin

if TYPE_CHECKING:
    import numpy as np

    from pinmech.model.mechanism import Mechanism

#: One colour a moving link (RGB in [0, 1]), in the order of the model's joints.
PALETTE = (
    (0.85, 0.15, 0.15),
    (0.15, 0.35, 0.85),
    (0.15, 0.65, 0.25),
    (0.9, 0.55, 0.05),
    (0.55, 0.25, 0.75),
    (0.1, 0.65, 0.7),
    (0.6, 0.4, 0.2),
    (0.9, 0.4, 0.7),
    (0.45, 0.5, 0.1),
    (0.2, 0.2, 0.5),
)
GROUND_GREY = (0.55, 0.55, 0.55)  # as the bundled URDFs paint their ground
#: Suffixes a point's name carries in a URDF that the textbook does not print.
_SUFFIXES = ("_pin", "_point")


def display_name(name: str, taken: set[str] | frozenset[str] = frozenset()) -> str:
    """The name to print for `name`: without a `_pin` (`_point`) suffix, unless the shorter
    name is in `taken` (another point's, a link's) and would be ambiguous. (A joint may share
    it: the point `A_pin` at pin A is the textbook's A.)"""
    for suffix in _SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            short = name[: -len(suffix)]
            return name if short in taken else short
    return name


def display_names(mechanism: Mechanism) -> dict[str, str]:
    """Every point, link, joint and loop cut name of the mechanism -> the name printed for it
    (a joint or cut `E_pin` is printed `E`, as is a point `E_pin` unless another point is `E`)."""
    points, links = set(mechanism.points), set(mechanism.links)
    pins = [*mechanism.joints, *(c.name for c in mechanism.closures)]  # joints and loop cuts
    out = {n: n for n in links}
    out.update({n: display_name(n, links) for n in pins})  # the joint E_pin is the textbook's E
    out.update({n: display_name(n, (points | links) - {n}) for n in points})  # a joint may share it
    return out


def joint_colours(mechanism: Mechanism) -> dict[int, tuple[float, float, float]]:
    """Pinocchio joint id (0: the ground) -> the colour of the link hanging on it: the
    colour the model's file gives that link's visuals (pinmech.model.file_colours: a URDF's
    materials, a drawn linkage's generated URDF's, an MJCF file's geom colours), else the
    palette's (the ground grey)."""
    from pinmech.model.file_colours import mjcf_joint_colours, urdf_link_colours

    out: dict[int, tuple[float, float, float]] = {0: GROUND_GREY}
    for k, joint in enumerate(range(1, mechanism.model.njoints)):
        out[joint] = PALETTE[k % len(PALETTE)]
    path = mechanism.urdf_path or mechanism.source
    if str(path).endswith(".xml"):  # MJCF: the colour of each body's first coloured geom
        out.update(mjcf_joint_colours(str(path), mechanism.model))
        return out
    filed = urdf_link_colours(str(path)) if str(path).endswith(".urdf") else {}
    taken: set[int] = set()
    for frame in mechanism.model.frames:  # a joint's first coloured body (the link on it)
        if frame.type == pin.FrameType.BODY and frame.name in filed and frame.parentJoint not in taken:
            out[frame.parentJoint] = filed[frame.name]
            taken.add(frame.parentJoint)
    return out


def colour_of(mechanism: Mechanism, name: str) -> tuple[float, float, float]:
    """The colour of a link, or of the link a point (or a drawn linkage's pin) is on (grey:
    the ground). FrameNotFound for a name the model has no frame of."""
    fid = mechanism.links[name] if name in mechanism.links else mechanism.frame_id(name)
    return joint_colours(mechanism)[mechanism.model.frames[fid].parentJoint]


def hex_colour(rgb: tuple[float, float, float]) -> str:
    """`#rrggbb` for an RGB colour in [0, 1]."""
    return "#" + "".join(f"{round(255 * min(max(c, 0.0), 1.0)):02x}" for c in rgb[:3])


def labelled_places(mechanism: Mechanism, q) -> dict[str, "np.ndarray"]:
    """Every joint, loop cut and named point at configuration q, by its printed name ->
    its world position [m], one name a place (a pin's name wins over a point's there)."""
    import numpy as np
    import pinocchio as pin

    from pinmech.model.link_nodes import sketch_links, world_nodes

    data = mechanism.model.createData()
    pin.forwardKinematics(mechanism.model, data, np.asarray(q, float))
    names, out = display_names(mechanism), {}
    tol = 1e-9 * mechanism.length_scale
    for link in sketch_links(mechanism).values():
        for node, p in zip(link.nodes, world_nodes(link, data)):
            if node.kind != "other" and not any(np.linalg.norm(p - x) <= tol for x in out.values()):
                out.setdefault(names.get(node.name, node.name), p)
    return out
