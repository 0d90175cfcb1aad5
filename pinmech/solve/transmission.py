"""Transmission angles of the pin dyads and pressure angles of the slider dyads of a planar
linkage, and the mechanical advantage of their output links.

A dyad is a coupler (a link that is not the input) joined by a pin B to an output link
farther than the coupler from the input (counted in links), the output being pivoted on
the ground at O (a pin dyad: a four-bar's coupler and rocker, a six-bar's last two links)
or a block sliding on the ground (a slider dyad: a slider-crank's rod and piston). The
coupler's line runs from B to its pin A on the side of the input.

Conventions (Norton, Design of Machinery, §4.10 "transmission angle"; Uicker, Theory of
Machines and Mechanisms, §1.10; the pressure angle as for cams, the angle between the
force on the output and its velocity):

- transmission angle mu: the angle ABO between the coupler and the output at B, in
  [0, 180] deg; Norton's mu is its acute form min(mu, 180 - mu) in [0, 90] deg, 90 deg
  best, 0 a toggle (the coupler and the output in line: the output cannot be driven);
- pressure angle phi = 90 deg - acute mu: the angle between the coupler's line (the force
  a two-force coupler transmits) and the velocity of B (normal to OB);
- slider dyad: phi is the acute angle between the coupler's line and the slide, and its
  transmission angle mu = 90 deg - phi (the angle between the coupler and the slide's
  normal, the "output link" of a slider being of infinite length along that normal).
- slot dyad (the inverted slider-crank, Norton §4.7, and the crank and slotted lever): a
  block on the input side's pin P slides in a slot of an output pivoted at O. Without
  friction the block pushes the output normal to the slot, and the output's point at P
  moves normal to OP: phi is the angle between those two normals, i.e. the acute angle
  between the slot and OP (sin phi = e / |OP|, e the slot's offset from O), and mu =
  90 deg - phi as for any dyad. A slot through the pivot transmits at mu = 90 deg always.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from pinmech.model.planar_linkage import Pair, PlanarLinkage


@dataclass(frozen=True)
class Dyad:
    """A coupler and its output link.

    Attributes:
        kind: "pin" (the output turns about a ground pivot), "slide" (a block on the
            ground) or "slot" (the coupler is a block sliding in a slot of a pivoted output).
        coupler, output: link indices of the linkage.
        joint: the pin B between them; near: the coupler's pin A towards the input;
        ground: the output's pin O to the ground, or its slide on the ground.
        driving: the link on the other side of A (for a toggle: it and the coupler in line).
    """

    kind: str
    coupler: int
    output: int
    joint: Pair
    near: Pair
    ground: Pair
    driving: int

    def name(self, linkage: PlanarLinkage) -> str:
        """'coupler-output at B', as reports list it."""
        n = linkage.names
        return f"{n[self.coupler]}-{n[self.output]} at {self.joint.name}"


@dataclass(frozen=True)
class Output:
    """A moving link with one pair to the ground and no driver: a rocker (or crank) on a
    ground pivot, or a block on a ground slide. Its limit positions are where it stops.

    Attributes:
        kind: "pin" or "slide"; output: the link; ground: its pair with the ground.
    """

    kind: str
    output: int
    ground: Pair


def find_outputs(linkage: PlanarLinkage, drivers: list[str]) -> list[Output]:
    """Every link, other than the inputs, with exactly one pair, a pin or a slide, to the ground."""
    inputs = input_links(linkage, drivers)
    out = []
    for link in sorted(linkage.names):
        grounds = [p for other, p in linkage.neighbours(link) if other == 0]
        if link != 0 and link not in inputs and len(grounds) == 1:
            out.append(Output(grounds[0].kind, link, grounds[0]))
    return out


@dataclass(frozen=True)
class DyadAngles:
    """The angles of a dyad at one pose [deg].

    Attributes:
        mu: transmission angle ABO in [0, 180] (slider dyad: 90 - phi).
        mu_acute: Norton's acute form, in [0, 90].
        pressure: pressure angle phi = 90 - mu_acute.
    """

    mu: float
    mu_acute: float
    pressure: float


def input_links(linkage: PlanarLinkage, drivers: list[str]) -> list[int]:
    """The links the drivers move: the moving side of each driven pair."""
    out = []
    for pair in linkage.pairs:
        if pair.name in drivers:
            out.append(pair.links[1] if pair.links[1] != 0 else pair.links[0])
    return out


def distances(linkage: PlanarLinkage, inputs: list[int]) -> dict[int, int]:
    """How many pairs each moving link is from an input, not through the ground."""
    dist = {i: 0 for i in inputs}
    todo = deque(inputs)
    while todo:
        link = todo.popleft()
        for other, _ in linkage.neighbours(link):
            if other != 0 and other not in dist:
                dist[other] = dist[link] + 1
                todo.append(other)
    return dist


def find_dyads(linkage: PlanarLinkage, drivers: list[str]) -> list[Dyad]:
    """Every pin and slider dyad, in the order of the linkage's pairs."""
    inputs = input_links(linkage, drivers)
    dist = distances(linkage, inputs)
    out = []
    for joint in linkage.pairs:
        if joint.kind == "slide" and 0 not in joint.links:
            out += _slot_dyads(linkage, joint, inputs, dist)
        if joint.kind != "pin" or 0 in joint.links:
            continue
        for coupler, output in (joint.links, joint.links[::-1]):
            if coupler in inputs or dist.get(output, -1) <= dist.get(coupler, 10**9):
                continue
            ground = _grounding(linkage, output, joint)
            near = _near_pin(linkage, coupler, joint, dist)
            if ground is not None and near is not None:
                kind = "pin" if ground.kind == "pin" else "slide"
                out.append(Dyad(kind, coupler, output, joint, near, ground, near.other(coupler)))
    return out


