"""A redrawn linkage's joint and frame placements, written into its model in place.

A drawn linkage's model (linkage_model.py: the URDF of linkage_urdf.py, loaded, with the
cut frames of closure_rows.py and the pin frames of linkage_pins.py) places every joint
and frame from the drawing's points: each link's frame sits on its parent joint with its
x axis from its first point to the next (a block: along its slide; a spatial linkage:
world-aligned), and

  * a tree joint's placement is its point in the parent link's frame (a planar slide's
    also turned by the child's angle less the parent's, as the URDF's rpy);
  * a cut's frames, a point's frames and a pin's frame are their point in their link's
    frame (a planar slide cut's frames world-aligned at the drawn pose, as the URDF's
    rpy = -phi), after the link's body frame.

A design study or a synthesis candidate changes `[params]`: the points are drawn again
(`linkage_from_spec`, the one drawing) and only these placements are computed and written
(no URDF, no model built: the compiled core reads the placements at each call).
`DrawnPlacements` checks once, on the template, that these rules give the loaded model's
own placements; a redrawing that turns a slide (its axis is the joint's or the cut's, not
a placement) is refused by name.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError
from pinmech.model.linkage import GROUND, Linkage
from pinmech.model.linkage_urdf import Tree, spanning_tree

_MATCH = 1e-9  # [-] of the linkage's size: the rules against the loaded model (rounding ~1e-15)


def _link_frames(linkage: Linkage, tree: Tree) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each link's frame at the drawn pose: (origin (3,) [m], rotation (3, 3)) in the world,
    by linkage_urdf's rules (its `_frames`, or world-aligned for a spatial linkage)."""
    from pinmech.model.linkage_urdf import _frames

    if linkage.spatial:
        out = {GROUND: (np.zeros(3), np.eye(3))}
        for link in tree.order[1:]:
            out[link] = (np.asarray(tree.parent[link][0].at, dtype=float), np.eye(3))
        return out
    return {link: (_at(f.origin), _turn(f.phi)) for link, f in _frames(linkage, tree).items()}


def _turn(phi: float) -> np.ndarray:
    """The rotation about z by phi [rad] (3, 3)."""
    c, s = math.cos(phi), math.sin(phi)
    return np.array(((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0)))


def _at(p: np.ndarray) -> np.ndarray:
    return np.array((p[0], p[1], 0.0)) if p.size == 2 else np.asarray(p, dtype=float)


