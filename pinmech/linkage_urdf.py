"""A parsed linkage -> URDF text: spanning tree, one cut per loop, frames, visuals.

Breadth first from the ground, slides before pins (so ground joints stay in the tree and can
drive); every edge left over is a loop cut (`<constraint>`). Each link's frame sits on its
parent joint with its x axis from the first point it lists to the next; every joint's
coordinate at the drawn pose is returned as the reference.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from pinmech.exceptions import ModelError
from pinmech.linkage import GROUND, Edge, Linkage

_COLOURS = ["0.85 0.15 0.15", "0.15 0.35 0.85", "0.15 0.65 0.25", "0.85 0.55 0.1", "0.55 0.2 0.75",
            "0.1 0.65 0.7", "0.75 0.3 0.5", "0.45 0.45 0.15"]


# ------------------------------------------------------------------------- the tree
@dataclass(frozen=True)
class Tree:
    """Spanning tree of the link graph: parent edge of each link, and the cut edges."""

    order: list[str]
    parent: dict[str, tuple[Edge, str]]
    cuts: list[Edge]


def spanning_tree(linkage: Linkage, last: tuple[str, ...] = ()) -> Tree:
    """Breadth first from the ground, slides before pins, so ground joints stay in the tree;
    edges of the kinds in `last` (balls) join the tree only where nothing else reaches.

    Raises:
        ModelError: a link not connected to the ground through joints.
    """
    edges = sorted(linkage.edges, key=lambda e: e.kind != "prismatic")
    seen, order, parent, used = {GROUND}, [GROUND], {}, set()

    def grow(queue: deque, kinds_ok) -> None:
        while queue:
            link = queue.popleft()
            for edge in edges:
                if link not in edge.links or not kinds_ok(edge):
                    continue
                other = edge.links[1] if edge.links[0] == link else edge.links[0]
                if other not in seen:
                    seen.add(other)
                    order.append(other)
                    parent[other] = (edge, link)
                    used.add(edge.name)
                    queue.append(other)

    grow(deque([GROUND]), lambda e: e.kind not in last)
    while True:  # a ball where nothing else reaches, then on from there
        bridge = next((e for e in edges if e.kind in last and (e.links[0] in seen) != (e.links[1] in seen)), None)
        if bridge is None:
            break
        inside, outside = bridge.links if bridge.links[0] in seen else bridge.links[::-1]
        seen.add(outside)
        order.append(outside)
        parent[outside] = (bridge, inside)
        used.add(bridge.name)
        grow(deque([outside]), lambda e: e.kind not in last)
    lost = [n for n in linkage.links if n not in seen]
    if lost:
        raise ModelError(f"link(s) {', '.join(lost)} are joined to the ground by no chain of joints",
                         path=linkage.source, element="[links]")
    return Tree(order, parent, [e for e in linkage.edges if e.name not in used])


# ------------------------------------------------------------------------- URDF text
@dataclass(frozen=True)
class _Frame:
    origin: np.ndarray  # world [m]
    phi: float  # x axis angle in the world at the drawn pose [rad]

    def local(self, p: np.ndarray) -> np.ndarray:
        c, s = math.cos(self.phi), math.sin(self.phi)
        d = p - self.origin
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def _xyz(p: np.ndarray, z: float = 0.0) -> str:
    return f"{_num(p[0])} {_num(p[1])} {_num(z)}"


def _num(x: float) -> str:
    return repr(float(x)) if x != 0 else "0"


def _frames(linkage: Linkage, tree: Tree) -> dict[str, _Frame]:
    """Each link's frame: on its parent joint, x from its first listed point to the next (a block: its slide)."""
    frames = {GROUND: _Frame(np.zeros(2), 0.0)}
    for link in tree.order[1:]:
        edge, _ = tree.parent[link]
        origin = edge.at
        if link in linkage.blocks:
            d = linkage.blocks[link].direction
            phi = math.atan2(d[1], d[0])
        else:
            names = linkage.links[link]
            first = linkage.points[names[0]]
            phi = 0.0
            for name in names[1:]:
                vector = linkage.points[name] - first
                if np.linalg.norm(vector) > 1e-9 * _size(linkage):
                    phi = math.atan2(vector[1], vector[0])
                    break
        frames[link] = _Frame(origin, phi)
    return frames


