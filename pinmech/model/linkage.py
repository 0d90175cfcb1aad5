"""A planar linkage written as drawn (TOML) -> a URDF with `<constraint>` loop cuts.

Mechanism people think in joint coordinates on a drawing. A linkage file gives every
joint's world coordinates at one drawn pose, the links and the joints and points each
carries, sliders and pin-in-slot joints one line each; this module picks a spanning tree
(breadth first from the ground), turns every other joint into one loop cut, and writes a
URDF whose reference configuration is the drawn pose. See the docs page
docs/howto/linkage_toml.md for the format; `parse_linkage` reads and validates it once,
`pinmech.model.linkage_urdf` writes the URDF text, `load_linkage` makes the Mechanism.

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

from pinmech.arguments import file_path
from pinmech.directions import unit_vector, written
from pinmech.exceptions import ModelError, UnitError
from pinmech.model.linkage_expr import check_param_name, length
from pinmech.model.linkage_masses import LinkMass, parse_masses
from pinmech.units import to_si

from pinmech.toml_file import read_toml

GROUND = "ground"
_KEYS = {"title", "ground", "params", "joints", "links", "sliders", "slots", "colors", "axes", "balls", "masses"}

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
    """Read a linkage file: values with units, names checked, the drawn pose constructed.

    Raises:
        ModelError: a missing file, malformed TOML, an unknown key or name, a value without
            units, a construction that cannot be drawn (circles that do not meet).
    """
    path = file_path(path, "the linkage file")
    source = str(path)
    raw = read_toml(path, "linkage", ModelError)
    unknown = set(raw) - _KEYS
    if unknown:
        raise ModelError(f"unknown key(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_KEYS))}",
                         path=source)
    reader = _Reader(source, _table(raw, "params", source))
    points = reader.points(_table(raw, "joints", source))
    ground = _names(raw.get("ground", []), "ground", source)
    links = {GROUND: list(ground)}
    for name, value in _table(raw, "links", source).items():
        if name == GROUND:
            raise ModelError("the ground is listed by ground = [...], not as a link", path=source,
                             element="[links] ground")
        links[name] = _names(value, f"[links] {name}", source)
    for link, names in links.items():
        for name in names:
            if name not in points:
                raise ModelError(f"names joint '{name}', which [joints] does not give", path=source,
                                 element=f"[links] {link}" if link != GROUND else "ground")
    if len(links) < 2:
        raise ModelError("no link: list the moving links under [links]", path=source)
    linkage = Linkage(source, str(raw.get("title", path.stem)), points, links, [], {})
    _spatial(linkage, raw, source)
    _pins(linkage)
    for name, spec in _table(raw, "sliders", source).items():
        _slider(linkage, reader, name, spec)
    for name, spec in _table(raw, "slots", source).items():
        _slot(linkage, reader, name, spec)
    _check_names(linkage)
    _masses(linkage, reader, raw.get("masses", {}))
    return linkage


def _masses(linkage: Linkage, reader: _Reader, table: Any) -> None:
    """`[masses]`: the links' masses as stated (`pinmech.model.linkage_masses`), none invented."""
    links = {n: v for n, v in linkage.links.items() if n not in linkage.hidden}
    linkage.masses = parse_masses(table, links, linkage.points, linkage.spatial, reader.length, linkage.source)
    for link, stated in linkage.masses.items():
        if stated.centre.size == 3 and not linkage.spatial and stated.centre[2] == 0.0:
            linkage.masses[link] = LinkMass(stated.mass, stated.centre[:2], stated.inertia)  # in the plane
        elif stated.centre.size == 3 and not linkage.spatial:
            raise ModelError("a planar linkage's centre of mass is [x, y]", path=linkage.source,
                             element=f"[masses] {link}")
        if linkage.spatial and stated.centre.size == 2:
            linkage.masses[link] = LinkMass(stated.mass, np.append(stated.centre, 0.0), stated.inertia)


def _table(raw: dict[str, Any], key: str, source: str) -> dict[str, Any]:
    value = raw.get(key, {})
    if not isinstance(value, dict):
        raise ModelError(f"[{key}] must be a table", path=source, element=key)
    return value


