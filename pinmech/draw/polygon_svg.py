"""A velocity or acceleration polygon as an SVG drawing at a stated scale (no extra needed).

One SVG user unit is one millimetre of paper; the scale, a round number ("1 mm = 0.02
m/s"), is written on the drawing with a scale bar, so a teacher can measure it as a
student's drawing. Each vector is an SVG `<line>` with `data-kind`, `data-from`,
`data-to` and `data-label`, so a program can read the drawing back; its name and magnitude
are written beside it. A vector lying along another is moved sideways (thin leaders join it
to its true ends) so that none hides another. Each link's image is closed and shaded in the
link's colour, and the space diagram can be drawn beside the polygon.
"""

from __future__ import annotations

import html
import math

import numpy as np

from pinmech.draw.polygon import KINDS, Polygon, PolygonVector
from pinmech.io.analysis_result import Analysis

COLOURS = {
    "absolute": "#1f3fbf",
    "relative": "#222222",
    "sliding": "#1b8a3a",
    "normal": "#c0392b",
    "tangential": "#e67e22",
    "coriolis": "#8e44ad",
}
PAPER = 150.0  # the longest side of the polygon on paper [mm]
MARGIN = 18.0  # around the polygon [mm]
HEADER = 16.0  # title lines [mm]
FOOTER = 36.0  # scale bar and legend [mm]
SPACE = 85.0  # the space diagram's width beside the polygon [mm]
SPACE_HEIGHT = 90.0  # the least height of the drawing's middle, room for the space diagram [mm]
LABEL_ROOM = 24.0  # room for the names and magnitudes written beside the vectors [mm]
STEP = 1.6  # how far a vector lying along another is moved sideways [mm]
HIDE = 1.0  # two vectors closer than this along one line would hide each other [mm]


def polygon_svg(polygon: Polygon, analysis: Analysis | None = None) -> str:
    """The polygon as a standalone SVG document; with the solved `analysis`, the space
    diagram (the mechanism at the pose, to scale) is drawn beside it."""
    ends = np.array([v.tail for v in polygon.vectors] + [v.head for v in polygon.vectors]
                    + list(polygon.images.values())).reshape(-1, 2)
    lo, hi = ends.min(axis=0), ends.max(axis=0)
    extent = float(max(np.max(hi - lo), 1e-300))
    per_mm = _round_up(extent / PAPER)  # quantity per millimetre of paper
    size = (hi - lo) / per_mm
    left = SPACE if analysis is not None else 0.0
    inner = max(size[1], SPACE_HEIGHT if analysis is not None else 0.0)
    width = max(left + size[0] + 2 * MARGIN + LABEL_ROOM, 190.0)
    height = inner + 2 * MARGIN + HEADER + FOOTER
    x0 = left + (width - left - size[0]) / 2 - lo[0] / per_mm
    y0 = HEADER + MARGIN + (inner - size[1]) / 2 + hi[1] / per_mm

    def at(v: np.ndarray) -> tuple[float, float]:
        return x0 + v[0] / per_mm, y0 - v[1] / per_mm

    parts = [_header(width, height, polygon, per_mm)]
    if analysis is not None:
        from pinmech.draw.space_svg import space_diagram

        parts += space_diagram(analysis, (0.0, HEADER, left, height - HEADER - FOOTER + 4))
        parts.append(f'<line x1="{left:.2f}" y1="{HEADER + 4:.2f}" x2="{left:.2f}" y2="{height - FOOTER:.2f}" '
                     f'stroke="#cccccc" stroke-width="0.3"/>')
    parts += _figures(polygon, at)
    offsets = vector_offsets(polygon.vectors, per_mm)
    for v, offset in zip(polygon.vectors, offsets):
        parts += _vector(v, at, offset)
    labels, boxes = _labels(polygon, at, per_mm, (lo + hi) / 2)
    parts += _magnitudes(polygon, at, per_mm, offsets, boxes) + labels
    parts += _footer(polygon, per_mm, height, width)
    parts.append("</svg>\n")
    return "\n".join(parts)