def _size(linkage: Linkage) -> float:
    pts = np.array(list(linkage.points.values()))
    return max(float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))), 1e-300)


def linkage_urdf(linkage: Linkage) -> tuple[str, dict[str, float]]:
    """The URDF text and each tree joint's coordinate at the drawn pose [rad or m]."""
    if linkage.spatial:
        return spatial_urdf(linkage)
    tree = spanning_tree(linkage)
    frames = _frames(linkage, tree)
    size = _size(linkage)
    lines = [f"<robot name={quoteattr(Path(linkage.source).stem)}>",
             f"  <!-- generated by pinmech from {linkage.source}: edit that file, not this one -->",
             '  <material name="ground"><color rgba="0.35 0.35 0.35 1"/></material>']
    for i, colour in enumerate(_COLOURS):
        lines.append(f'  <material name="c{i}"><color rgba="{colour} 1"/></material>')
    reference: dict[str, float] = {}
    for i, link in enumerate(tree.order):
        lines += _link_xml(linkage, link, frames[link], size, i)
    for link in tree.order[1:]:
        edge, parent = tree.parent[link]
        lines.append(_joint_xml(edge, parent, link, frames, reference, size))
    for cut in tree.cuts:
        lines.append(_cut_xml(cut, frames))
    for name, link in linkage.point_links.items():
        lines.append(f'  <link name={quoteattr(name)}/>')
        lines.append(f'  <joint name={quoteattr("point_" + name)} type="fixed"><parent link={quoteattr(link)}/>'
                     f'<child link={quoteattr(name)}/><origin xyz="{_xyz(frames[link].local(linkage.points[name]))}"/>'
                     '</joint>')
    lines.append("</robot>")
    return "\n".join(lines) + "\n", reference


def _joint_xml(edge: Edge, parent: str, child: str, frames: dict[str, _Frame], reference: dict[str, float],
               size: float) -> str:
    p, c = frames[parent], frames[child]
    xyz = _xyz(p.local(edge.at))
    head = f'  <joint name={quoteattr(edge.name)} type="{"continuous" if edge.kind == "revolute" else "prismatic"}">'
    links = f"<parent link={quoteattr(parent)}/><child link={quoteattr(child)}/>"
    if edge.kind == "revolute":
        reference[edge.name] = _wrap(c.phi - p.phi)
        return f'{head}{links}<origin xyz="{xyz}"/><axis xyz="0 0 1"/></joint>'
    reference[edge.name] = 0.0
    axis = c.local(c.origin + edge.direction)  # URDF axes are in the joint frame, turned by rpy
    rpy = f"0 0 {_num(_wrap(c.phi - p.phi))}"
    span = 1e3 * size
    return (f'{head}{links}<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{_xyz(axis)}"/>'
            f'<limit lower="{_num(-span)}" upper="{_num(span)}" effort="0" velocity="0"/></joint>')


def _cut_xml(cut: Edge, frames: dict[str, _Frame]) -> str:
    a, b = cut.links
    pa, pb = frames[a], frames[b]
    if cut.kind == "revolute":
        return (f'  <constraint name={quoteattr(cut.name)} type="revolute">'
                f'<parent link={quoteattr(a)}/><parent_origin xyz="{_xyz(pa.local(cut.at))}"/>'
                '<parent_axis xyz="0 0 1"/>'
                f'<child link={quoteattr(b)}/><child_origin xyz="{_xyz(pb.local(cut.at))}"/>'
                '<child_axis xyz="0 0 1"/></constraint>')
    # slide cut: both cut frames world-aligned at the drawn pose, the line along the axis
    axis = _xyz(cut.direction)
    return (f'  <constraint name={quoteattr(cut.name)} type="prismatic">'
            f'<parent link={quoteattr(a)}/><parent_origin xyz="{_xyz(pa.local(cut.at))}" '
            f'rpy="0 0 {_num(-pa.phi)}"/><parent_axis xyz="{axis}"/>'
            f'<child link={quoteattr(b)}/><child_origin xyz="{_xyz(pb.local(cut.at))}" '
            f'rpy="0 0 {_num(-pb.phi)}"/><child_axis xyz="{axis}"/></constraint>')


