"""The space diagram: a planar mechanism at its solved pose drawn to scale in plain SVG, as
a textbook draws it beside its polygons (no extra needed, and it prints, unlike a WebGL page).

Each moving link in its colour (`pinmech.model.display`): a bar between its pins, a plate over
three or more, a block on a slider; pins as open circles, named points as dots, the ground
as hatched pivots and guides. One SVG user unit is one millimetre of paper; the length
scale, a round number, is written under the drawing.
"""

from __future__ import annotations

import html
import math

import numpy as np
import pinocchio as pin

from pinmech.model.display import display_names, hex_colour, joint_colours
from pinmech.draw.inputs import DrawError
from pinmech.model.link_nodes import LinkSketch, sketch_links, world_nodes
from pinmech.solve.motion import _plane_reference
from pinmech.io.analysis_result import Analysis

GROUND = "#777777"
BLOCK = 5.0  # a slider block's length on paper [mm]


def plane_axes(analysis: Analysis) -> np.ndarray:
    """The plane's x and y axes in world coordinates, shape (2, 3) (as the polygons use)."""
    normal = analysis.mechanism.plane_normal
    if normal is None:
        raise DrawError(f"{analysis.scene.path}: the space diagram is drawn for planar mechanisms; "
                        f"{analysis.mechanism.source} moves in space", argument="scene",
                        value=str(analysis.scene.path))
    e1 = _plane_reference(*normal.tolist())
    return np.array([e1, np.cross(normal, e1)])


def space_diagram(analysis: Analysis, box: tuple[float, float, float, float]) -> list[str]:
    """SVG elements of the space diagram fitted in `box` = (x, y, width, height) on paper [mm],
    its scale line underneath (inside the box)."""
    axes = plane_axes(analysis)
    mech = analysis.mechanism
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, analysis.solution.q)
    sketches = sketch_links(mech)
    nodes = {name: world_nodes(s, data) @ axes.T for name, s in sketches.items()}
    places = _named_places(sketches, nodes, display_names(mech), mech.length_scale)
    everything = np.vstack([*nodes.values(), *places.values()]).reshape(-1, 2)
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    x, y, width, height = box
    room = np.array([width - 16.0, height - 22.0])  # labels around, the scale line below [mm]
    per_mm = _round_up(float(np.max((hi - lo) / np.maximum(room, 1.0))) or 1e-3)
    centre = np.array([x + width / 2, y + 4 + room[1] / 2 + 4])

    def at(p: np.ndarray) -> tuple[float, float]:
        q = (p - (lo + hi) / 2) / per_mm
        return float(centre[0] + q[0]), float(centre[1] - q[1])

    colours = joint_colours(mech)
    out = [f'<g class="space-diagram" data-per-mm="{per_mm:.12g}">',
           f'<text x="{x + 4:.2f}" y="{y + 4:.2f}" font-size="3.2" fill="#555555">space diagram</text>']
    for name, sketch in sketches.items():
        margin = 0.08 * float(np.max(hi - lo))
        out += _link(sketch, nodes[name], at, hex_colour(colours[sketch.joint]), axes, data,
                     (lo - margin, hi + margin))
    out += _pins_and_labels(sketches, nodes, places, at)
    bar = 20.0
    yb = y + height - 3
    out.append(f'<line class="space-scale" x1="{x + 4:.2f}" y1="{yb:.2f}" x2="{x + 4 + bar:.2f}" y2="{yb:.2f}" '
               f'stroke="black" stroke-width="0.5"/>')
    out.append(f'<text x="{x + 6 + bar:.2f}" y="{yb + 1.2:.2f}" font-size="3">{_length(bar * per_mm)} '
               f'(space diagram, 1 mm = {_length(per_mm)})</text>')
    out.append("</g>")
    return out


def pose_svg(analysis: Analysis, width: float = 160.0, height: float = 110.0) -> str:
    """The space diagram alone, as a standalone SVG document of width x height [mm]."""
    title = html.escape(f"{analysis.scene.title}: the pose drawn to scale")
    return "\n".join([
        f'<svg xmlns="http://www.w3.org/2000/svg" class="pose" width="{width:.2f}mm" height="{height:.2f}mm" '
        f'viewBox="0 0 {width:.4f} {height:.4f}" font-family="sans-serif">',
        f"<title>{title}</title>", '<rect width="100%" height="100%" fill="white"/>',
        *space_diagram(analysis, (0.0, 0.0, width, height)), "</svg>\n"])