class DrawnPlacements:
    """The placements of a drawn linkage's model that its drawing sets, by index.

    Attributes:
        model: the linkage's model (the user's, written in place).
        tree: the spanning tree (the template's: a redrawing keeps the topology).
    """

    def __init__(self, linkage: Linkage, model: pin.Model) -> None:
        self.model, self.source = model, linkage.source
        self.tree = spanning_tree(linkage, last=("spherical",) if linkage.spatial else ())
        self.joints = [(model.getJointId(link_edge[0].name), link, link_edge[0], link_edge[1])
                       for link, link_edge in self.tree.parent.items() if model.existJointName(link_edge[0].name)]
        self.frames = self._frame_roles(linkage)
        self.slides = self._slides(linkage)
        bodies = {link: self.model.frames[self.model.getFrameId(link, pin.FrameType.BODY)].placement
                  for _, link, _, _ in self.frames}  # each frame's link's body frame (fixed)
        self._bodies = {link: (np.array(M.rotation), np.array(M.translation)) for link, M in bodies.items()}
        self._joint_placements, self._model_frames = model.jointPlacements, model.frames  # Pinocchio's own vectors
        self._check(linkage)

    def _frame_roles(self, linkage: Linkage) -> list[tuple[int, str, str, bool]]:
        """(frame index, link, point, world-aligned) for every frame the drawing places."""
        model, roles = self.model, []
        cuts = {c.name: c for c in self.tree.cuts}
        for i, f in enumerate(model.frames):
            name = f.name
            if f.type == pin.FrameType.OP_FRAME and "__" in name and name.rsplit("__", 1)[0] in cuts:
                cut, side = name.rsplit("__", 1)
                link = cuts[cut].links[0 if side == "parent" else 1]
                roles.append((i, link, ("cut", cut), cuts[cut].kind == "prismatic" and not linkage.spatial))
            elif f.type == pin.FrameType.FIXED_JOINT and name.startswith("point_") \
                    and name[6:] in linkage.point_links:
                roles.append((i, linkage.point_links[name[6:]], ("point", name[6:]), False))
            elif f.type == pin.FrameType.BODY and name in linkage.point_links:
                roles.append((i, linkage.point_links[name], ("point", name), False))
            elif f.type == pin.FrameType.OP_FRAME and name in linkage.points and name not in linkage.point_links:
                body = model.frames[f.parentFrame].name  # a pin's frame, on the link add_pin_frames chose
                if body in linkage.links:
                    roles.append((i, body, ("point", name), False))
        return roles

    def _slides(self, linkage: Linkage) -> dict[str, np.ndarray]:
        """Each slide's direction [-] (world, drawn pose): an axis, not a placement."""
        return {e.name: np.asarray(e.direction, dtype=float) for e in linkage.edges if e.kind == "prismatic"}

    def placements(self, linkage: Linkage) -> list[tuple[str, int, np.ndarray, np.ndarray]]:
        """(kind, index, rotation (3, 3), translation (3,) [m]) of every joint and frame the
        redrawn `linkage` places, in its parent joint's frame.

        Raises:
            ModelError: the redrawing turns a slide (its direction changes: the joint's or
                the cut's axis, which no placement holds).
        """
        for name, d in self._slides(linkage).items():
            if max(abs(float(x) - float(y)) for x, y in zip(d, self.slides[name])) > 1e-12:
                raise ModelError(f"redrawn, the slide {name} turns (direction {np.round(d, 9).tolist()} against "
                                 f"{np.round(self.slides[name], 9).tolist()} drawn): a slide's axis cannot be "
                                 "written in place; keep its direction fixed", path=self.source)
        edges = {e.name: e for e in linkage.edges}
        tree = Tree(self.tree.order, {link: (edges[e.name], parent) for link, (e, parent) in self.tree.parent.items()},
                    [edges[c.name] for c in self.tree.cuts])  # the template's tree, the new drawing's points
        frames = _link_frames(linkage, tree)
        out, identity = [], np.eye(3)
        for j, child, template_edge, parent in self.joints:
            edge = edges[template_edge.name]
            o_p, R_p = frames[parent]
            R = R_p.T @ frames[child][1] if edge.kind == "prismatic" and not linkage.spatial else identity
            out.append(("joint", j, R, R_p.T @ (_at(edge.at) - o_p)))
        for i, link, (kind, name), world in self.frames:
            o, R = frames[link]
            x = edges[name].at if kind == "cut" else linkage.points[name]
            body_R, body_t = self._bodies[link]
            local = body_t + body_R @ (R.T @ (_at(x) - o))
            out.append(("frame", i, body_R @ R.T if world else body_R, local))
        return out

    def write(self, placements: list[tuple[str, int, np.ndarray, np.ndarray]]) -> None:
        """Write `placements` into the model in place (through Pinocchio's views: no SE3 made)."""
        joints, frames = self._joint_placements, self._model_frames
        for kind, i, R, t in placements:
            M = joints[i] if kind == "joint" else frames[i].placement
            M.translation[:] = t
            M.rotation[:] = R

    def _check(self, linkage: Linkage) -> None:
        """The rules give the loaded model's own placements (else: refused by name)."""
        pts = np.array([_at(p) for p in linkage.points.values()])
        tol = _MATCH * max(float(np.ptp(pts, axis=0).max()), 1e-300)
        for kind, i, R, t in self.placements(linkage):
            have = self.model.jointPlacements[i] if kind == "joint" else self.model.frames[i].placement
            gap = float(np.max(np.abs(have.translation - t)))
            turn = float(np.max(np.abs(have.rotation - R)))
            if gap > tol or turn > _MATCH:
                what = self.model.names[i] if kind == "joint" else self.model.frames[i].name
                raise ModelError(f"the {kind} {what}'s placement is not the drawing's (off by {gap:.3g} m, {turn:.3g} in its rotation): "
                                 "its params cannot be written in place", path=self.source)
