"""A velocity or acceleration polygon as an SVG drawing at a stated scale (no extra needed).

One SVG user unit is one millimetre of paper; the scale, a round number ("1 mm = 0.02
m/s"), is written on the drawing with a scale bar, so a teacher can measure it as a
student's drawing. Each vector is an SVG `<line>` with `data-kind`, `data-from`,
`data-to` and `data-label`, so a program can read the drawing back.
"""

from __future__ import annotations

import html
import math

import numpy as np

from pinmech.polygon import KINDS, Polygon

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


def polygon_svg(polygon: Polygon) -> str:
    """The polygon as a standalone SVG document."""
    ends = np.array([v.tail for v in polygon.vectors] + [v.head for v in polygon.vectors]
                    + list(polygon.images.values())).reshape(-1, 2)
    lo, hi = ends.min(axis=0), ends.max(axis=0)
    extent = float(max(np.max(hi - lo), 1e-300))
    per_mm = _round_up(extent / PAPER)  # quantity per millimetre of paper
    size = (hi - lo) / per_mm
    width = max(size[0] + 2 * MARGIN, 190.0)
    height = size[1] + 2 * MARGIN + HEADER + FOOTER
    x0 = (width - size[0]) / 2 - lo[0] / per_mm
    y0 = HEADER + MARGIN + hi[1] / per_mm

    def at(v: np.ndarray) -> tuple[float, float]:
        return x0 + v[0] / per_mm, y0 - v[1] / per_mm

    parts = [_header(width, height, polygon, per_mm)]
    for v in polygon.vectors:
        parts.append(_vector(v, at))
    parts += _labels(polygon, at, per_mm, (lo + hi) / 2)
    parts += _footer(polygon, per_mm, height, width)
    parts.append("</svg>\n")
    return "\n".join(parts)


def scale_text(per_mm: float, unit: str) -> str:
    """The scale as written on the drawing: "scale: 1 mm = 0.02 m/s"."""
    return f"scale: 1 mm = {per_mm:.6g} {unit}"


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


def _vector(v, at) -> str:
    (x1, y1), (x2, y2) = at(v.tail), at(v.head)
    dash = ' stroke-dasharray="1.6,0.8"' if v.kind in ("normal", "tangential", "coriolis") else ""
    return (
        f'<line class="vector" data-kind="{v.kind}" data-from="{html.escape(v.start)}" '
        f'data-to="{html.escape(v.end)}" data-label="{html.escape(v.label)}" x1="{x1:.4f}" y1="{y1:.4f}" '
        f'x2="{x2:.4f}" y2="{y2:.4f}" stroke="{COLOURS[v.kind]}" stroke-width="0.5"{dash} '
        f'marker-end="url(#head-{v.kind})"/>'
    )


def _labels(polygon: Polygon, at, per_mm: float, centre: np.ndarray) -> list[str]:
    """One label per place: images at one place share it ("o, a, c"), set off from the centre."""
    groups: list[list[str]] = []
    tol = 0.3 * per_mm  # images closer than 0.3 mm on paper share a label
    for name, p in polygon.images.items():
        for group in groups:
            if np.linalg.norm(polygon.images[group[0]] - p) <= tol:
                group.append(name)
                break
        else:
            groups.append([name])
    out = []
    places = [polygon.images[g[0]] for g in groups]
    for group in groups:
        p = polygon.images[group[0]]
        offset = _label_direction(p, places, polygon, centre, per_mm)
        x, y = at(p)
        x, y = x + 4.5 * offset[0], y - 4.5 * offset[1]
        anchor = "start" if offset[0] > 0.3 else "end" if offset[0] < -0.3 else "middle"
        text = html.escape(", ".join(group))
        px, py = at(p)
        out.append(f'<circle class="image" data-label="{html.escape(group[0])}" cx="{px:.4f}" cy="{py:.4f}" r="0.7"/>')
        out.append(f'<text class="label" x="{x:.3f}" y="{y + 1.4:.3f}" font-size="4" text-anchor="{anchor}" '
                   f'font-style="italic">{text}</text>')
    return out


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
           f'<text x="{8 + bar_mm:.2f}" y="{y + 1.3:.2f}" font-size="3.4">{bar_mm * per_mm:.6g} {polygon.unit}</text>']
    kinds = [k for k in KINDS if any(v.kind == k for v in polygon.vectors)]
    for i, kind in enumerate(kinds):
        col, row = i % 2, i // 2
        x, yy = 6 + col * (width / 2), y + 7 + row * 5.5
        out.append(f'<line x1="{x:.2f}" y1="{yy:.2f}" x2="{x + 10:.2f}" y2="{yy:.2f}" stroke="{COLOURS[kind]}" '
                   f'stroke-width="0.8"/>')
        out.append(f'<text x="{x + 12:.2f}" y="{yy + 1.2:.2f}" font-size="3.4">{html.escape(KINDS[kind])}</text>')
    return out