def _names(value: Any, where: str, source: str) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(n, str) for n in value):
        raise ModelError(f"must be a list of joint names, e.g. [\"A\", \"B\"], got {value!r}", path=source,
                         element=where)
    if len(set(value)) != len(value):
        raise ModelError(f"lists a joint twice: {value}", path=source, element=where)
    return list(value)


class _Reader:
    """Lengths and angles of one file: quantities with units, or names of `[params]`."""

    def __init__(self, source: str, params: dict[str, Any]):
        self.source = source
        self.params: dict[str, float] = {}
        for name, value in params.items():  # in the order written: a parameter may use earlier ones
            check_param_name(name, source)
            self.params[name] = self.length(value, f"[params] {name}")

    def length(self, value: Any, where: str) -> float:
        """A length [m]: "15 mm", a parameter name "crank", or an expression "-a", "2*a + b"
        (see `pinmech.model.linkage_expr`)."""
        return length(value, self.params, self.source, where)

    def _quantity(self, value: Any, kind: str, where: str) -> float:
        try:
            return to_si(value, kind, where=where)
        except UnitError as exc:
            raise ModelError(str(exc), path=self.source) from exc

    def angle(self, value: Any, where: str) -> float:
        return self._quantity(value, "angle", where)

    def points(self, table: dict[str, Any]) -> dict[str, np.ndarray]:
        """World positions of `[joints]`, in the order written (constructions use earlier ones)."""
        out: dict[str, np.ndarray] = {}
        for name, spec in table.items():
            where = f"[joints] {name}"
            if isinstance(spec, list):
                if len(spec) not in (2, 3):
                    raise ModelError(f"give coordinates [x, y] (or [x, y, z]) with units, got {spec!r}",
                                     path=self.source, element=where)
                out[name] = np.array([self.length(v, f"{where} {c}") for v, c in zip(spec, "xyz")])
            elif isinstance(spec, dict):
                out[name] = self._construction(name, spec, out, where)
            else:
                raise ModelError(f"give [x, y] with units or a construction table, got {spec!r}",
                                 path=self.source, element=where)
        return out

    def _construction(self, name: str, spec: dict[str, Any], known: dict[str, np.ndarray], where: str) -> np.ndarray:
        """`{from = "O", length = "m", angle = "30 deg"}` or `{from = ["A", "B"], lengths = [..], side = ..}`."""
        origin = spec.get("from")
        bases = [origin] if isinstance(origin, str) else origin
        if not isinstance(bases, list) or not all(isinstance(b, str) for b in bases):
            raise ModelError("a construction needs from = \"JOINT\" (with length, angle) or from = [\"A\", \"B\"] "
                             "(with lengths, side)", path=self.source, element=where)
        for base in bases:
            if base not in known:
                raise ModelError(f"from names '{base}', which is not given above it", path=self.source,
                                 element=where)
        if len(bases) == 1:
            if set(spec) != {"from", "length", "angle"}:
                raise ModelError("a polar construction has exactly from, length, angle", path=self.source,
                                 element=where)
            r, phi = self.length(spec["length"], f"{where} length"), self.angle(spec["angle"], f"{where} angle")
            base = known[bases[0]]  # in 3-D: in the plane z = the base's z (the angle from x, seen from +z)
            return base + r * np.array([math.cos(phi), math.sin(phi), 0.0][: base.size])
        if len(bases) != 2 or set(spec) != {"from", "lengths", "side"}:
            raise ModelError("a compass construction has exactly from = [\"A\", \"B\"], lengths = [|A..|, |B..|], "
                             "side = \"left\" or \"right\" (of the line A -> B)", path=self.source, element=where)
        lengths = spec["lengths"]
        if not isinstance(lengths, list) or len(lengths) != 2:
            raise ModelError(f"lengths must be two lengths, got {lengths!r}", path=self.source, element=where)
        if spec["side"] not in ("left", "right"):
            raise ModelError(f"side must be \"left\" or \"right\", got {spec['side']!r}", path=self.source,
                             element=where)
        r1, r2 = (self.length(v, f"{where} lengths") for v in lengths)
        a, b = _level(known[bases[0]], known[bases[1]], bases, self.source, where)
        point = _compass(a[:2], b[:2], r1, r2, spec["side"] == "left", f"{self.source}, {where}")
        return np.append(point, a[2]) if a.size == 3 else point


