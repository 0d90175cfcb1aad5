"""Visual geometry for links that have none: each drawn from its nodes (`pinmech.model.link_nodes`).

A link with two nodes is a bar between them, with three or more a plate over them (a
planar mechanism) or bars joining them in turn (a spatial one); a slider block is a box
along its guide, a guide on the ground a thin rail; fixed pivots stand on a ground
symbol (a triangle). Links that carry their own `<visual>` keep it.
"""

from __future__ import annotations

import itertools

import numpy as np
import pinocchio as pin

from pinmech.draw.geometry import _screen_up
from pinmech.model.display import joint_colours
from pinmech.model.link_nodes import LinkSketch, sketch_links
from pinmech.model.mechanism import Mechanism

_BAR = 0.05  # bar width, as a share of the longest link
_BLOCK = (0.2, 0.11)  # slider block length and width, shares of the longest link
_GROUND = 0.1  # ground triangle height, share of the longest link


def sketch_visuals(mechanism: Mechanism, visual_model: pin.GeometryModel | None = None) -> pin.GeometryModel:
    """The visuals of `visual_model` (if any) plus a sketch of every link that has none.

    Args:
        mechanism: the model the visuals hang on (`mechanism.model`).
        visual_model: the URDF's own visuals (`load_visuals`); None or empty: sketch all.
    """
    import coal

    out = pin.GeometryModel()
    drawn = set()
    for obj in visual_model.geometryObjects if visual_model is not None else ():
        out.addGeometryObject(obj)
        drawn.add(obj.parentJoint)
    sketches = sketch_links(mechanism)
    scale = _longest_link(sketches) or mechanism.length_scale
    normal = mechanism.plane_normal
    data = mechanism.model.createData()  # link frames at the neutral pose: their plane normal
    pin.forwardKinematics(mechanism.model, data, mechanism.neutral())
    colours = joint_colours(mechanism)  # as in every figure (pinmech.model.display)
    for link in sketches.values():
        if link.joint in drawn:
            continue
        colour = np.array([*colours[link.joint], 1.0])
        local_normal = None if normal is None else data.oMi[link.joint].rotation.T @ normal
        shapes = _ground_shapes(link, scale, normal) if link.is_ground else []
        shapes += _link_shapes(link, scale, local_normal, coal)
        for k, (geometry, placement) in enumerate(shapes):
            obj = pin.GeometryObject(f"sketch_{link.name}_{k}", link.joint, placement, geometry)
            obj.meshColor = colour
            out.addGeometryObject(obj)
    return out


def _link_shapes(link: LinkSketch, scale: float, normal: np.ndarray | None, coal) -> list:
    """(coal shape, placement in the link's joint frame) of one moving link, or the ground's rails."""
    points = [n.position for n in link.nodes]
    shapes = []
    width = _BAR * scale
    if link.slide_axis is not None:
        length, side = _BLOCK[0] * scale, _BLOCK[1] * scale
        centre = next((n.position for n in link.nodes if n.kind == "revolute"), np.zeros(3))
        shapes.append((coal.Box(length, side, 0.6 * side), _frame(centre, link.slide_axis, normal)))
    for origin, axis in link.guides:
        if link.is_ground:
            rail = _frame(origin + 0.5 * scale * axis - 0.5 * _BLOCK[1] * scale * _across(axis, normal), axis, normal)
            shapes.append((coal.Box(2 * scale, 0.3 * width, 0.3 * width), rail))
    if link.is_ground:
        return shapes
    if link.is_plate and normal is not None:
        shapes.append((_plate(points, normal, width, coal), pin.SE3.Identity()))
    else:
        if not link.is_plate:  # nodes on one line: one bar from end to end
            points = _ends(points)
        pairs = list(itertools.pairwise(points + points[:1] if len(points) > 2 else points))  # closed if 3 or more
        shapes += [_bar(a, b, width, normal, coal) for a, b in pairs if np.linalg.norm(b - a) > 1e-9 * scale]
    if len(points) == 1 and link.slide_axis is None:
        shapes.append((coal.Sphere(width), pin.SE3(np.eye(3), points[0])))
    return shapes


