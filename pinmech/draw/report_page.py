"""One offline HTML page about a scene: the drawing (meshcat, in a frame of its own), the text
report's tables, the velocity and acceleration polygons, the sweep figures and paths, and the
hand-check verdicts when a hand file is given. Everything is inlined (figures as data: URIs,
the drawing as the frame's `srcdoc`): the page opens in any browser with no network.
"""

from __future__ import annotations

import base64
import html
import tempfile
from pathlib import Path

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.results import Analysis


def report_html(analysis: Analysis, *, steps: int = 121, hand_text: str | None = None) -> str:
    """The whole page.

    Args:
        analysis: the solved scene (`pinmech.analyse`).
        steps: poses of the sweep drawn (a whole turn of the first driver); 0: no sweep.
        hand_text: the hand-check verdicts, as `pinmech check` prints them, or None.
    """
    from pinmech.report import to_text

    sections = [("Drawing", _caption(_CAPTIONS["drawing"]) + _drawing(analysis)),
                ("Motion", _caption(_CAPTIONS["motion"]) + motion_table_html(analysis)),
                ("Report", _pre(to_text(analysis)))]
    if analysis.mechanism.plane_normal is not None:
        sections.append(("Velocity and acceleration polygons", _caption(_CAPTIONS["polygons"]) + _polygons(analysis)))
    if steps and "task" not in analysis.scene.raw:
        sections.append(("Over a turn of the driver", _caption(_CAPTIONS["sweep"]) + _sweep(analysis, steps)))
    if hand_text is not None:
        sections.append(("Hand calculation checked", _caption(_CAPTIONS["hand"]) + _pre(hand_text)))
    body = "\n".join(f"<section><h2>{html.escape(t)}</h2>\n{content}</section>" for t, content in sections)
    title = html.escape(analysis.scene.title)
    return _PAGE.format(title=title, body=body)


def _drawing(analysis: Analysis) -> str:
    page = snapshot(analysis).html
    return f'<iframe class="drawing" title="the mechanism at the scene\'s pose" srcdoc="{html.escape(page)}"></iframe>'


def _polygons(analysis: Analysis) -> str:
    from pinmech.draw.polygon_svg import polygon_svg
    from pinmech.polygon import acceleration_polygon, velocity_polygon

    return "".join(f'<div class="figure">{polygon_svg(make(analysis), analysis)}</div>'
                   for make in (velocity_polygon, acceleration_polygon))


def _sweep(analysis: Analysis, steps: int) -> str:
    from pinmech.plot import SweepPlot
    from pinmech.sweep import Sweep

    sweep = Sweep.from_scene(analysis.scene)
    recorder = SweepPlot(sweep, total=steps)
    for pose in sweep.poses(sweep.default_values(steps), skip_failures=True):
        recorder.add(pose)
    with tempfile.TemporaryDirectory() as folder:
        try:
            figures = [recorder.save(Path(folder) / "sweep.png")]
            if recorder.points:
                figures.append(recorder.save_paths(Path(folder) / "paths.png"))
        except PinmechError as exc:  # every pose failed: the page says so, the rest stands
            return f"<p>No sweep figure: {html.escape(str(exc))}</p>"
        return "".join(f'<img alt="{p.stem}" src="data:image/png;base64,{base64.b64encode(p.read_bytes()).decode()}">'
                       for p in figures)


_CAPTIONS = {
    "drawing": "The mechanism at the scene's pose, named points as black dots (drag to turn, scroll to zoom).",
    "motion": "World frame, SI units; φ, ω, α about the plane's normal for a planar mechanism.",
    "polygons": "From the pole o: each point's velocity (acceleration); between points of one link their "
                "relative motion (normal and tangential parts), between a guide and its slider the sliding "
                "and Coriolis parts. The scale is written on each drawing.",
    "sweep": "Every quantity against the driver over one turn (the scene's pose dashed), and the paths of "
             "the points with the mechanism at the scene's pose.",
    "hand": "Each hand value against pinmech's, within the rounding of its printed digits.",
}


