"""One offline HTML page about a scene, laid out as a lab report: what was given (the
model's dimensions, the driver and its sense, gravity, loads, assumptions), numbered figures
with captions (the pose drawn to scale, the velocity and acceleration polygons, the sweep and
the paths), the motion tables, the hand-check verdicts when a hand file is given, and the
full text report folded away. pinmech's version, the date and the scene file head it.

Everything is inlined (figures as SVG or data: URIs, the interactive meshcat view as a
frame's `srcdoc`): the page opens in any browser with no network. It prints: the drawings
are plain SVG (a WebGL view prints blank, so the interactive view is left off paper), and
tables wrap within the page's width.
"""

from __future__ import annotations

import base64
import datetime
import html
import os
import tempfile
from pathlib import Path


from pinmech.exceptions import PinmechError
from pinmech.io.analysis_result import Analysis
from pinmech.io.html_tables import motion_table_html


def report_html(analysis: Analysis, *, steps: int = 121, hand_text: str | None = None) -> str:
    """The whole page: a sheet that prints on one page (A4 or Letter) -- the given data, the
    drawing beside the design table, the polygons, the sweep and the paths -- then, on screen
    only, the motion tables, the hand check and the full text report.

    Args:
        analysis: the solved scene (`pinmech.analyse`).
        steps: poses of the sweep drawn (a whole turn of the first driver); 0: no sweep.
        hand_text: the hand-check verdicts, as `pinmech check` prints them, or None.
    """
    from pinmech.io.report import to_text

    sweep_figures, summary = _sweep(analysis, steps) if steps and not analysis.scene.is_task else ([], None)
    drawing, polygons = _drawing(analysis), _polygons(analysis) if analysis.mechanism.plane_normal is not None else []
    numbered = [drawing, *polygons, *sweep_figures]
    figure = {id(f): _figure(n, *f) for n, f in enumerate(numbered, 1)}
    rows = [row for row in (polygons, sweep_figures) if row]
    sheet_fit = _fit(analysis, summary, len(rows))
    sheet = [_section("Given", _given(analysis)),
             f'<div class="pair">{figure[id(drawing)]}{_design_section(analysis, summary, steps)}</div>']
    sheet += [f'<div class="pair{"" if sheet_fit.sweep_printed or row is not sweep_figures else " off-paper"}">'
              f'{"".join(figure[id(f)] for f in row)}</div>' for row in rows]
    style = f"--figure: {sheet_fit.figure_mm:g}mm; --pose: {sheet_fit.pose_mm:g}mm"
    more = [("Results", _caption(_CAPTIONS["motion"]) + motion_table_html(analysis.motion, analysis.mechanism.plane_normal))]
    if hand_text is not None:
        more.append(("Hand calculation checked", _caption(_CAPTIONS["hand"]) + _pre(hand_text)))
    more.append(("Full text report", '<details><summary>As <code>pinmech solve</code> prints it (click to '
                 f'open)</summary>{_pre(to_text(analysis))}</details>'))
    rest = "\n".join(_section(t, content) for t, content in more)
    off = "" if sheet_fit.sweep_printed or not sweep_figures else " the sweep and paths figures (Figures 4-5),"
    body = (f'<div class="sheet" style="{style}">{"".join(sheet)}</div>\n'
            f'<p class="print-only rest">{_REST.format(off=off)}</p>\n'
            f'<div class="screen-only">{rest}</div>')
    return _PAGE.format(title=html.escape(analysis.scene.title), meta=_meta(analysis), body=body)


_REST = ("On the HTML page, not printed:{off} the points' and links' motion tables, the hand check and the full "
         "text report.")


def _fit(analysis: Analysis, summary: dict | None, rows_of_figures: int):
    """The figures' printed heights that keep the sheet on one page (report_fit.py)."""
    from pinmech.draw.report_design import design_rows
    from pinmech.draw.report_fit import fit
    from pinmech.io.report_given import given

    design = design_rows(summary) if summary and summary.get("planar") else []
    return fit(given(analysis), design, rows_of_figures=rows_of_figures)


def _section(title: str, content: str) -> str:
    return f"<section><h2>{html.escape(title)}</h2>\n{content}</section>"


def _design_section(analysis: Analysis, summary: dict | None, steps: int) -> str:
    """The design table of the page's sweep, or a line saying why there is none."""
    from pinmech.draw.report_design import design_table

    if summary is None:
        why = ("a task scene is followed in time (pinmech path)" if analysis.scene.is_task
               else "no sweep (--steps 0)" if not steps else "no pose of the sweep closed")
        return f'<section class="design"><h2>Design</h2><p class="design-none">No design table: {why}.</p></section>'
    driver = analysis.motion.joints.get(summary["driver"])
    sense = 1.0 if driver is None or driver.v >= 0 else -1.0
    return (f'<section class="design"><h2>Design</h2>{design_table(summary, sense)}'
            f'{_caption(_CAPTIONS["design"].format(poses=summary.get("poses", 0)))}</section>')


