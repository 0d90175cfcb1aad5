"""Velocity and acceleration polygons of a solved planar pose, as the graphical method draws them.

Every point P has an image p (p' for accelerations) drawn from the pole o (o'): the vector
o->p is v_P. Points of one rigid link are joined by their relative velocity b->p = v_PB =
w x BP; in the acceleration polygon the relative acceleration is drawn as its normal part
a^n_PB = -w^2 BP (towards B) then its tangential part a^t_PB = alpha x BP. A point of one
link under a point of another (B3 of the guide under the slider pin B) is joined by the
sliding velocity v_rel = v_B - v_B3, and in accelerations by the Coriolis part
2 w x v_rel (w of the guide) then the sliding acceleration a_rel. The points of a link are
taken in a chain, a fixed pivot first: C, then B3 about C, then D about B3.

Which points share a link: the link a point hangs on, and the links a pin at its place
joins (`pinmech.model.link_nodes`). The numbers are pinmech's (`Analysis.motion`); the polygon is
their picture, and `Polygon.closure_error` says how well the chains of components land on
the images (the rigid-body formulas against Pinocchio's point accelerations).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.arguments import instance_of
from pinmech.model.display import colour_of, display_names, hex_colour
from pinmech.draw.inputs import DrawError
from pinmech.model.link_nodes import pin_links, sketch_links, world_nodes
from pinmech.solve.motion import PointMotion, _plane_reference, evaluate_motion
from pinmech.io.analysis_result import Analysis
from pinmech.io.scene_model import coincident_points

KINDS = {
    "absolute": "from the pole",
    "relative": "relative, points of one link",
    "sliding": "sliding, relative to the guide",
    "normal": "normal part, -ω² r",
    "tangential": "tangential part, α × r",
    "coriolis": "Coriolis part, 2 ω × v_rel",
}


@dataclass(frozen=True)
class PolygonVector:
    """One drawn vector, in plane coordinates [m/s or m/s^2].

    Attributes:
        kind: one of KINDS.
        tail, head: its ends, shape (2,), from the pole.
        start, end: labels of the image points it joins ("" for a point between components).
        label: the textbook's name of the vector (v_B, v_DC, a^n_DC, ...).
    """

    kind: str
    tail: np.ndarray
    head: np.ndarray
    start: str
    end: str
    label: str


@dataclass(frozen=True)
class Polygon:
    """A velocity or acceleration polygon.

    Attributes:
        quantity: "velocity" or "acceleration".
        unit: "m/s" or "m/s^2".
        images: image label (o, a, b, ... or o', a', ...) -> its place, shape (2,).
        labels: point name -> its image label.
        vectors: what is drawn, absolute vectors first.
        axes: the plane's x and y axes in world coordinates, shape (2, 3).
        title: what the polygon shows (scene, driver value and rates).
        figures: moving link -> the image labels of its places (fixed pivots first): the
            link's velocity (acceleration) image, similar to the link.
        colours: moving link -> its colour (`pinmech.model.display`), "#rrggbb".
    """

    quantity: str
    unit: str
    images: dict[str, np.ndarray]
    labels: dict[str, str]
    vectors: list[PolygonVector]
    axes: np.ndarray
    title: str
    figures: dict[str, list[str]]
    colours: dict[str, str]

    @property
    def closure_error(self) -> float:
        """Largest gap between a chain of relative components and the image it should reach
        [m/s or m/s^2]: 0 up to rounding when the rigid-body relations hold."""
        gaps = [np.linalg.norm(v.head - self.images[v.end]) for v in self.vectors if v.end]
        return float(max(gaps, default=0.0))


def velocity_polygon(analysis: Analysis) -> Polygon:
    """The velocity polygon of a solved planar pose."""
    instance_of(analysis, Analysis, "velocity_polygon's analysis")
    return _polygon(analysis, "velocity")


def acceleration_polygon(analysis: Analysis) -> Polygon:
    """The acceleration polygon of a solved planar pose (normal, tangential, Coriolis parts)."""
    instance_of(analysis, Analysis, "acceleration_polygon's analysis")
    return _polygon(analysis, "acceleration")


def _polygon(analysis: Analysis, quantity: str) -> Polygon:
    mech = analysis.mechanism
    normal = mech.plane_normal
    if normal is None:
        raise DrawError(f"{analysis.scene.path}: velocity and acceleration polygons are drawn for planar "
                        f"mechanisms; {mech.source} moves in space", argument="scene", value=str(analysis.scene.path))
    e1 = _plane_reference(*normal.tolist())
    axes = np.array([e1, np.cross(normal, e1)])
    acc = quantity == "acceleration"
    prime = "'" if acc else ""
    places, members = _places_and_links(analysis)
    shown = display_names(mech)
    labels = {name: _image_label(shown.get(name, name), place, prime) for name, place in places.items()}
    images = {"o" + prime: np.zeros(2)}
    for name, place in places.items():
        images[labels[name]] = axes @ (place.acceleration if acc else place.velocity)
    vectors = [PolygonVector("absolute", np.zeros(2), images[labels[n]], "o" + prime, labels[n],
                             f"{quantity[0]}_{shown.get(n, n)}")
               for n in places if np.linalg.norm(images[labels[n]]) > 0]
    coincident = [c for c in coincident_points(analysis.scene) if c.name in labels and c.at in labels]
    rates = _link_rates(analysis, [*members, *(c.link for c in coincident)])
    for link, names in members.items():
        for base, name in itertools.pairwise(names):  # a chain: each point about the one before
            vectors += _relative(places, shown, axes, labels, images, base, name, *rates[link], acc)
    for c in coincident:
        vectors += _sliding(places, shown, axes, labels, images, c, rates[c.link][0], acc)
    drawn = _drawn(vectors, images)
    if not drawn:
        raise DrawError(f"{analysis.scene.path}: no reported point has a {quantity}: nothing to draw in the "
                        f"{quantity} polygon; report moving points ([report] points)", argument="scene",
                        value=list(labels))
    figures = {link: [labels[n] for n in names] for link, names in members.items()}
    colours = {link: hex_colour(colour_of(mech, link)) for link in members}
    return Polygon(quantity, "m/s^2" if acc else "m/s", images, labels, drawn, axes, _title(analysis, quantity),
                   figures, colours)


def _image_label(shown: str, place: PointMotion, prime: str) -> str:
    """A point's image label: its printed name in lower case (a moving point that would read
    as the pole "o" keeps its capital)."""
    moving = np.linalg.norm(place.velocity) > 0 or np.linalg.norm(place.acceleration) > 0
    return (shown if moving and shown.lower() == "o" else shown.lower()) + prime


def _drawn(vectors: list[PolygonVector], images: dict[str, np.ndarray]) -> list[PolygonVector]:
    """The vectors worth drawing: none of zero length, and none drawn twice (a relative
    vector from a fixed pivot's image is the absolute one: o->b is v_B and v_BA)."""
    tol = 1e-9 * max((np.linalg.norm(v) for v in images.values()), default=0.0)
    absolute = [v for v in vectors if v.kind == "absolute"]

    def twice(v: PolygonVector) -> bool:
        return v.kind != "absolute" and any(
            np.linalg.norm(v.tail - a.tail) <= tol and np.linalg.norm(v.head - a.head) <= tol for a in absolute)

    return [v for v in vectors if np.linalg.norm(v.head - v.tail) > tol and not twice(v)]


def _places_and_links(analysis: Analysis) -> tuple[dict[str, PointMotion], dict[str, list[str]]]:
    """The reported points, the pins the report leaves out and the fixed pivots of the moving
    links (at rest, image at the pole), and moving link -> the places on it (a pin's on both links), fixed ones first,
    then in the report's order. The fixed pivots let a point at the end of a rocker be
    reached by both routes of the graphical method: about the coupler's pin and about the
    rocker's pivot."""
    mech, motion = analysis.mechanism, analysis.motion
    coincident = {c.name for c in coincident_points(analysis.scene)}
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, analysis.solution.q)
    sketches = sketch_links(mech)
    joint_of = {name: sketch.joint for name, sketch in sketches.items()}
    places = dict(motion.points)
    places.update(_fixed_pivots(sketches, data, places, mech.length_scale))
    places.update(_moving_pins(analysis, sketches, data, places))
    members: dict[str, list[str]] = {}
    for name, p in places.items():
        on = {p.link} if name in coincident else {p.link, *pin_links(sketches, data, p.position, mech.length_scale)}
        for link in on:
            if joint_of.get(link, 0) != 0 and link in mech.links:
                members.setdefault(link, []).append(name)
    for names in members.values():
        names.sort(key=lambda n: np.linalg.norm(places[n].velocity) > 0)  # stable: fixed pivots first
    return places, {link: names for link, names in members.items() if len(names) > 1}


