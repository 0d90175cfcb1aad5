"""A mechanism as a textbook draws it: each link a set of nodes (its joints, its cut sides,
its named points), in the link's own frame, from the model alone.

The drawings use it to sketch links that carry no `<visual>` (a bar between two nodes, a
plate over three or more, a block on a slider, a ground symbol at fixed pivots), and the
velocity and acceleration polygons use it to know which points share a link: a point at a
pin (a revolute joint or cut) belongs to both links the pin joins; a slider does not join
the points of its two links.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.model.mechanism import Mechanism

_SAME = 1e-9  # nodes closer than this share of the mechanism's size are one node

@dataclass(frozen=True)
class Node:
    """A place on a link, in the frame of the joint the link hangs on.

    Attributes:
        name: the joint's, cut's or point's name.
        position: in the link's joint frame [m], shape (3,).
        kind: "revolute" (a pin: joint or cut), "prismatic", "point" or "other".
    """

    name: str
    position: np.ndarray
    kind: str


@dataclass(frozen=True)
class LinkSketch:
    """One rigid link: the Pinocchio joint it hangs on (0: the ground) and its nodes.

    Attributes:
        slide_axis: when the link is the block of a slider (the side of a prismatic joint
            with fewer nodes), the guide's direction in the link's joint frame, else None.
        guides: on the guide's side, (a point of the guide, its direction) in the link's
            joint frame, one per prismatic joint.
    """

    name: str
    joint: int
    nodes: tuple[Node, ...]
    slide_axis: np.ndarray | None = None
    guides: tuple[tuple[np.ndarray, np.ndarray], ...] = ()

    @property
    def is_ground(self) -> bool:
        return self.joint == 0

    @property
    def is_plate(self) -> bool:
        """Three or more nodes not on one line: drawn as a plate, not as a bar."""
        if len(self.nodes) < 3:
            return False
        points = np.array([n.position for n in self.nodes])
        sigma = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
        return bool(sigma[1] > 1e-3 * sigma[0])


def sketch_links(mechanism: Mechanism) -> dict[str, LinkSketch]:
    """Every link of the mechanism (the ground included) with its nodes; one per joint."""
    model = mechanism.model
    by_joint: dict[int, list[Node]] = {}
    names: dict[int, str] = {}
    for name, fid in mechanism.links.items():
        names.setdefault(model.frames[fid].parentJoint, name)
    for joint in mechanism.joints.values():  # a joint: a node of both links it joins
        kind = "revolute" if joint.is_angular else "prismatic" if joint.kind == "prismatic" else "other"
        placement = model.jointPlacements[joint.id].translation.copy()
        _add(by_joint, model.parents[joint.id], Node(joint.name, placement, kind), mechanism)
        if kind != "prismatic":  # a slide has no fixed place on the sliding link
            _add(by_joint, joint.id, Node(joint.name, np.zeros(3), kind), mechanism)
    for closure in mechanism.closures:
        kind = "revolute" if closure.cut_type in ("revolute", "spherical") else "prismatic"
        for fid in (closure.parent_frame, closure.child_frame):
            frame = model.frames[fid]
            _add(by_joint, frame.parentJoint, Node(closure.name, frame.placement.translation.copy(), kind), mechanism)
    for name, fid in mechanism.points.items():
        frame = model.frames[fid]
        _add(by_joint, frame.parentJoint, Node(name, frame.placement.translation.copy(), "point"), mechanism)
    blocks: dict[int, np.ndarray] = {}
    guides: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
    for parent, child, on_parent, on_child in _slides(mechanism):
        block, guide = (parent, child) if len(by_joint.get(parent, [])) < len(by_joint.get(child, [])) else (child, parent)
        blocks[block] = (on_parent if block == parent else on_child)[1]
        guides.setdefault(guide, []).append(on_parent if guide == parent else on_child)
    return {
        names.get(j, model.names[j]): LinkSketch(names.get(j, model.names[j]), j, tuple(nodes), blocks.get(j),
                                                 tuple(guides.get(j, ())))
        for j, nodes in by_joint.items()
    }


_Line = tuple[np.ndarray, np.ndarray]  # a point of a line and its direction


def _slides(mechanism: Mechanism) -> list[tuple[int, int, _Line, _Line]]:
    """Every slide, a prismatic tree joint or a prismatic loop cut: the joints its two links
    hang on (parent, child) and on each, (a point of the line, its direction) in that
    link's joint frame."""
    model, out = mechanism.model, []
    for joint in mechanism.joints.values():
        if joint.kind == "prismatic":
            placement = model.jointPlacements[joint.id]
            on_parent = (placement.translation.copy(), placement.rotation @ joint.axis)
            on_child = (np.zeros(3), np.asarray(joint.axis, dtype=float))
            out.append((model.parents[joint.id], joint.id, on_parent, on_child))
    for c in mechanism.closures:
        if c.cut_type == "prismatic":
            sides = [(model.frames[f].parentJoint, model.frames[f].placement) for f in (c.parent_frame, c.child_frame)]
            (parent, on_p), (child, on_c) = sides
            out.append((parent, child, (on_p.translation.copy(), on_p.rotation @ c.axis),
                        (on_c.translation.copy(), on_c.rotation @ c.child_axis)))
    return out


def world_nodes(link: LinkSketch, data: pin.Data) -> np.ndarray:
    """The link's nodes in the world frame [m], shape (n, 3); needs `data.oMi` at the pose."""
    M = data.oMi[link.joint]
    return np.array([M.act(node.position) for node in link.nodes]).reshape(-1, 3)


def pin_links(sketches: dict[str, LinkSketch], data: pin.Data, position: np.ndarray, scale: float) -> list[str]:
    """The links a point at `position` [m] (world) belongs to through a pin at that place."""
    out = []
    for name, link in sketches.items():
        for node, p in zip(link.nodes, world_nodes(link, data)):
            if node.kind == "revolute" and np.linalg.norm(p - position) <= 1e-6 * scale:
                out.append(name)
                break
    return out


_RANK = {"revolute": 0, "prismatic": 1, "other": 2, "point": 3}  # which node names a shared place


def _add(by_joint: dict[int, list[Node]], joint: int, node: Node, mechanism: Mechanism) -> None:
    """Add a node, or merge it with one at the same place (a pin wins over a slide, a point)."""
    nodes = by_joint.setdefault(joint, [])
    tol = _SAME * mechanism.length_scale
    for i, other in enumerate(nodes):
        if np.linalg.norm(other.position - node.position) <= tol:
            if _RANK[node.kind] < _RANK[other.kind]:
                nodes[i] = Node(node.name, other.position, node.kind)
            return
    nodes.append(node)