def _level(a: np.ndarray, b: np.ndarray, names: list[str], source: str, where: str) -> tuple[np.ndarray, np.ndarray]:
    """The two bases of a compass construction, both 2-D or both 3-D at one z [m]: left and
    right of A -> B are seen from +z, so the circles are drawn in the plane z = z_A.

    Raises:
        ModelError: bases at different heights (the circles' plane would be a guess).
    """
    if a.size == b.size == 2:
        return a, b
    a, b = (np.append(p, 0.0) if p.size == 2 else p for p in (a, b))
    if abs(a[2] - b[2]) > 1e-12 * max(float(np.linalg.norm(b - a)), float(np.max(np.abs(a))), 1e-300):
        raise ModelError(f"a compass construction draws in a plane z = constant, but {names[0]} is at z = "
                         f"{a[2]:.6g} m and {names[1]} at z = {b[2]:.6g} m: give this joint's [x, y, z]",
                         path=source, element=where)
    return a, b


def _compass(a: np.ndarray, b: np.ndarray, r1: float, r2: float, left: bool, where: str) -> np.ndarray:
    """The point at r1 from a and r2 from b, left or right of a -> b [m]."""
    d = float(np.linalg.norm(b - a))
    if d == 0 or r1 <= 0 or r2 <= 0 or r1 + r2 < d or abs(r1 - r2) > d:
        raise ModelError(f"cannot be drawn: circles of radii {r1:.6g} m and {r2:.6g} m about points "
                         f"{d:.6g} m apart do not meet (the linkage cannot be assembled here)", path=where)
    u = (b - a) / d
    along = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    across = math.sqrt(max(r1 * r1 - along * along, 0.0))
    normal = np.array([-u[1], u[0]])
    return a + along * u + (across if left else -across) * normal