def _fixed_pivots(sketches: dict, data: pin.Data, reported: dict[str, PointMotion],
                  scale: float) -> dict[str, PointMotion]:
    """The ground's pins that no reported point marks, as points at rest on the ground."""
    ground = next((s for s in sketches.values() if s.is_ground), None)
    if ground is None:
        return {}
    out = {}
    for node, p in zip(ground.nodes, world_nodes(ground, data)):
        taken = any(np.linalg.norm(p - q.position) <= 1e-6 * scale for q in [*reported.values(), *out.values()])
        if node.kind == "revolute" and not taken and node.name not in reported:
            out[node.name] = PointMotion(p, np.zeros(3), np.zeros(3), ground.name)
    return out


def _moving_pins(analysis: Analysis, sketches: dict, data: pin.Data,
                 shown: dict[str, PointMotion]) -> dict[str, PointMotion]:
    """The pins between moving links that no reported point marks (a polygon draws every
    pin, as the graphical method does, whatever the scene reports), read off the solved pose
    at the pin joint's frame."""
    mech, scale = analysis.mechanism, analysis.mechanism.length_scale
    found: dict[str, np.ndarray] = {}
    for sketch in sketches.values():
        if sketch.is_ground:
            continue
        for node, p in zip(sketch.nodes, world_nodes(sketch, data)):
            taken = any(np.linalg.norm(p - q.position) <= 1e-6 * scale for q in shown.values()) or any(
                np.linalg.norm(p - q) <= 1e-6 * scale for q in found.values())
            if node.kind == "revolute" and not taken and node.name not in shown and mech.model.existFrame(node.name):
                found[node.name] = p
    if not found:
        return {}
    sol = analysis.solution
    motion = evaluate_motion(mech, mech.model.createData(), sol.q, sol.v, sol.a, points=list(found), links=[])
    return {name: m for name, m in motion.points.items()
            if np.linalg.norm(m.position - found[name]) <= 1e-6 * scale}  # the frame is at the pin


