"""A planar linkage written as drawn (TOML) -> a URDF with `<constraint>` loop cuts.

Mechanism people think in joint coordinates on a drawing. A linkage file gives every
joint's world coordinates at one drawn pose, the links and the joints and points each
carries, sliders and pin-in-slot joints one line each. `pinmech.model.linkage_spec` reads
and validates the file once into a `LinkageSpec`; this module turns a spec into the
`Linkage` graph at the drawn pose (lengths and angles in SI, constructions drawn, pins
split into pairs); `pinmech.model.linkage_urdf` picks a spanning tree (breadth first from
the ground), turns every other joint into one loop cut and writes the URDF, whose
reference configuration is the drawn pose; `load_linkage` makes the Mechanism. See the
docs page docs/howto/linkage_toml.md for the format.

Conventions of the generated URDF (all in the plane z = 0, axes along z):
  * every link's frame sits on its parent joint, its x axis from the first point the link
    lists to the next, so a link's reported angle is the textbook phi of that bar;
  * a pin's coordinate is the angle between the x axes of its two links [rad], a
    slider's the displacement of its block from the drawn position along the line [m];
  * those coordinates at the drawn pose are the mechanism's reference: the default guess.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pinmech.exceptions import ModelError
from pinmech.model.compass import compass
from pinmech.model.linkage_expr import is_angle, length, quantity_si
from pinmech.model.linkage_masses import LinkMass, parse_masses
from pinmech.directions import unit_vector
from pinmech.model.linkage_entries import Bearing
from pinmech.model.linkage_spec import GROUND, Compass, LinkageSpec, Polar, Slot, read_linkage_spec


@dataclass(frozen=True)
class Edge:
    """One joint between two links of the graph: a pin (revolute) or a slide (prismatic).

    Attributes:
        name: the URDF joint (or cut) name.
        kind: "revolute" or "prismatic".
        links: the two links it joins.
        at: its point in the world at the drawn pose [m] (x, y).
        direction: unit direction of a slide, world frame at the drawn pose.
        axis: unit axis of a pin in a spatial linkage, world frame at the drawn pose.
    """

    name: str
    kind: str
    links: tuple[str, str]
    at: np.ndarray
    direction: np.ndarray | None = None
    axis: np.ndarray | None = None


@dataclass
class Linkage:
    """A drawn linkage, parsed and validated: SI units, world frame, at the drawn pose.

    Attributes:
        points: every named point's world position [m] (joints and points of interest).
        links: link name -> the names it carries, in the order written.
        edges: every joint of the graph (pins split into pairs, slots into pin + slide).
        point_links: named point -> the one link it is fixed on.
        blocks: block link -> the slide it moves on (sliders' blocks, slots' hidden blocks).
        hidden: links added for pin-in-slot joints (no visual of their own).
        spatial: points are 3-D (x, y, z) and pins have their own axes (`[axes]`), balls
            (`balls = [...]`) are spherical joints; else planar, in z = 0, axes along z.
        masses: link -> its mass, as `[masses]` states it (`pinmech.model.linkage_masses`); a
            link not there has none.
    """

    source: str
    title: str
    points: dict[str, np.ndarray]
    links: dict[str, list[str]]
    edges: list[Edge]
    point_links: dict[str, str]
    blocks: dict[str, Edge] = field(default_factory=dict)
    hidden: set[str] = field(default_factory=set)
    spatial: bool = False
    axes: dict[str, np.ndarray] = field(default_factory=dict)
    balls: set[str] = field(default_factory=set)
    masses: dict[str, LinkMass] = field(default_factory=dict)


# ------------------------------------------------------------------------- reading
def parse_linkage(path: str | Path) -> Linkage:
    """Read a linkage file: validated once (`read_linkage_spec`), then drawn (`linkage_from_spec`).

    Raises:
        ModelError: a missing file, malformed TOML, an unknown key or name, a value without
            units, a construction that cannot be drawn (circles that do not meet).
    """
    spec, source = read_linkage_spec(path)
    return linkage_from_spec(spec, source)


def linkage_from_spec(spec: LinkageSpec, source: str = "<linkage>", values: dict[str, float] | None = None
                      ) -> Linkage:
    """The linkage a spec draws: lengths and angles in SI, the drawn pose constructed.

    Args:
        spec: a validated linkage (`read_linkage_spec`, `linkage_spec`, or built in code).
        source: the file's name for messages (its stem is the default title).
        values: every `[params]` value as a length [m], instead of the spec's own (a design
            study's or a synthesis candidate's redrawing: no text read again).

    Raises:
        ModelError: a quantity without units or of the wrong kind, a construction that
            cannot be drawn, names that clash in the URDF it would write.
    """
    reader = _Reader(source, spec.params, values)
    points = reader.points(spec.joints)
    links = {GROUND: list(spec.ground), **{name: list(names) for name, names in spec.links.items()}}
    title = spec.title if spec.title is not None else Path(source).stem
    linkage = Linkage(source, title, points, links, [], {})
    _spatial(linkage, spec)
    _pins(linkage)
    _distinct_pins(linkage)
    for name, slider in spec.sliders.items():
        edge = Edge(name, "prismatic", (slider.on, slider.block), linkage.points[slider.at],
                    _direction(linkage, reader, slider.along, linkage.points[slider.at], f"[sliders] {name}"))
        linkage.edges.append(edge)
        linkage.blocks[slider.block] = edge
    for name, slot in spec.slots.items():
        _slot(linkage, reader, name, slot)
    _check_names(linkage)
    _masses(linkage, reader, spec)
    return linkage


def linkage_params(spec: LinkageSpec, source: str = "<linkage>") -> dict[str, float]:
    """The spec's parameters in SI, in the order written (a study's named dimensions): lengths
    [m], and angles [rad] for those written with an angle's unit (`param_kinds`).

    Raises:
        ModelError: a parameter that is no length nor angle (naming `[params] NAME`).
    """
    reader = _Reader(source, spec.params)
    return {name: reader.params.get(name, reader.angles.get(name)) for name in spec.params}


def param_kinds(spec: LinkageSpec) -> dict[str, str]:
    """Each parameter's kind: "angle" where written as one quantity with an angle's unit
    ("25 deg"), else "length"."""
    return {name: "angle" if is_angle(value) else "length" for name, value in spec.params.items()}


def _masses(linkage: Linkage, reader: _Reader, spec: LinkageSpec) -> None:
    """`[masses]`: the links' masses as stated (`pinmech.model.linkage_masses`), none invented."""
    linkage.masses = parse_masses(spec.masses, linkage.points, linkage.spatial, reader.length, linkage.source)
    for link, stated in linkage.masses.items():
        if stated.centre.size == 3 and not linkage.spatial and stated.centre[2] == 0.0:
            linkage.masses[link] = LinkMass(stated.mass, stated.centre[:2], stated.inertia)  # in the plane
        elif stated.centre.size == 3 and not linkage.spatial:
            raise ModelError("a planar linkage's centre of mass is [x, y]", path=linkage.source,
                             element=f"[masses] {link}")
        if linkage.spatial and stated.centre.size == 2:
            linkage.masses[link] = LinkMass(stated.mass, np.append(stated.centre, 0.0), stated.inertia)