def _link(sketch: LinkSketch, nodes: np.ndarray, at, colour: str, axes: np.ndarray, data: pin.Data,
          box: tuple[np.ndarray, np.ndarray]) -> list[str]:
    """One link: a bar, a plate or a block; the ground: its guides, across the drawing's
    `box` (lowest and highest corner in the plane [m]; pivots come with the pins)."""
    out = []
    frame = data.oMi[sketch.joint]
    for point, direction in sketch.guides:
        p, d = axes @ frame.act(point), axes @ (frame.rotation @ direction)
        d = d / max(float(np.linalg.norm(d)), 1e-300)
        if sketch.is_ground:
            (x1, y1), (x2, y2) = at(p - _inside(p, -d, box) * d), at(p + _inside(p, d, box) * d)
            out.append(f'<line class="guide" x1="{x1:.3f}" y1="{y1:.3f}" x2="{x2:.3f}" y2="{y2:.3f}" '
                       f'stroke="{GROUND}" stroke-width="0.6" stroke-dasharray="2,1"/>')
    if sketch.is_ground:
        return out
    paper = np.array([at(p) for p in nodes]).reshape(-1, 2)
    name = html.escape(sketch.name)
    if sketch.slide_axis is not None:
        d = axes @ (frame.rotation @ sketch.slide_axis)
        angle = math.degrees(math.atan2(-d[1], d[0]))
        cx, cy = paper[0]
        out.append(f'<rect class="link" data-link="{name}" x="{cx - BLOCK / 2:.3f}" y="{cy - BLOCK / 3:.3f}" '
                   f'width="{BLOCK}" height="{2 * BLOCK / 3:.3f}" fill="{colour}" fill-opacity="0.35" '
                   f'stroke="{colour}" stroke-width="0.6" transform="rotate({angle:.3f} {cx:.3f} {cy:.3f})"/>')
    elif sketch.is_plate:
        order = np.argsort(np.arctan2(*(paper - paper.mean(axis=0)).T[::-1]))
        points = " ".join(f"{px:.3f},{py:.3f}" for px, py in paper[order])
        out.append(f'<polygon class="link" data-link="{name}" points="{points}" fill="{colour}" '
                   f'fill-opacity="0.3" stroke="{colour}" stroke-width="1.2" stroke-linejoin="round"/>')
    elif len(paper) >= 2:
        d = paper - paper[0]
        ends = paper[[int(np.argmin(d @ d[-1])), int(np.argmax(d @ d[-1]))]]
        out.append(f'<line class="link" data-link="{name}" x1="{ends[0][0]:.3f}" y1="{ends[0][1]:.3f}" '
                   f'x2="{ends[1][0]:.3f}" y2="{ends[1][1]:.3f}" stroke="{colour}" stroke-width="1.6" '
                   f'stroke-linecap="round"/>')
    return out


def _inside(p: np.ndarray, d: np.ndarray, box: tuple[np.ndarray, np.ndarray]) -> float:
    """How far from p along the unit vector d the box's edge is [m] (p inside the box)."""
    reach = [((box[1] if di > 0 else box[0])[i] - p[i]) / di for i, di in enumerate(d) if abs(di) > 1e-12]
    return max(min(reach, default=0.0), 0.0)


def _named_places(sketches: dict[str, LinkSketch], nodes: dict[str, np.ndarray], shown: dict[str, str],
                  scale: float) -> dict[str, np.ndarray]:
    """Printed name -> place in the plane [m] of every pin and named point, one name a place
    (a pin's wins); a slide has no place of its own to name."""
    found: list[tuple[int, str, np.ndarray]] = []
    for sketch in sketches.values():
        for node, p in zip(sketch.nodes, nodes[sketch.name]):
            if node.kind in ("revolute", "point"):
                found.append((node.kind != "revolute", shown.get(node.name, node.name), p))
    out: dict[str, np.ndarray] = {}
    for _, name, p in sorted(found, key=lambda f: f[0]):
        if not any(np.linalg.norm(p - q) <= 1e-9 * scale for q in out.values()):
            out.setdefault(name, p)
    return out


def _pins_and_labels(sketches: dict[str, LinkSketch], nodes: dict[str, np.ndarray], places: dict[str, np.ndarray],
                     at) -> list[str]:
    """Ground symbols under fixed pivots, open circles at pins, dots at points, the names."""
    out = []
    ground = next((s for s in sketches.values() if s.is_ground), None)
    if ground is not None:
        for node, p in zip(ground.nodes, nodes[ground.name]):
            if node.kind == "revolute":
                x, y = at(p)
                out.append(f'<path class="ground" d="M{x:.3f},{y:.3f} l-2.6,4.2 h5.2 z M{x - 3.6:.3f},{y + 4.2:.3f} '
                           f'h7.2" fill="white" stroke="{GROUND}" stroke-width="0.5"/>')
                out += [f'<line x1="{x - 3.2 + 1.6 * k:.3f}" y1="{y + 4.2:.3f}" x2="{x - 4.4 + 1.6 * k:.3f}" '
                        f'y2="{y + 5.6:.3f}" stroke="{GROUND}" stroke-width="0.35"/>' for k in range(5)]
    for sketch in sketches.values():
        for node, p in zip(sketch.nodes, nodes[sketch.name]):
            x, y = at(p)
            if node.kind == "revolute":
                out.append(f'<circle class="pin" cx="{x:.3f}" cy="{y:.3f}" r="0.9" fill="white" stroke="black" '
                           f'stroke-width="0.4"/>')
            elif node.kind == "point":
                out.append(f'<circle class="point" cx="{x:.3f}" cy="{y:.3f}" r="0.6" fill="black"/>')
    centre = np.mean(list(places.values()), axis=0) if places else np.zeros(2)
    for name, p in places.items():
        away = p - centre
        away = away / np.linalg.norm(away) if np.linalg.norm(away) > 0 else np.array([0.0, 1.0])
        away = np.array([away[0], max(away[1], 0.45)])  # never down onto a ground symbol
        away = away / np.linalg.norm(away)
        x, y = at(p)
        out.append(f'<text class="place" x="{x + 4.2 * away[0]:.3f}" y="{y - 4.2 * away[1] + 1.2:.3f}" '
                   f'font-size="3.6" font-style="italic" text-anchor="middle">{html.escape(name)}</text>')
    return out


def _round_up(x: float) -> float:
    """The smallest of 1, 2, 2.5, 4, 5 times a power of ten that is at least x (> 0)."""
    power = 10.0 ** math.floor(math.log10(x))
    return next(m * power for m in (1, 2, 2.5, 4, 5, 10) if m * power >= x * (1 - 1e-9))


def _length(metres: float) -> str:
    """A length as a drawing writes it: in mm below a metre, else in m."""
    return f"{metres * 1000:.6g} mm" if metres < 1.0 else f"{metres:.6g} m"