def _slot_dyads(linkage: PlanarLinkage, joint: Pair, inputs: list[int], dist: dict[int, int]) -> list[Dyad]:
    """The slot dyad of a slide between two moving links: a block (not an input) pinned
    towards the input, sliding on an output farther from it that is pivoted on the ground."""
    out = []
    for block, output in (joint.links, joint.links[::-1]):
        if block in inputs or dist.get(output, -1) <= dist.get(block, 10**9):
            continue
        pivots = [p for other, p in linkage.neighbours(output) if other == 0]
        near = _near_pin(linkage, block, joint, dist)
        if len(pivots) == 1 and pivots[0].kind == "pin" and near is not None:
            out.append(Dyad("slot", block, output, joint, near, pivots[0], near.other(block)))
    return out


def _grounding(linkage: PlanarLinkage, output: int, joint: Pair) -> Pair | None:
    """The output's one pair with the ground: a pivot away from B, or a slide."""
    pairs = [p for other, p in linkage.neighbours(output) if other == 0]
    if len(pairs) != 1:
        return None
    pair = pairs[0]
    if pair.kind == "pin":
        end = pair.local[0] if pair.links[0] == output else pair.local[1]
        mine = joint.local[0] if joint.links[0] == output else joint.local[1]
        if np.linalg.norm(end - mine) <= 1e-9 * linkage.mechanism.length_scale:
            return None
    return pair


def _near_pin(linkage: PlanarLinkage, coupler: int, joint: Pair, dist: dict[int, int]) -> Pair | None:
    """The coupler's pin to the link nearest the input (not B, not on the ground)."""
    pins = [p for p in linkage.pins(coupler) if p is not joint and 0 not in p.links]
    pins = [p for p in pins if dist.get(p.other(coupler), 10**9) < dist.get(coupler, 10**9)]
    return min(pins, key=lambda p: dist[p.other(coupler)], default=None)


def _end(pair: Pair, link: int) -> np.ndarray:
    return pair.local[0] if pair.links[0] == link else pair.local[1]


def dyad_angles(linkage: PlanarLinkage, dyad: Dyad) -> DyadAngles:
    """The dyad's angles at the pose `linkage.place` was last given (of a linkage whose
    points and directions are (2, N) arrays over N poses, the N angles of each)."""
    A = linkage.point(dyad.coupler, _end(dyad.near, dyad.coupler))
    if dyad.kind == "slot":
        return _slot_angles(linkage, dyad, A)
    B = linkage.point(dyad.coupler, _end(dyad.joint, dyad.coupler))
    rod = A - B
    if dyad.kind == "pin":
        O = linkage.point(0, _end(dyad.ground, 0))
        mu = _angle(rod, O - B)
        acute = np.minimum(mu, 180.0 - mu)
        return DyadAngles(mu, acute, 90.0 - acute)
    u = linkage.direction(dyad.ground.links[0], dyad.ground.axis)
    phi = _angle(rod, u)
    phi = np.minimum(phi, 180.0 - phi)
    return DyadAngles(90.0 - phi, 90.0 - phi, phi)


