"""A planar mechanism as a textbook's linkage: rigid links (the Pinocchio bodies, 0 the
ground) joined by pins and slides, placed in the plane of motion at a pose.

The design diagnostics (transmission angles, Grashof classes, limit positions, instant
centres) read the linkage from here, never from raw URDF: its links and kinematic pairs
come from the model's tree joints and loop cuts alike, so a URDF, a drawn linkage and an
MJCF file give the same answer. Coordinates in the plane are (x, y) along two unit
vectors `e1`, `e2` with e1 x e2 = the plane normal n (the world x, y for n = z), so
angles count counter-clockwise about n.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.exceptions import DiagnosticError
from pinmech.model.mechanism import Mechanism

_SAME = 1e-9  # two pin places on one link closer than this share of the mechanism's size are one pin


@dataclass(frozen=True)
class Pair:
    """A kinematic pair between two links.

    Attributes:
        name: the joint's or cut's name.
        kind: "pin" (a revolute pair) or "slide" (a prismatic pair).
        links: the two links (Pinocchio body indices; 0 is the ground).
        local: the pair's place on each link, in that link's frame [m] (for a slide, a
            point of the slide's line on each link).
        axis: for a slide, its direction in the frame of `links[0]` (unit), else None.
    """

    name: str
    kind: str
    links: tuple[int, int]
    local: tuple[np.ndarray, np.ndarray]
    axis: np.ndarray | None = None

    def other(self, link: int) -> int:
        """The link the pair joins to `link`."""
        return self.links[1] if self.links[0] == link else self.links[0]


@dataclass
class PlanarLinkage:
    """The links and pairs of a planar mechanism, with a `pin.Data` of its own.

    Attributes:
        names: link index -> the link's name (the first URDF link on that body).
        pairs: every pin and slide, tree joints and loop cuts; a pin drawn on three links
            (one name in a drawn linkage) appears once per pair of links it joins.
        e1, e2, normal: the plane's axes in the world frame (unit, e1 x e2 = normal).
        offset: the plane's distance from the world origin along the normal [m].
    """

    mechanism: Mechanism
    names: dict[int, str]
    pairs: list[Pair]
    e1: np.ndarray
    e2: np.ndarray
    normal: np.ndarray
    offset: float
    data: pin.Data

    def pins(self, link: int) -> list[Pair]:
        """The pins of a link."""
        return [p for p in self.pairs if p.kind == "pin" and link in p.links]

    def neighbours(self, link: int) -> list[tuple[int, Pair]]:
        """(the other link, the pair) for every pair of a link."""
        return [(p.other(link), p) for p in self.pairs if link in p.links]

    def place(self, q: np.ndarray, v: np.ndarray | None = None) -> None:
        """Put the links at configuration q (and velocities v [rad/s, m/s]) in `data`."""
        model = self.mechanism.model
        if v is None:
            pin.forwardKinematics(model, self.data, q)
        else:
            pin.forwardKinematics(model, self.data, q, v)

    def point(self, link: int, local: np.ndarray) -> np.ndarray:
        """A point of a link, given in its frame [m], in plane coordinates (x, y) [m]."""
        p = self.data.oMi[link].act(local)
        return np.array([self.e1 @ p, self.e2 @ p])

    def direction(self, link: int, local_axis: np.ndarray) -> np.ndarray:
        """A direction fixed in a link, in plane coordinates (unit if the axis is)."""
        d = self.data.oMi[link].rotation @ local_axis
        return np.array([self.e1 @ d, self.e2 @ d])

    def pair_point(self, pair: Pair) -> np.ndarray:
        """Where a pin is, in plane coordinates [m] (a slide: a point of its line on links[0])."""
        return self.point(pair.links[0], pair.local[0])

    def omega(self, link: int) -> float:
        """Angular velocity of a link about the plane normal [rad/s] (needs `place` with v)."""
        if link == 0:
            return 0.0
        return float(self.normal @ (self.data.oMi[link].rotation @ self.data.v[link].angular))

    def velocity(self, link: int, xy: np.ndarray) -> np.ndarray:
        """Velocity [m/s] of the point of `link` at plane coordinates xy [m], in the plane."""
        if link == 0:
            return np.zeros(2)
        M = self.data.oMi[link]
        v_origin = M.rotation @ self.data.v[link].linear
        origin = np.array([self.e1 @ M.translation, self.e2 @ M.translation])
        w = self.omega(link)
        r = np.asarray(xy, dtype=float) - origin
        return np.array([self.e1 @ v_origin, self.e2 @ v_origin]) + w * np.array([-r[1], r[0]])

    def to_world(self, xy: np.ndarray) -> np.ndarray:
        """Plane coordinates [m] -> a world point [m], shape (3,)."""
        return xy[0] * self.e1 + xy[1] * self.e2 + self.offset * self.normal

    def to_link(self, link: int, xy: np.ndarray) -> np.ndarray:
        """Plane coordinates [m] -> the same point in a link's frame [m], shape (3,)."""
        return self.data.oMi[link].actInv(self.to_world(xy))


def planar_linkage(mechanism: Mechanism) -> PlanarLinkage:
    """The linkage of a planar mechanism of pins and slides.

    Raises:
        DiagnosticError: a spatial mechanism, a joint of more than one freedom, a fixed
            cut, or a pin axis out of the plane's normal, naming the joint.
    """
    normal = mechanism.plane_normal
    if normal is None:
        raise DiagnosticError("planar diagnostics need a planar mechanism; this one moves in space",
                              path=mechanism.source)
    model = mechanism.model
    pairs = [_tree_pair(mechanism, j) for j in mechanism.joints.values()]
    pairs += [_cut_pair(mechanism, c) for c in mechanism.closures]
    pairs += _shared_pins(pairs, mechanism.length_scale)
    e1, e2 = _plane_axes(np.asarray(normal, dtype=float))
    data = model.createData()
    pin.forwardKinematics(model, data, mechanism.neutral())
    offset = float(normal @ data.oMi[pairs[0].links[1]].translation) if pairs else 0.0
    names: dict[int, str] = {}
    for name, fid in mechanism.links.items():
        names.setdefault(model.frames[fid].parentJoint, name)
    for j in range(model.njoints):
        names.setdefault(j, model.names[j])
    return PlanarLinkage(mechanism, names, pairs, e1, e2, np.asarray(normal, dtype=float), offset, data)


def _tree_pair(mechanism: Mechanism, joint) -> Pair:
    model = mechanism.model
    if joint.nv != 1 or joint.kind not in ("revolute", "continuous", "prismatic"):
        raise DiagnosticError(f"joint '{joint.name}' is not a pin or a slide ({joint.kind}, {joint.nv} freedoms): "
                              "planar diagnostics need a linkage of pins and slides", path=mechanism.source)
    M = model.jointPlacements[joint.id]
    links = (int(model.parents[joint.id]), int(joint.id))
    local = (M.translation.copy(), np.zeros(3))
    if joint.is_angular:
        return Pair(joint.name, "pin", links, local)
    return Pair(joint.name, "slide", links, local, M.rotation @ np.asarray(joint.axis, dtype=float))


def _cut_pair(mechanism: Mechanism, closure) -> Pair:
    model = mechanism.model
    P, C = model.frames[closure.parent_frame], model.frames[closure.child_frame]
    links = (int(P.parentJoint), int(C.parentJoint))
    local = (P.placement.translation.copy(), C.placement.translation.copy())
    if closure.cut_type in ("revolute", "spherical"):  # a ball in a planar loop acts as a pin
        return Pair(closure.name, "pin", links, local)
    if closure.cut_type == "prismatic":
        return Pair(closure.name, "slide", links, local, P.placement.rotation @ np.asarray(closure.axis, dtype=float))
    raise DiagnosticError(f"loop cut '{closure.name}' is {closure.cut_type}: planar diagnostics need pins and slides",
                          path=mechanism.source)


def _shared_pins(pairs: list[Pair], scale: float) -> list[Pair]:
    """Pins implied by one pin place shared on a link: a pin drawn on links a, b, c is
    modelled as pins a-b and b-c at one place of b; a-c is a pin too (its centre is there)."""
    out: list[Pair] = []
    pins = [p for p in pairs if p.kind == "pin"]
    for i, p in enumerate(pins):
        for r in pins[i + 1:]:
            for a in range(2):
                for b in range(2):
                    same = p.links[a] == r.links[b] and np.linalg.norm(p.local[a] - r.local[b]) <= _SAME * scale
                    ends = (p.links[1 - a], r.links[1 - b])
                    known = any(set(x.links) == set(ends) for x in pairs + out)
                    if same and ends[0] != ends[1] and not known:
                        out.append(Pair(f"{p.name}/{r.name}", "pin", ends, (p.local[1 - a], r.local[1 - b])))
    return out


def _plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit e1, e2 in the plane with e1 x e2 = normal: the world x, y when normal is z."""
    helper = np.eye(3)[0] if abs(normal[0]) < 0.9 else np.eye(3)[1]
    e1 = helper - normal * (normal @ helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)