def vector_offsets(vectors: list[PolygonVector], per_mm: float) -> list[np.ndarray]:
    """Where each vector is drawn off its true place, on paper [mm] (y up), so that none
    hides another: a vector lying along one already placed is moved sideways in steps of
    STEP. The chains of parts keep their place (they meet at the images); the vectors from
    the pole move first."""
    order = sorted(range(len(vectors)), key=lambda i: vectors[i].kind == "absolute")
    placed: list[tuple[np.ndarray, np.ndarray]] = []
    offsets = [np.zeros(2)] * len(vectors)
    for i in order:
        a, b = vectors[i].tail / per_mm, vectors[i].head / per_mm
        u = (b - a) / max(float(np.linalg.norm(b - a)), 1e-300)
        side = np.array([-u[1], u[0]])
        for k in range(40):
            offset = side * STEP * ((k + 1) // 2) * (1 if k % 2 else -1)
            if not any(hides((a + offset, b + offset), other) for other in placed):
                break
        offsets[i] = offset
        placed.append((a + offset, b + offset))
    return offsets


def hides(s1: tuple[np.ndarray, np.ndarray], s2: tuple[np.ndarray, np.ndarray]) -> bool:
    """Whether two segments on paper [mm] lie along each other: within HIDE of one line and
    sharing more than 0.5 mm of their length."""
    (a, b), (c, d) = s1, s2
    length = float(np.linalg.norm(b - a))
    if length < 1e-9:
        return False
    u = (b - a) / length
    n = np.array([-u[1], u[0]])
    if abs(n @ (c - a)) > HIDE or abs(n @ (d - a)) > HIDE:
        return False
    t = sorted([float(u @ (c - a)), float(u @ (d - a))])
    return min(length, t[1]) - max(0.0, t[0]) > 0.5


def scale_text(per_mm: float, unit: str) -> str:
    """The scale as written on the drawing: "scale: 1 mm = 0.02 m/s"."""
    return f"scale: 1 mm = {per_mm:.6g} {_printed(unit)}"


def _printed(unit: str) -> str:
    """A unit as printed on paper: m/s^2 -> m/s²."""
    return unit.replace("^2", "²")


def _round_up(x: float) -> float:
    """The smallest of 1, 2, 5 times a power of ten that is at least x (> 0)."""
    power = 10.0 ** math.floor(math.log10(x))
    return next(m * power for m in (1, 2, 5, 10) if m * power >= x * (1 - 1e-9))


def _header(width: float, height: float, polygon: Polygon, per_mm: float) -> str:
    markers = "".join(
        f'<marker id="head-{kind}" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="3.2" markerHeight="3.2" '
        f'markerUnits="userSpaceOnUse" orient="auto"><path d="M0,1.5 L10,5 L0,8.5 z" fill="{colour}"/></marker>'
        for kind, colour in COLOURS.items()
    )
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.2f}mm" height="{height:.2f}mm" '
        f'viewBox="0 0 {width:.4f} {height:.4f}" font-family="sans-serif" data-quantity="{polygon.quantity}" '
        f'data-unit="{polygon.unit}" data-per-mm="{per_mm:.12g}">\n'
        f'<title>{html.escape(polygon.title)}</title><defs>{markers}</defs>\n'
        f'<rect width="100%" height="100%" fill="white"/>\n'
        f'<text x="6" y="8" font-size="4.2">{html.escape(polygon.title)}</text>\n'
        f'<text id="scale" x="6" y="13.5" font-size="3.6">{scale_text(per_mm, polygon.unit)}</text>'
    )


def _vector(v: PolygonVector, at, offset: np.ndarray) -> list[str]:
    """The vector's line (moved by `offset` on paper [mm], y up), with thin leaders back to its
    true ends when moved."""
    (x1, y1), (x2, y2) = at(v.tail), at(v.head)
    dx, dy = float(offset[0]), -float(offset[1])
    dash = ' stroke-dasharray="1.6,0.8"' if v.kind in ("normal", "tangential", "coriolis") else ""
    out = [f'<line class="vector" data-kind="{v.kind}" data-from="{html.escape(v.start)}" '
           f'data-to="{html.escape(v.end)}" data-label="{html.escape(v.label)}" x1="{x1 + dx:.4f}" '
           f'y1="{y1 + dy:.4f}" x2="{x2 + dx:.4f}" y2="{y2 + dy:.4f}" stroke="{COLOURS[v.kind]}" '
           f'stroke-width="0.5"{dash} marker-end="url(#head-{v.kind})"/>']
    if dx or dy:
        out += [f'<line class="leader" x1="{x:.4f}" y1="{y:.4f}" x2="{x + dx:.4f}" y2="{y + dy:.4f}" '
                f'stroke="#999999" stroke-width="0.2" stroke-dasharray="0.5,0.5"/>' for x, y in ((x1, y1), (x2, y2))]
    return out