class _Reader:
    """Lengths and angles of one file: quantities with units, or names of `[params]`
    (lengths, and angles: a parameter written with an angle's unit, used by its name)."""

    def __init__(self, source: str, params: dict[str, Any], values: dict[str, float] | None = None):
        self.source = source
        self.params: dict[str, float] = {}  # the length parameters [m]
        self.angles: dict[str, float] = {}  # the angle parameters [rad]
        for name, value in params.items():  # in the order written: a parameter may use earlier ones
            angle = is_angle(value)
            if values is not None:  # already in SI, one for every parameter
                (self.angles if angle else self.params)[name] = float(values[name])
            elif angle:
                self.angles[name] = self.angle(value, f"[params] {name}")
            else:
                self.params[name] = self.length(value, f"[params] {name}")

    def length(self, value: Any, where: str) -> float:
        """A length [m]: "15 mm", a parameter name "crank", or an expression "-a", "2*a + b"
        (see `pinmech.model.linkage_expr`)."""
        if isinstance(value, str) and value.strip() in self.angles:
            raise ModelError(f"'{value.strip()}' is an angle parameter ({self.angles[value.strip()] * 180 / math.pi:.6g}"
                             " deg) where a length is needed", path=self.source, element=where)
        return length(value, self.params, self.source, where)

    def angle(self, value: Any, where: str) -> float:
        """An angle [rad]: "30 deg", or the name of an angle parameter ("gamma")."""
        if isinstance(value, str) and value.strip() in self.angles:
            return self.angles[value.strip()]
        return quantity_si(value, "angle", self.source, where)

    def points(self, joints: dict[str, tuple | Polar | Compass | Bearing]) -> dict[str, np.ndarray]:
        """World positions of `[joints]`, in the order written (constructions use earlier ones)."""
        out: dict[str, np.ndarray] = {}
        for name, spec in joints.items():
            where = f"[joints] {name}"
            if isinstance(spec, Polar):
                r, phi = self.length(spec.length, f"{where} length"), self.angle(spec.angle, f"{where} angle")
                base = out[spec.base]  # in 3-D: in the plane z = the base's z (the angle from x, seen from +z)
                out[name] = base + r * np.array([math.cos(phi), math.sin(phi), 0.0][: base.size])
            elif isinstance(spec, Compass):
                r1, r2 = (self.length(v, f"{where} lengths") for v in spec.lengths)
                a, b = _level(out[spec.bases[0]], out[spec.bases[1]], list(spec.bases), self.source, where)
                point = _compass(a[:2], b[:2], r1, r2, spec.side == "left", f"{self.source}, {where}")
                out[name] = np.append(point, a[2]) if a.size == 3 else point
            elif isinstance(spec, Bearing):
                out[name] = self._bearing(spec, out, where)
            else:
                out[name] = np.array([self.length(v, f"{where} {c}") for v, c in zip(spec, "xyz")])
        return out

    def _bearing(self, spec: Bearing, out: dict[str, np.ndarray], where: str) -> np.ndarray:
        """At `length` from A, turned `angle` from A -> B (seen from +z, in the plane z = z_A) [m]."""
        r, gamma = self.length(spec.length, f"{where} length"), self.angle(spec.angle, f"{where} angle")
        a, b = _level(out[spec.bases[0]], out[spec.bases[1]], list(spec.bases), self.source, where, "bearing")
        d = float(np.linalg.norm(b[:2] - a[:2]))
        if d == 0:
            raise ModelError(f"cannot be drawn: {spec.bases[0]} and {spec.bases[1]} are at one place, so the line "
                             "the angle is measured from has no direction", path=self.source, element=where)
        u = (b[:2] - a[:2]) / d
        c, s = math.cos(gamma), math.sin(gamma)
        point = a[:2] + r * np.array([c * u[0] - s * u[1], s * u[0] + c * u[1]])
        return np.append(point, a[2]) if a.size == 3 else point