def _caption(text: str) -> str:
    return f'<p class="caption">{html.escape(text)}</p>'


def _pre(text: str) -> str:
    return f"<pre>{html.escape(text)}</pre>"


def _html_table(rows: list[list[str]]) -> str:
    """A plain HTML table, the first row its header."""
    head, *rest = rows
    cells = "".join(f"<th>{html.escape(c)}</th>" for c in head)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rest)
    return f"<table><tr>{cells}</tr>{body}</table>"


def motion_table_html(analysis: Analysis) -> str:
    """The points' and links' motion as HTML tables (SI units; angles in degrees)."""
    m = analysis.motion
    normal = analysis.mechanism.plane_normal
    points = [["point", "link", "position [m]", "velocity [m/s]", "|v| [m/s]", "acceleration [m/s²]", "|a| [m/s²]"]]
    for name, p in m.points.items():
        points.append([name, p.link, _vec(p.position), _vec(p.velocity), f"{np.linalg.norm(p.velocity):.6g}",
                       _vec(p.acceleration), f"{np.linalg.norm(p.acceleration):.6g}"])
    links = [["link", "φ [deg]", "ω [rad/s]", "α [rad/s²]"]]
    for name, link in m.links.items():
        w = link.angular_velocity if normal is None else [float(normal @ link.angular_velocity)]
        a = link.angular_acceleration if normal is None else [float(normal @ link.angular_acceleration)]
        angle = "" if link.angle is None else f"{np.degrees(link.angle):.6g}"
        links.append([name, angle, _vec(np.asarray(w)), _vec(np.asarray(a))])
    return _html_table(points) + _html_table(links)


def _vec(v: np.ndarray) -> str:
    return ", ".join(f"{x:.6g}" for x in np.ravel(v)) if np.size(v) != 1 else f"{float(np.ravel(v)[0]):.6g}"


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{font: 14px sans-serif; margin: 16px auto; max-width: 1100px; color: #222}}
h1 {{font-size: 20px}} h2 {{font-size: 16px; border-bottom: 1px solid #ccc}}
iframe.drawing {{width: 100%; height: 520px; border: 1px solid #ccc}}
.caption {{color: #555; margin: 4px 0 8px}}
pre {{font-size: 12px; background: #f7f7f7; padding: 8px; overflow-x: auto}}
img, .figure svg {{max-width: 100%; height: auto}} img[alt="paths"] {{max-width: 760px}} .figure {{display: inline-block; width: 49%; vertical-align: top}}
table {{border-collapse: collapse; margin: 6px 0}} td, th {{border: 1px solid #ccc; padding: 2px 6px}}
</style></head>
<body><h1>{title}</h1>
{body}
<p style="color:#777">Written by pinmech; offline: everything is on this page.</p>
</body></html>
"""


class HtmlPage:
    """A finished offline page: `save(path)` writes it, and Jupyter shows it inline
    (`_repr_html_`: the page in a frame of its own, so its scripts run apart)."""

    def __init__(self, page: str, height: int = 480) -> None:
        self.html, self.height = page, height

    def save(self, path: str | Path) -> Path:
        path = Path(path)
        path.write_text(self.html, encoding="utf-8")
        return path

    def _repr_html_(self) -> str:
        return (f'<iframe style="width: 100%; height: {self.height}px; border: 1px solid #ccc" '
                f'srcdoc="{html.escape(self.html)}"></iframe>')


def snapshot(analysis: Analysis) -> HtmlPage:
    """The solved pose drawn (meshcat, offline), its points named: shows inline in Jupyter."""
    mech = analysis.mechanism
    from pinmech.draw import snapshot_html
    from pinmech.draw.pages import mechanism_visuals

    visuals = mechanism_visuals(mech)[0]  # the model's own file: a URDF, a drawn linkage's, an MJCF file
    from pinmech.display import labelled_places

    points = labelled_places(mech, analysis.solution.q)  # joints and points, as the textbook names them
    return HtmlPage(snapshot_html(mech.model, visuals, analysis.solution.q, points=points,
                                  plane_normal=mech.plane_normal, title=analysis.scene.title))