def _link_rates(analysis: Analysis, links: list[str]) -> dict[str, tuple[float, float]]:
    """Link -> its angular velocity [rad/s] and acceleration [rad/s^2] about the plane normal,
    read off the solved pose (also for links the scene does not report)."""
    mech, sol = analysis.mechanism, analysis.solution
    motion = evaluate_motion(mech, mech.model.createData(), sol.q, sol.v, sol.a, points=[], links=sorted(set(links)))
    n = mech.plane_normal
    return {name: (float(n @ m.angular_velocity), float(n @ m.angular_acceleration))
            for name, m in motion.links.items()}


def _relative(places, shown, axes, labels, images, base: str, name: str, w: float, alpha: float,
              acc: bool) -> list[PolygonVector]:
    """The relative motion of `name` about `base`, points of one link turning at w [rad/s],
    alpha [rad/s^2]."""
    r = axes @ (places[name].position - places[base].position)
    tail, end = images[labels[base]], labels[name]
    pair = f"{shown.get(name, name)}{shown.get(base, base)}"
    if not acc:
        return [PolygonVector("relative", tail, images[end], labels[base], end, f"v_{pair}")]
    normal = -w * w * r
    tangential = alpha * np.array([-r[1], r[0]])
    return [PolygonVector("normal", tail, tail + normal, labels[base], "", f"a^n_{pair}"),
            PolygonVector("tangential", tail + normal, tail + normal + tangential, "", end, f"a^t_{pair}")]


def _sliding(places, shown, axes, labels, images, c, w: float, acc: bool) -> list[PolygonVector]:
    """The point `c.at` about the point `c.name` of the guide link under it (turning at w [rad/s])."""
    on_guide, moving = places[c.name], places[c.at]
    v_rel = axes @ (moving.velocity - on_guide.velocity)
    tail, end = images[labels[c.name]], labels[c.at]
    pair = f"{shown.get(c.at, c.at)}{shown.get(c.name, c.name)}"
    if not acc:
        return [PolygonVector("sliding", tail, images[end], labels[c.name], end, f"v_{pair}")]
    coriolis = 2.0 * w * np.array([-v_rel[1], v_rel[0]])
    return [PolygonVector("coriolis", tail, tail + coriolis, labels[c.name], "", f"a^c_{pair}"),
            PolygonVector("sliding", tail + coriolis, images[end], "", end, f"a^r_{pair}")]


def _title(analysis: Analysis, quantity: str) -> str:
    scene = analysis.scene
    drivers = "; ".join(f"{n}: " + ", ".join(str(v) for _, _, v in spec.given())
                        for n, spec in scene.file.drivers.items())
    return f"{quantity.capitalize()} polygon: {scene.title}" + (f" ({drivers})" if drivers else "")