def dyad_side(linkage: PlanarLinkage, dyad: Dyad) -> float:
    """A number whose sign changes exactly where the dyad's acute transmission angle passes
    through 0 (the coupler and the output in line: a toggle, a change point) [m^2]: of a pin
    dyad the cross product (A - B) x (O - B) (mu through 0 or 180 deg); of a slider dyad
    the rod's component along the slide times |rod| (the rod normal to the slide); of a
    slot dyad the slot's direction along O P times |OP| (the slot normal to O P)."""
    A = linkage.point(dyad.coupler, _end(dyad.near, dyad.coupler))
    O = linkage.point(0, _end(dyad.ground, 0)) if dyad.kind != "slide" else None
    if dyad.kind == "slot":
        return float(linkage.direction(dyad.joint.links[0], dyad.joint.axis) @ (A - O))
    B = linkage.point(dyad.coupler, _end(dyad.joint, dyad.coupler))
    if dyad.kind == "slide":
        return float(linkage.direction(dyad.ground.links[0], dyad.ground.axis) @ (A - B))
    u, w = A - B, O - B
    return float(u[0] * w[1] - u[1] * w[0])


def _slot_angles(linkage: PlanarLinkage, dyad: Dyad, P: np.ndarray) -> DyadAngles:
    """A slot dyad's angles with the block's pin at P: phi between the slot and OP."""
    O = linkage.point(0, _end(dyad.ground, 0))
    phi = _angle(linkage.direction(dyad.joint.links[0], dyad.joint.axis), P - O)
    phi = np.minimum(phi, 180.0 - phi)
    return DyadAngles(90.0 - phi, 90.0 - phi, phi)


def output_rate(linkage: PlanarLinkage, output: Output | Dyad) -> float:
    """The output's rate [rad/s, or m/s along the slide's axis] at the placed velocities."""
    if output.kind == "pin":
        return linkage.omega(output.output)
    slide = output.ground
    u = linkage.direction(slide.links[0], slide.axis)
    B = linkage.point(output.output, _end(slide, output.output))
    sign = 1.0 if slide.links[1] == output.output else -1.0  # the block's motion on the ground
    return float(sign * (u @ linkage.velocity(output.output, B)))


def output_position(linkage: PlanarLinkage, output: Output | Dyad) -> float:
    """The output's angle (of its frame's x axis from the plane's e1, as a report's phi)
    [rad], or its place along the slide [m] (the slide's point on the block)."""
    if output.kind == "pin":
        d = linkage.direction(output.output, np.array([1.0, 0.0, 0.0]))
        return math.atan2(d[1], d[0])
    slide = output.ground
    u = linkage.direction(slide.links[0], slide.axis)
    return float(u @ linkage.point(output.output, _end(slide, output.output)))


def toggle(linkage: PlanarLinkage, dyad: Dyad, tol: float = 1e-6) -> str:
    """"extended" or "folded" when the driving link's pivot, A and B are in line (within
    `tol` of the sine of their angle), else "": the toggle of the driving link and the coupler
    (a slot dyad's block has no line of its own to fall in line with: always "")."""
    if dyad.kind == "slot":
        return ""
    pivot = [p for other, p in linkage.neighbours(dyad.driving) if other == 0 and p.kind == "pin"]
    if len(pivot) != 1:
        return ""
    O = linkage.point(0, _end(pivot[0], 0))
    A = linkage.point(dyad.coupler, _end(dyad.near, dyad.coupler))
    B = linkage.point(dyad.coupler, _end(dyad.joint, dyad.coupler))
    u, w = A - O, B - A
    sine = (u[0] * w[1] - u[1] * w[0]) / max(np.linalg.norm(u) * np.linalg.norm(w), 1e-300)
    if abs(sine) > tol:
        return ""
    return "extended" if u @ w > 0 else "folded"


def _angle(a: np.ndarray, b: np.ndarray) -> float | np.ndarray:
    """The angle between two plane vectors [deg], in [0, 180]; of (2, N) arrays of vectors
    (x row, y row), the N angles."""
    return np.degrees(np.arctan2(np.abs(a[0] * b[1] - a[1] * b[0]), a[0] * b[0] + a[1] * b[1]))