# ------------------------------------------------------------------------- visuals
def _link_xml(linkage: Linkage, link: str, frame: _Frame, size: float, index: int) -> list[str]:
    """A link with bars between its joints, pins, a block for a slider, a symbol for the ground."""
    if link in linkage.hidden:
        return [f"  <link name={quoteattr(link)}/>"]
    width = 0.02 * size
    material = "ground" if link == GROUND else f"c{(index - 1) % len(_COLOURS)}"
    z = -width if link == GROUND else 0.4 * width * (index % 5)
    names = linkage.links[link]
    local = [frame.local(linkage.points[n]) for n in names]
    shapes = []
    if link == GROUND:
        for p in local:
            shapes.append((p, 0.0, f'<cylinder radius="{_num(0.9 * width)}" length="{_num(width)}"/>'))
        for edge in linkage.edges:
            if edge.kind == "prismatic" and GROUND in edge.links:
                phi = math.atan2(edge.direction[1], edge.direction[0])
                shapes.append((frame.local(edge.at), phi,
                               f'<box size="{_num(0.5 * size)} {_num(0.3 * width)} {_num(0.3 * width)}"/>'))
    else:
        ring = local if len(local) > 2 else local[:2]
        for i, p in enumerate(ring):
            q = ring[(i + 1) % len(ring)]
            if len(ring) == 2 and i == 1:
                break
            length = float(np.linalg.norm(q - p))
            if length > 1e-9 * size:
                shapes.append(((p + q) / 2, math.atan2(q[1] - p[1], q[0] - p[0]),
                               f'<box size="{_num(length)} {_num(width)} {_num(0.5 * width)}"/>'))
        if link in linkage.blocks:
            shapes.append((frame.local(linkage.blocks[link].at), 0.0,
                           f'<box size="{_num(3 * width)} {_num(1.5 * width)} {_num(width)}"/>'))
        for p in local:
            shapes.append((p, 0.0, f'<cylinder radius="{_num(0.6 * width)}" length="{_num(1.2 * width)}"/>'))
    out = [f"  <link name={quoteattr(link)}>"]  # no <inertial>: a drawing gives no masses
    for p, phi, geometry in shapes:
        out.append(f'    <visual><origin xyz="{_xyz(p, z)}" rpy="0 0 {_num(phi)}"/><geometry>{geometry}</geometry>'
                   f'<material name="{material}"/></visual>')
    out.append("  </link>")
    return out


# ------------------------------------------------------------------------- spatial
def _rpy_z_to(direction: np.ndarray) -> str:
    """rpy turning the z axis onto `direction` (for a cylinder drawn along a bar)."""
    import pinocchio as pin

    d = direction / np.linalg.norm(direction)
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, d)
    s, c = float(np.linalg.norm(axis)), float(z @ d)
    if s < 1e-12:
        R = np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    else:
        R = pin.AngleAxis(math.atan2(s, c), axis / s).matrix()
    return " ".join(_num(a) for a in pin.rpy.matrixToRpy(R))


def spatial_urdf(linkage: Linkage) -> tuple[str, dict[str, float]]:
    """The URDF of a spatial linkage: every link's frame world-aligned at the drawn pose, on
    its parent joint, so every joint coordinate is 0 there (the reference)."""
    tree = spanning_tree(linkage, last=("spherical",))
    origin = {GROUND: np.zeros(3)}
    for link in tree.order[1:]:
        origin[link] = tree.parent[link][0].at
    size = max(float(np.linalg.norm(np.ptp(np.array(list(linkage.points.values())), axis=0))), 1e-300)
    lines = [f"<robot name={quoteattr(Path(linkage.source).stem)}>",
             f"  <!-- generated by pinmech from {linkage.source}: edit that file, not this one -->",
             '  <material name="ground"><color rgba="0.35 0.35 0.35 1"/></material>']
    lines += [f'  <material name="c{i}"><color rgba="{c} 1"/></material>' for i, c in enumerate(_COLOURS)]
    reference: dict[str, float] = {}
    for i, link in enumerate(tree.order):
        lines += _spatial_link_xml(linkage, link, origin[link], size, i)
    for link in tree.order[1:]:
        edge, parent = tree.parent[link]
        lines += _spatial_joint_xml(edge, parent, link, origin, reference, size)
    for cut in tree.cuts:
        a, b = cut.links
        kind = {"revolute": "revolute", "prismatic": "prismatic", "spherical": "spherical"}[cut.kind]
        axis = cut.direction if cut.kind == "prismatic" else cut.axis
        lines.append(f'  <constraint name={quoteattr(cut.name)} type="{kind}">'
                     f'<parent link={quoteattr(a)}/><parent_origin xyz="{_xyz3(cut.at - origin[a])}"/>'
                     f'<parent_axis xyz="{_xyz3(axis)}"/><child link={quoteattr(b)}/>'
                     f'<child_origin xyz="{_xyz3(cut.at - origin[b])}"/><child_axis xyz="{_xyz3(axis)}"/></constraint>')
    for name, link in linkage.point_links.items():
        lines.append(f'  <link name={quoteattr(name)}/>')
        lines.append(f'  <joint name={quoteattr("point_" + name)} type="fixed"><parent link={quoteattr(link)}/>'
                     f'<child link={quoteattr(name)}/><origin xyz="{_xyz3(linkage.points[name] - origin[link])}"/>'
                     '</joint>')
    lines.append("</robot>")
    return "\n".join(lines) + "\n", reference