def _level(a: np.ndarray, b: np.ndarray, names: list[str], source: str, where: str, kind: str = "compass"
           ) -> tuple[np.ndarray, np.ndarray]:
    """The two bases of a compass construction, both 2-D or both 3-D at one z [m]: left and
    right of A -> B are seen from +z, so the circles are drawn in the plane z = z_A.

    Raises:
        ModelError: bases at different heights (the circles' plane would be a guess).
    """
    if a.size == b.size == 2:
        return a, b
    a, b = (np.append(p, 0.0) if p.size == 2 else p for p in (a, b))
    if abs(a[2] - b[2]) > 1e-12 * max(float(np.linalg.norm(b - a)), float(np.max(np.abs(a))), 1e-300):
        raise ModelError(f"a {kind} construction draws in a plane z = constant, but {names[0]} is at z = "
                         f"{a[2]:.6g} m and {names[1]} at z = {b[2]:.6g} m: give this joint's [x, y, z]",
                         path=source, element=where)
    return a, b


def _compass(a: np.ndarray, b: np.ndarray, r1: float, r2: float, left: bool, where: str) -> np.ndarray:
    """The point at r1 from a and r2 from b, left or right of a -> b [m]."""
    d = float(np.linalg.norm(b - a))
    if d == 0 or r1 <= 0 or r2 <= 0 or r1 + r2 < d or abs(r1 - r2) > d:
        raise ModelError(f"cannot be drawn: circles of radii {r1:.6g} m and {r2:.6g} m about points "
                         f"{d:.6g} m apart do not meet (the linkage cannot be assembled here)", path=where)
    return compass(a, b, r1, r2, 1.0 if left else -1.0)[0]