def _ground_shapes(link: LinkSketch, scale: float, world_normal: np.ndarray | None) -> list:
    """A triangle under every fixed pivot (apex on the pivot, base below it on screen)."""
    import coal

    back = world_normal if world_normal is not None else np.array([1.0, 0.6, 0.8]) / np.linalg.norm([1.0, 0.6, 0.8])
    up = _screen_up(back)
    side = np.cross(up, back)
    h = _GROUND * scale
    shapes = []
    for node in link.nodes:
        if node.kind != "revolute":
            continue
        p = node.position
        corners = [p, p - h * up + 0.6 * h * side, p - h * up - 0.6 * h * side]
        thick = 0.3 * h * back
        prism = [c + s * thick for c in corners for s in (-1.0, 1.0)] + [
            c - h * 0.25 * up - s * thick for c in corners[1:] for s in (-1.0, 1.0)
        ]
        shapes.append((coal.Convex.convexHull([np.asarray(x, float) for x in prism], True, None),
                       pin.SE3.Identity()))
    return shapes


def _ends(points: list[np.ndarray]) -> list[np.ndarray]:
    """The two farthest apart of points on one line (all of them if fewer than three)."""
    if len(points) < 3:
        return points
    pairs = [(np.linalg.norm(a - b), i, j) for i, a in enumerate(points) for j, b in enumerate(points) if i < j]
    _, i, j = max(pairs, key=lambda t: t[0])
    return [points[i], points[j]]


def _longest_link(sketches) -> float:
    """The largest distance between two nodes of one link [m] (0 when no link has two)."""
    spans = [np.linalg.norm(a.position - b.position) for link in sketches.values() for a in link.nodes
             for b in link.nodes]
    return float(max(spans, default=0.0))


def _across(axis: np.ndarray, normal: np.ndarray | None) -> np.ndarray:
    """A unit vector across a guide, in the plane (or any, in space)."""
    n = normal if normal is not None else np.array([0.0, 0.0, 1.0])
    side = np.cross(n, axis)
    return side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-9 else np.array([0.0, 1.0, 0.0])


def _plate(points: list[np.ndarray], normal: np.ndarray, width: float, coal):
    """A flat plate: the convex hull of the nodes, widened by half a bar and thickened."""
    centre = np.mean(points, axis=0)
    grown = []
    for p in points:
        out = p - centre
        n = np.linalg.norm(out)
        p2 = p + (0.5 * width * out / n if n > 0 else 0)
        grown += [p2 + 0.25 * width * normal, p2 - 0.25 * width * normal]
    return coal.Convex.convexHull([np.asarray(x, float) for x in grown], True, None)


def _bar(a: np.ndarray, b: np.ndarray, width: float, normal: np.ndarray | None, coal):
    """A flat bar from a to b (a box, its thin side along the plane normal)."""
    length = float(np.linalg.norm(b - a))
    return coal.Box(length + width, width, 0.5 * width), _frame(0.5 * (a + b), (b - a) / length, normal)


def _frame(centre: np.ndarray, x_axis: np.ndarray, normal: np.ndarray | None) -> pin.SE3:
    """A placement at `centre` whose x axis is `x_axis` and z axis the plane normal (if any)."""
    x = x_axis / np.linalg.norm(x_axis)
    z = normal if normal is not None else np.array([0.0, 0.0, 1.0])
    z = z - x * (x @ z)
    if np.linalg.norm(z) < 1e-9:
        z = np.array([0.0, 1.0, 0.0]) - x * x[1]
    z = z / np.linalg.norm(z)
    return pin.SE3(np.column_stack([x, np.cross(z, x), z]), np.asarray(centre, float))