def _meta(analysis: Analysis) -> str:
    """pinmech's version, the date and the scene and model files, one line."""
    from pinmech import __version__

    when = datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    scene = Path(analysis.scene.path)
    model = Path(os.path.relpath(Path(str(analysis.mechanism.source)).resolve(), scene.resolve().parent))
    return html.escape(f"pinmech {__version__} · {when} · scene {scene} · model {model} (from the scene's folder)")


def _given(analysis: Analysis) -> str:
    from pinmech.io.report_given import given

    rows = "".join(f"<tr><th>{html.escape(h)}</th><td>" + "<br>".join(html.escape(x) for x in lines) + "</td></tr>"
                   for h, lines in given(analysis))
    return f'<table class="given">{rows}</table>'


def _drawing(analysis: Analysis) -> tuple[str, str]:
    """Figure 1: the space diagram (planar), or the interactive view (spatial)."""
    if analysis.mechanism.plane_normal is not None:
        from pinmech.draw.space_svg import pose_svg

        return pose_svg(analysis) + _interactive(analysis, "Interactive 3-D view"), _CAPTIONS["pose"]
    return _interactive(analysis, None), _CAPTIONS["drawing"]


def _figure(number: int, body: str, caption: str) -> str:
    return (f'<figure id="figure-{number}">{body}<figcaption><b>Figure {number}.</b> {html.escape(caption)}'
            f"</figcaption></figure>")


def _interactive(analysis: Analysis, folded: str | None) -> str:
    """The meshcat view in a frame; folded under `folded` (a summary) when a static drawing
    stands for it. Not printed (WebGL prints blank): a line on paper says so."""
    page = snapshot(analysis).html
    frame = f'<iframe class="drawing" title="the mechanism at the scene\'s pose" srcdoc="{html.escape(page)}"></iframe>'
    if folded:
        frame = f"<details><summary>{html.escape(folded)} (drag to turn, scroll to zoom)</summary>{frame}</details>"
    note = '<p class="print-only">The interactive 3-D view is on the HTML page (it does not print).</p>'
    return f'<div class="screen-only">{frame}</div>' + ("" if folded else note)


def _polygons(analysis: Analysis) -> list[tuple[str, str]]:
    """The velocity and acceleration polygons (the space diagram is Figure 1), captioned."""
    from pinmech.draw.polygon_svg import polygon_svg
    from pinmech.draw.polygon import acceleration_polygon, velocity_polygon

    return [(polygon_svg(make(analysis)), _CAPTIONS[key]) for make, key in
            ((velocity_polygon, "velocity"), (acceleration_polygon, "acceleration"))]


def _sweep(analysis: Analysis, steps: int) -> tuple[list[tuple[str, str]], dict | None]:
    """The sweep and paths figures over one turn of the first driver (up to a fold, where the
    driver cannot turn on), and the sweep's design summary (`pinmech.design_summary`)."""
    import math

    from pinmech.draw.plot import SweepPlot
    from pinmech.io.sweep import Sweep
    from pinmech.solve.design_summary import design_summary
    from pinmech.solve.diagnostics_sweep import design_of

    sweep = Sweep.from_scene(analysis.scene)
    recorder, design = SweepPlot(sweep, total=steps), design_of(sweep)
    values = sweep.default_values(steps)
    for pose in sweep.poses(values, skip_failures=True, to_fold=True, past_change_points=True):
        recorder.add(pose)
        design.add(pose)
    turn = sweep.is_angular and sweep.fold_end is None
    summary = design_summary(sweep, 2 * math.pi if turn else None) if design.count or not design.applicable else None
    with tempfile.TemporaryDirectory() as folder:
        try:
            figures = [recorder.save(Path(folder) / "sweep.png")]
            if recorder.points:
                figures.append(recorder.save_paths(Path(folder) / "paths.png"))
        except PinmechError as exc:  # every pose failed: the page says so, the rest stands
            return [(f"<p>No sweep figure: {html.escape(str(exc))}</p>", _CAPTIONS["sweep"])], summary
        return [(f'<img alt="{p.stem}" src="data:image/png;base64,{base64.b64encode(p.read_bytes()).decode()}">',
                 _CAPTIONS[p.stem]) for p in figures], summary