def _spatial(linkage: Linkage, spec: LinkageSpec) -> None:
    """3-D coordinates, `[axes]` or `balls`: a spatial linkage (2-D entries lie in z = 0)."""
    linkage.spatial = bool(spec.axes or spec.balls or any(p.size == 3 for p in linkage.points.values()))
    if not linkage.spatial:
        return
    linkage.points = {n: np.append(p, 0.0) if p.size == 2 else p for n, p in linkage.points.items()}
    z = np.array([0.0, 0.0, 1.0])
    for name in linkage.points:
        linkage.axes[name] = z
    for name, value in spec.axes.items():
        linkage.axes[name] = unit_vector(value)
    linkage.balls = set(spec.balls)
    if _drawn_in_plane(linkage, spec):  # z = 0 and axes +z written out: the planar linkage it draws
        linkage.spatial, linkage.axes = False, {}
        linkage.points = {n: p[:2] for n, p in linkage.points.items()}


def _drawn_in_plane(linkage: Linkage, spec: LinkageSpec) -> bool:
    """Every point at z = 0, every axis +z, no ball and no spatial inertia: a planar linkage
    written in 3-D, read as one (else its driver angles would count from the drawing, not
    from world x, because a third "0 mm" or a default axis was written out)."""
    spatial_mass = any(m.inertia is not None for m in spec.masses.values())
    return (not linkage.balls and not spatial_mass and all(p[2] == 0.0 for p in linkage.points.values())
            and all(a.tolist() == [0.0, 0.0, 1.0] for a in linkage.axes.values()))


def _pins(linkage: Linkage) -> None:
    """Names on two or more links become pins (split into pairs), on one link points."""
    carriers: dict[str, list[str]] = {}
    for link, names in linkage.links.items():
        for name in names:
            carriers.setdefault(name, []).append(link)
    for name, on in carriers.items():
        if len(on) == 1:
            linkage.point_links[name] = on[0]
            continue
        kind = "spherical" if name in linkage.balls else "revolute"
        for other in on[1:]:
            label = name if len(on) == 2 else f"{name}_{other}"
            linkage.edges.append(Edge(label, kind, (on[0], other), linkage.points[name],
                                      axis=linkage.axes.get(name) if linkage.spatial else None))


#: Two pins of one link closer than this share of the drawing's extent are one place: the
#: link between them has no length and the joints it would join coincide (another
#: linkage, e.g. a crank drawn with crank = "0 mm"). Rounding of a drawing is 1e-15 of it.
COINCIDENT_PINS = 1e-9


def _distinct_pins(linkage: Linkage) -> None:
    """Refuse a link two of whose pins are drawn at one place (ModelError naming both)."""
    xyz = np.array(list(linkage.points.values()), dtype=float)
    size = float(np.max(np.ptp(xyz, axis=0))) if len(xyz) > 1 else 0.0
    for link, names in linkage.links.items():
        pins = [n for n in dict.fromkeys(names) if n not in linkage.point_links]
        for i, a in enumerate(pins):
            for b in pins[i + 1:]:
                gap = float(np.linalg.norm(linkage.points[a] - linkage.points[b]))
                if gap <= COINCIDENT_PINS * size and not _crossed_axes(linkage, a, b):
                    raise ModelError(f"[links] {link}: its pins {a} and {b} are drawn {gap * 1e3:.3g} mm apart, at one "
                                     f"place (a link of no length: the joints it joins would coincide); draw them apart",
                                     path=linkage.source)