def _spatial(linkage: Linkage, raw: dict[str, Any], source: str) -> None:
    """3-D coordinates, `[axes]` or `balls`: a spatial linkage (2-D entries lie in z = 0)."""
    axes = _table(raw, "axes", source)
    balls = _names(raw.get("balls", []), "balls", source)
    linkage.spatial = bool(axes or balls or any(p.size == 3 for p in linkage.points.values()))
    if not linkage.spatial:
        return
    linkage.points = {n: np.append(p, 0.0) if p.size == 2 else p for n, p in linkage.points.items()}
    z = np.array([0.0, 0.0, 1.0])
    for name in linkage.points:
        linkage.axes[name] = z
    for name, value in axes.items():
        where = f"[axes] {name}"
        if name not in linkage.points:
            raise ModelError(f"'{name}' is not a joint of [joints]", path=source, element=where)
        if (not isinstance(value, list) or len(value) != 3
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
            raise ModelError(f"an axis is three numbers, e.g. [0, 0, 1], got {value!r}", path=source, element=where)
        axis = unit_vector(value)
        if axis is None:
            raise ModelError(f"{written(value)} is not a direction (zero or not finite)", path=source, element=where)
        linkage.axes[name] = axis
    for name in balls:
        if name not in linkage.points:
            raise ModelError(f"'{name}' is not a joint of [joints]", path=source, element="balls")
    linkage.balls = set(balls)
    if _drawn_in_plane(linkage, raw):  # z = 0 and axes +z written out: the planar linkage it draws
        linkage.spatial, linkage.axes = False, {}
        linkage.points = {n: p[:2] for n, p in linkage.points.items()}


def _drawn_in_plane(linkage: Linkage, raw: dict[str, Any]) -> bool:
    """Every point at z = 0, every axis +z, no ball and no spatial inertia: a planar linkage
    written in 3-D, read as one (else its driver angles would count from the drawing, not
    from world x, because a third "0 mm" or a default axis was written out)."""
    masses = raw.get("masses")
    spatial_mass = isinstance(masses, dict) and any(isinstance(m, dict) and "inertia" in m for m in masses.values())
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


def _link(linkage: Linkage, value: Any, key: str, where: str) -> str:
    if not isinstance(value, str) or value not in linkage.links:
        known = ", ".join(linkage.links)
        raise ModelError(f"{key} = {value!r} names no link (links: {known})", path=linkage.source, element=where)
    return value


def _direction(linkage: Linkage, reader: _Reader, spec: dict[str, Any], at: np.ndarray, where: str) -> np.ndarray:
    """`along = "30 deg"` or `along = ["A", "B"]`: a unit direction in the world [-]."""
    along = spec.get("along")
    if along is None:
        raise ModelError("has no line: give along = \"ANGLE\" or along = [\"P\", \"Q\"]", path=linkage.source,
                         element=where)
    if isinstance(along, list):
        if len(along) != 2 or not all(isinstance(n, str) and n in linkage.points for n in along):
            raise ModelError(f"along = {along!r} must name two joints of [joints]", path=linkage.source,
                             element=where)
        vector = linkage.points[along[1]] - linkage.points[along[0]]
        if np.linalg.norm(vector) < 1e-12 * max(1.0, float(np.linalg.norm(at))):
            raise ModelError(f"along = {along!r}: the two joints coincide, so they give no direction",
                             path=linkage.source, element=where)
        return vector / np.linalg.norm(vector)
    phi = reader.angle(along, f"{where} along")
    return np.array([math.cos(phi), math.sin(phi), 0.0][: at.size])


def _slider(linkage: Linkage, reader: _Reader, name: str, spec: Any) -> None:
    """`S = {block = "piston", on = "ground", at = "B", along = "0 deg"}`: a prismatic pair."""
    where = f"[sliders] {name}"
    if not isinstance(spec, dict) or not set(spec) <= {"block", "on", "at", "along"}:
        raise ModelError("a slider is {block = LINK, on = LINK, at = JOINT, along = ANGLE or [P, Q]}",
                         path=linkage.source, element=where)
    block = _link(linkage, spec.get("block"), "block", where)
    on = _link(linkage, spec.get("on"), "on", where)
    if block == on:
        raise ModelError(f"block and on are the same link '{block}'", path=linkage.source, element=where)
    at = spec.get("at")
    if at not in linkage.links[block]:
        raise ModelError(f"at = {at!r} must be a joint the block '{block}' lists", path=linkage.source,
                         element=where)
    edge = Edge(name, "prismatic", (on, block), linkage.points[at],
                _direction(linkage, reader, spec, linkage.points[at], where))
    linkage.edges.append(edge)
    linkage.blocks[block] = edge


def _slot(linkage: Linkage, reader: _Reader, name: str, spec: Any) -> None:
    """`A = {pin = "crank", slot = "rocker", along = ["O4", "A"]}`: a pin sliding in a slot."""
    where = f"[slots] {name}"
    if not isinstance(spec, dict) or not set(spec) <= {"pin", "slot", "along"}:
        raise ModelError("a pin-in-slot joint is {pin = LINK, slot = LINK, along = ANGLE or [P, Q]}",
                         path=linkage.source, element=where)
    if linkage.spatial:
        raise ModelError("pin-in-slot joints are planar only: in a spatial linkage, give the block as a link "
                         "with a slider and a pin", path=linkage.source, element=where)
    pin_link = _link(linkage, spec.get("pin"), "pin", where)
    slot_link = _link(linkage, spec.get("slot"), "slot", where)
    if name not in linkage.points:
        raise ModelError(f"the slot's pin '{name}' is not given in [joints]", path=linkage.source, element=where)
    if name not in linkage.links[pin_link]:
        raise ModelError(f"the pin '{name}' must be listed by its link '{pin_link}'", path=linkage.source,
                         element=where)
    at = linkage.points[name]
    block = f"{name}_block"
    if block in linkage.links:  # it was replaced by the block, in silence
        raise ModelError(f"link '{block}' has the name pinmech gives slot {name}'s block (a hidden link): rename "
                         "the link", path=linkage.source, element=f"[links] {block}")
    linkage.links[block] = [name]
    linkage.hidden.add(block)
    linkage.edges.append(Edge(f"{name}_pin", "revolute", (pin_link, block), at))
    edge = Edge(f"{name}_slide", "prismatic", (slot_link, block), at, _direction(linkage, reader, spec, at, where))
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