def _xyz3(p: np.ndarray) -> str:
    return " ".join(_num(x) for x in p)


def _spatial_joint_xml(edge: Edge, parent: str, child: str, origin: dict[str, np.ndarray],
                       reference: dict[str, float], size: float) -> list[str]:
    xyz = _xyz3(edge.at - origin[parent])
    links = f"<parent link={quoteattr(parent)}/><child link={quoteattr(child)}/>"
    if edge.kind == "prismatic":
        reference[edge.name] = 0.0
        span = 1e3 * size
        return [(f'  <joint name={quoteattr(edge.name)} type="prismatic">{links}<origin xyz="{xyz}"/>'
                 f'<axis xyz="{_xyz3(edge.direction)}"/><limit lower="{_num(-span)}" upper="{_num(span)}" '
                 'effort="0" velocity="0"/></joint>')]
    if edge.kind == "revolute":
        reference[edge.name] = 0.0
        return [(f'  <joint name={quoteattr(edge.name)} type="continuous">{links}<origin xyz="{xyz}"/>'
                 f'<axis xyz="{_xyz3(edge.axis)}"/></joint>')]
    # a ball in the tree: hinges about x, y, z through two massless links (gimbal: singular
    # where the middle one turns by 90 deg)
    out, last = [], parent
    for k, (axis, hidden) in enumerate((("1 0 0", f"{edge.name}_rx"), ("0 1 0", f"{edge.name}_ry"),
                                        ("0 0 1", child))):
        name = f"{edge.name}_{'xyz'[k]}"
        reference[name] = 0.0
        if hidden != child:
            out.append(f"  <link name={quoteattr(hidden)}/>")
        out.append(f'  <joint name={quoteattr(name)} type="continuous"><parent link={quoteattr(last)}/>'
                   f'<child link={quoteattr(hidden)}/><origin xyz="{xyz if k == 0 else "0 0 0"}"/>'
                   f'<axis xyz="{axis}"/></joint>')
        last = hidden
    return out


def _spatial_link_xml(linkage: Linkage, link: str, origin: np.ndarray, size: float, index: int) -> list[str]:
    """Cylinders between a link's joints in turn, a ball at each joint; the ground: its pivots only."""
    width = 0.02 * size
    material = "ground" if link == GROUND else f"c{(index - 1) % len(_COLOURS)}"
    local = [linkage.points[n] - origin for n in linkage.links[link]]
    out = [f"  <link name={quoteattr(link)}>"]  # no <inertial>: a drawing gives no masses
    ring = [] if link == GROUND else local + local[:1] if len(local) > 2 else local[:2]  # outline, or a bar
    pairs = [(ring[i], ring[i + 1]) for i in range(len(ring) - 1)]
    for p, q in pairs:
        length = float(np.linalg.norm(q - p))
        if length > 1e-9 * size:
            out.append(f'    <visual><origin xyz="{_xyz3((p + q) / 2)}" rpy="{_rpy_z_to(q - p)}"/><geometry>'
                       f'<cylinder radius="{_num(0.4 * width)}" length="{_num(length)}"/></geometry>'
                       f'<material name="{material}"/></visual>')
    for p in local:
        out.append(f'    <visual><origin xyz="{_xyz3(p)}"/><geometry><sphere radius="{_num(0.7 * width)}"/>'
                   f'</geometry><material name="{material}"/></visual>')
    out.append("  </link>")
    return out