def _crossed_axes(linkage: Linkage, a: str, b: str) -> bool:
    """Two pins at one place whose axes are not parallel: a universal joint's cross, drawn
    so in a spatial linkage (its two revolutes meet at the cross's centre)."""
    u, w = linkage.axes.get(a), linkage.axes.get(b)
    if u is None or w is None:
        return False
    u, w = np.asarray(u, dtype=float), np.asarray(w, dtype=float)
    return float(np.linalg.norm(np.cross(u, w))) > 1e-9 * float(np.linalg.norm(u) * np.linalg.norm(w))


def _direction(linkage: Linkage, reader: _Reader, along: Any, at: np.ndarray, where: str) -> np.ndarray:
    """`along = "30 deg"` or `along = ["A", "B"]`: a unit direction in the world [-]."""
    if isinstance(along, tuple):
        vector = linkage.points[along[1]] - linkage.points[along[0]]
        if np.linalg.norm(vector) < 1e-12 * max(1.0, float(np.linalg.norm(at))):
            raise ModelError(f"along = {list(along)!r}: the two joints coincide, so they give no direction",
                             path=linkage.source, element=where)
        return vector / np.linalg.norm(vector)
    phi = reader.angle(along, f"{where} along")
    return np.array([math.cos(phi), math.sin(phi), 0.0][: at.size])


def _slot(linkage: Linkage, reader: _Reader, name: str, slot: Slot) -> None:
    """`A = {pin = "crank", slot = "rocker", along = ["O4", "A"]}`: a pin sliding in a slot."""
    where = f"[slots] {name}"
    if linkage.spatial:
        raise ModelError("pin-in-slot joints are planar only: in a spatial linkage, give the block as a link "
                         "with a slider and a pin", path=linkage.source, element=where)
    at = linkage.points[name]
    block = f"{name}_block"
    linkage.links[block] = [name]
    linkage.hidden.add(block)
    linkage.edges.append(Edge(f"{name}_pin", "revolute", (slot.pin, block), at))
    edge = Edge(f"{name}_slide", "prismatic", (slot.slot, block), at, _direction(linkage, reader, slot.along, at, where))
    linkage.edges.append(edge)
    linkage.blocks[block] = edge
    linkage.point_links.pop(name, None)


def _check_names(linkage: Linkage) -> None:
    """Links, points and joints share one namespace in the URDF."""
    seen: dict[str, str] = {}
    for kind, names in (("link", linkage.links), ("point", linkage.point_links),
                        ("joint", [e.name for e in linkage.edges])):
        for name in names:
            if not name.strip() or not name.isprintable():
                raise ModelError(f"the {kind} name {name!r} is empty or holds a control character: names go "
                                 "into the generated URDF and the reports", path=linkage.source)
            if name in seen and not (kind == "point" and seen[name] == "link"):
                raise ModelError(f"'{name}' names both a {seen[name]} and a {kind}: rename one",
                                 path=linkage.source)
            seen.setdefault(name, kind)
    for link, names in linkage.links.items():
        if link != GROUND and not names:
            raise ModelError("lists no joint", path=linkage.source, element=f"[links] {link}")
    for name, what in _generated_names(linkage).items():
        if name in seen:
            raise ModelError(f"{seen[name]} '{name}' has the name pinmech gives {what} in the URDF it writes: "
                             f"rename the {seen[name]}", path=linkage.source)


def _generated_names(linkage: Linkage) -> dict[str, str]:
    """URDF names pinmech makes up (a point's fixed joint, a ball's hinges and the links
    between them), with what each names: a user's name equal to one would make two URDF
    elements of one name (Pinocchio then refuses the generated file)."""
    out = {f"point_{p}": f"point {p}'s fixed joint" for p in linkage.point_links}
    for edge in linkage.edges:
        if edge.kind == "spherical":
            out.update({f"{edge.name}_{x}": f"ball {edge.name}'s hinge about {x}" for x in "xyz"})
            out.update({f"{edge.name}_r{x}": f"ball {edge.name}'s link between hinges" for x in "xy"})
    return out