def _figures(polygon: Polygon, at) -> list[str]:
    """Each link's image, closed and shaded in the link's colour: a polygon over three or more
    images (similar to the link), a line between two."""
    out = []
    for link, labels in polygon.figures.items():
        places: list[np.ndarray] = []
        for label in labels:
            p = polygon.images[label]
            if all(np.linalg.norm(p - q) > 1e-9 * max(np.linalg.norm(p), 1e-300) for q in places):
                places.append(p)
        if len(places) < 2:
            continue
        paper = np.array([at(p) for p in places])
        order = np.argsort(np.arctan2(*(paper - paper.mean(axis=0)).T[::-1]))
        points = " ".join(f"{x:.4f},{y:.4f}" for x, y in paper[order])
        colour = polygon.colours.get(link, "#888888")
        fill = f'fill="{colour}" fill-opacity="0.15"' if len(places) > 2 else 'fill="none"'
        out.append(f'<polygon class="image-figure" data-link="{html.escape(link)}" points="{points}" {fill} '
                   f'stroke="{colour}" stroke-width="0.35" stroke-opacity="0.8"/>')
    return out


def _magnitudes(polygon: Polygon, at, per_mm: float, offsets: list[np.ndarray], boxes: list[tuple]) -> list[str]:
    """Each vector's name and magnitude beside it ("v_B = 0.5236 m/s"), at the spot along it
    (either side) whose text box crosses the fewest other lines, names (`boxes`, on paper
    [mm], y up: grown here) and images."""
    segments = [(v.tail / per_mm + o, v.head / per_mm + o) for v, o in zip(polygon.vectors, offsets)]
    boxes = [*boxes, *(_box(p / per_mm + np.array([0.0, -1.5]), 1.6, "middle") for p in polygon.images.values())]
    out = []
    for v, (a, b) in zip(polygon.vectors, segments):
        magnitude = f"{float(np.linalg.norm(v.head - v.tail)):.4g} {_printed(polygon.unit)}"
        width = 0.55 * 2.8 * (len(v.label) + 3 + len(magnitude))  # the text's length on paper [mm]
        u = (b - a) / max(float(np.linalg.norm(b - a)), 1e-300)
        n = np.array([-u[1], u[0]])
        candidates = []
        for t in (0.5, 0.4, 0.6, 0.3, 0.7, 0.2, 0.8):
            for s in (1.0, -1.0):
                for gap in (1.8, 4.0, 6.5):
                    spot = a + t * (b - a) + s * gap * n
                    anchor = "start" if s * n[0] > 0.35 else "end" if s * n[0] < -0.35 else "middle"
                    box = _box(spot, width, anchor)
                    cost = (sum(_box_overlap(box, other) for other in boxes)
                            + sum(_box_crosses(box, p, q) for p, q in segments) + 0.2 * gap + 0.5 * abs(t - 0.5))
                    candidates.append((cost, tuple(spot), anchor, box))
        _, spot, anchor, box = min(candidates, key=lambda c: c[0])
        boxes.append(box)
        x, y = at(np.array(spot) * per_mm)
        out.append(f'<text class="magnitude" data-label="{html.escape(v.label)}" x="{x:.3f}" y="{y + 1.0:.3f}" '
                   f'font-size="2.8" fill="{COLOURS[v.kind]}" text-anchor="{anchor}">{_symbol(v.label, magnitude)}</text>')
    return out


def _box(spot: np.ndarray, width: float, anchor: str, height: float = 3.0) -> tuple[float, float, float, float]:
    """A text's box on paper [mm] (x0, y0, x1, y1; y up) about its spot, `height` high."""
    x0 = spot[0] - (0.0 if anchor == "start" else width if anchor == "end" else width / 2)
    return (x0, spot[1] - height / 2, x0 + width, spot[1] + height / 2)