_CAPTIONS = {
    "pose": "The mechanism at the scene's pose, drawn to scale (space diagram): each link in its colour, "
            "pins as open circles, named points as dots, fixed pivots and guides hatched grey.",
    "drawing": "The mechanism at the scene's pose, named points as black dots (drag to turn, scroll to zoom).",
    "velocity": "Velocity polygon at the pose of Figure 1: from the pole o each point's velocity; between points "
                "of one link their relative velocity; between a guide and its slider the sliding velocity. Each "
                "link's velocity image shaded in its colour; scale written on the drawing.",
    "acceleration": "Acceleration polygon at the pose of Figure 1: from the pole o' each point's acceleration; "
                    "relative accelerations as their normal and tangential parts, a slider's as its Coriolis and "
                    "sliding parts; a point on two links reached by both routes. Scale written on the drawing.",
    "sweep": "Every quantity against the driver over one turn (the scene's pose dashed).",
    "design": "From the design summary of the sweep's {poses} poses (pinmech sweep --summary-json gives it at full "
              "precision): extremes located between the poses, at toggles and change points included; driver "
              "positions on [0, 360) deg.",
    "paths": "The paths of the named points over one turn, with the mechanism at the scene's pose.",
    "motion": "Table 1: the points; Table 2: the links. World frame, SI units; φ, ω, α about the plane's normal "
              "for a planar mechanism.",
    "hand": "Each hand value against pinmech's, within the rounding of its printed digits.",
}


def _caption(text: str) -> str:
    return f'<p class="caption">{html.escape(text)}</p>'


def _pre(text: str) -> str:
    return f"<pre>{html.escape(text)}</pre>"


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{font: 14px sans-serif; margin: 16px auto; max-width: 1100px; color: #222; padding: 0 8px}}
h1 {{font-size: 20px; margin-bottom: 2px}} h2 {{font-size: 16px; border-bottom: 1px solid #ccc; margin: 10px 0 4px}}
.meta {{color: #666; font-size: 12px; margin-top: 0}}
iframe.drawing {{width: 100%; height: 520px; border: 1px solid #ccc}}
.caption {{color: #555; margin: 4px 0 8px}}
pre {{font-size: 12px; background: #f7f7f7; padding: 8px; overflow-x: auto}}
.pair {{display: flex; gap: 16px; align-items: flex-start}} .pair > * {{flex: 1 1 0; min-width: 0}}
figure {{margin: 12px 0}} figcaption {{color: #444; font-size: 13px; margin-top: 4px}}
figure svg, figure img {{display: block; max-width: 100%; height: auto}} figure svg.pose {{max-height: 460px}}
table {{border-collapse: collapse; margin: 6px 0; max-width: 100%}}
td, th {{border: 1px solid #ccc; padding: 2px 6px; overflow-wrap: anywhere; vertical-align: top}}
table.given th, table.design th {{text-align: left; background: #f4f4f4}} table.given th {{white-space: nowrap}}
table.design th {{width: 32%}}
.print-only {{display: none}}
@page {{margin: 9mm}}
@media print {{
  body {{max-width: none; margin: 0; padding: 0; font-size: 7.5pt}}
  h1 {{font-size: 12pt; margin: 0}} .meta {{font-size: 6.5pt; margin: 0 0 1mm}}
  h2 {{font-size: 9pt; margin: 1.5mm 0 1mm}}
  .screen-only {{display: none}} .print-only {{display: block}} .rest {{font-size: 6.5pt; color: #666; margin: 1mm 0 0}}
  .sheet {{break-after: avoid}} .pair {{gap: 4mm}}
  figure {{margin: 1.5mm 0; break-inside: avoid}} figcaption {{font-size: 6.5pt; margin-top: 0.5mm; line-height: 1.2}}
  figure svg, figure img {{max-width: 100%; width: auto; max-height: var(--figure, 52mm); margin: 0 auto}}
  figure svg.pose {{max-height: var(--pose, 60mm)}} .off-paper {{display: none}}
  .caption {{font-size: 6.5pt; margin: 1mm 0}}
  table {{width: 100%; font-size: 7pt}} td, th {{padding: 0.3mm 1.2mm; line-height: 1.2}}
}}
</style></head>
<body><h1>{title}</h1>
<p class="meta">{meta}</p>
{body}
<p class="screen-only" style="color:#777">Written by pinmech; offline: everything is on this page.</p>
</body></html>
"""


class HtmlPage:
    """A finished offline page: `save(path)` writes it, and Jupyter shows it inline
    (`_repr_html_`: the page in a frame of its own, so its scripts run apart)."""

    def __init__(self, page: str, height: int = 480) -> None:
        self.html, self.height = page, height

    def save(self, path: str | Path) -> Path:
        from pinmech.outputs import write_whole

        path = Path(path)
        write_whole(path, self.html)  # whole or not at all; a link at `path` replaced, not written through
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
    from pinmech.model.display import labelled_places

    points = labelled_places(mech, analysis.solution.q)  # joints and points, as the textbook names them
    return HtmlPage(snapshot_html(mech.model, visuals, analysis.solution.q, points=points,
                                  plane_normal=mech.plane_normal, title=analysis.scene.title))