def _box_overlap(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """The area two boxes share [mm^2]."""
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    return max(w, 0.0) * max(h, 0.0)


def _box_crosses(box: tuple[float, ...], p: np.ndarray, q: np.ndarray) -> float:
    """How much of the segment p-q runs through the box [mm] (sampled every ~0.5 mm)."""
    steps = max(int(np.linalg.norm(q - p) / 0.5), 1)
    t = np.linspace(0.0, 1.0, steps + 1)
    pts = p + t[:, None] * (q - p)
    inside = (pts[:, 0] >= box[0]) & (pts[:, 0] <= box[2]) & (pts[:, 1] >= box[1]) & (pts[:, 1] <= box[3])
    return float(inside.sum()) * float(np.linalg.norm(q - p)) / (steps + 1) * 3.0


def _symbol(label: str, tail: str) -> str:
    """A vector's name with its sub- and superscripts as SVG tspans (a^n_BA: a, n up, BA
    down), then " = tail" on the baseline."""
    letter, _, rest = label.partition("_")
    sup = ""
    if "^" in letter:
        letter, sup = letter.split("^", 1)
    text = f'<tspan font-style="italic">{html.escape(letter)}</tspan>'
    up = 1.1 if sup else 0.0
    if sup:
        text += f'<tspan font-size="2" dy="-{up}">{html.escape(sup)}</tspan>'
    if rest:
        text += f'<tspan font-size="2.1" dy="{up + 0.8:.1f}" dx="{-0.9 if sup else 0}">{html.escape(rest)}</tspan>'
    down = 0.8 if rest else -up  # back to the baseline
    return text + f'<tspan dy="{-down:.1f}"> = {html.escape(tail)}</tspan>'



def _labels(polygon: Polygon, at, per_mm: float, centre: np.ndarray) -> tuple[list[str], list[tuple]]:
    """One label per place: images at one place share it ("o, a, c"), set off from the centre;
    and the labels' boxes on paper [mm] (y up)."""
    groups: list[list[str]] = []
    tol = 0.3 * per_mm  # images closer than 0.3 mm on paper share a label
    for name, p in polygon.images.items():
        for group in groups:
            if np.linalg.norm(polygon.images[group[0]] - p) <= tol:
                group.append(name)
                break
        else:
            groups.append([name])
    out, boxes = [], []
    places = [polygon.images[g[0]] for g in groups]
    for group in groups:
        p = polygon.images[group[0]]
        offset = _label_direction(p, places, polygon, centre, per_mm)
        x, y = at(p)
        x, y = x + 4.5 * offset[0], y - 4.5 * offset[1]
        anchor = "start" if offset[0] > 0.3 else "end" if offset[0] < -0.3 else "middle"
        text = html.escape(", ".join(group))
        boxes.append(_box(p / per_mm + 4.5 * offset, 2.3 * len(text), anchor, 4.5))
        px, py = at(p)
        out.append(f'<circle class="image" data-label="{html.escape(group[0])}" cx="{px:.4f}" cy="{py:.4f}" r="0.7"/>')
        out.append(f'<text class="label" x="{x:.3f}" y="{y + 1.4:.3f}" font-size="4" text-anchor="{anchor}" '
                   f'font-style="italic">{text}</text>')
    return out, boxes


def _label_direction(p: np.ndarray, places: list[np.ndarray], polygon: Polygon, centre: np.ndarray,
                     per_mm: float) -> np.ndarray:
    """Where to set a label off its image (a unit vector on paper, y up): of eight directions,
    the one whose label spot (4 mm out) lies farthest from every vector and other image,
    away from the drawing's centre on a tie."""
    spots = [np.array([np.cos(t), np.sin(t)]) for t in np.radians(np.arange(0, 360, 45))]
    segments = [(v.tail / per_mm, v.head / per_mm) for v in polygon.vectors]  # on paper [mm]
    others = [q / per_mm for q in places if np.linalg.norm(q - p) > 1e-12 * per_mm]
    outward = p - centre
    outward = outward / np.linalg.norm(outward) if np.linalg.norm(outward) > 1e-12 * per_mm else np.zeros(2)

    def clearance(direction: np.ndarray) -> float:
        spot = p / per_mm + 4.5 * direction
        near = [_to_segment(spot, a, b) for a, b in segments] + [np.linalg.norm(spot - q) for q in others]
        return min(min(near, default=99.0), 6.0) + 0.5 * float(direction @ outward)

    return max(spots, key=clearance)


def _to_segment(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance from the point x to the segment a-b (same units)."""
    ab = b - a
    t = float(np.clip((x - a) @ ab / max(float(ab @ ab), 1e-300), 0.0, 1.0))
    return float(np.linalg.norm(x - a - t * ab))


def _footer(polygon: Polygon, per_mm: float, height: float, width: float) -> list[str]:
    """A scale bar of a round length and the legend of the vector kinds drawn."""
    bar_mm = 20.0
    y = height - FOOTER + 8
    out = [f'<line x1="6" y1="{y:.2f}" x2="{6 + bar_mm:.2f}" y2="{y:.2f}" stroke="black" stroke-width="0.6"/>',
           f'<text x="{8 + bar_mm:.2f}" y="{y + 1.3:.2f}" font-size="3.4">{bar_mm * per_mm:.6g} {_printed(polygon.unit)}</text>']
    kinds = [k for k in KINDS if any(v.kind == k for v in polygon.vectors)]
    for i, kind in enumerate(kinds):
        col, row = i % 2, i // 2
        x, yy = 6 + col * (width / 2), y + 7 + row * 5.5
        out.append(f'<line x1="{x:.2f}" y1="{yy:.2f}" x2="{x + 10:.2f}" y2="{yy:.2f}" stroke="{COLOURS[kind]}" '
                   f'stroke-width="0.8"/>')
        out.append(f'<text x="{x + 12:.2f}" y="{yy + 1.2:.2f}" font-size="3.4">{html.escape(KINDS[kind])}</text>')
    return out
