"""The sweep figures as a lecturer reads them, checked by reading the drawn artists back
(colours, markers, limits, units, label boxes), not by comparing pixels: each point its own
colour and marker, the transmission angle on 0-180 deg with the 40-140 deg band, rates in a
unit that keeps them under five digits, timing labels apart, a slider's guide no longer than
what moves along it, SVG text kept as text and titles inside the figure.
"""

from __future__ import annotations

import itertools
import math

import matplotlib
import numpy as np
import pytest

from pinmech.cli import main
from tests.conftest import SCENES

matplotlib.use("Agg")


@pytest.fixture
def kept(monkeypatch):
    """The figures pinmech saves, kept open (matplotlib's close made a no-op) to read back."""
    import matplotlib.pyplot as plt

    figures = []
    monkeypatch.setattr(plt, "close", lambda fig=None: figures.append(fig))
    return figures


def _sweep(tmp_path, scene: str, *args: str) -> None:
    assert main(["sweep", str(SCENES / f"{scene}.toml"), "--csv", str(tmp_path / "s.csv"), *args]) == 0


def _panel(fig, word: str):
    return next(ax for ax in fig.axes if word in ax.get_title())


def test_each_point_has_its_own_colour_and_marker(tmp_path, kept):
    """Five points of the Jansen leg: drawn in their links' colours, points of one link shared
    one (D and G on the foot, both orange); now no two share a colour or a marker, in the
    panels and the paths, and each keeps its style from one figure to the other."""
    names = ["C", "D", "E", "F", "G"]
    _sweep(tmp_path, "jansen_leg", "--steps", "73", "--points", *names, "--plot", str(tmp_path / "f.png"),
           "--paths", str(tmp_path / "p.png"))
    sweep_fig, paths_fig = kept
    speed = _panel(sweep_fig, "speed")
    lines = [x for x in speed.get_lines() if x.get_label() in names]
    assert len(lines) == 5
    styles = [(matplotlib.colors.to_hex(x.get_color()), x.get_marker()) for x in lines]
    assert len({c for c, _ in styles}) == 5 and len({m for _, m in styles}) == 5
    paths = [x for x in paths_fig.axes[0].get_lines() if x.get_label().startswith("path of")]
    drawn = [(matplotlib.colors.to_hex(x.get_color()), x.get_marker()) for x in paths]
    assert len(paths) == 5 and len({c for c, _ in drawn}) == 5 and len({m for _, m in drawn}) == 5
    assert dict(zip((x.get_label() for x in lines), styles)) == {
        x.get_label().removeprefix("path of "): s for x, s in zip(paths, drawn)}  # one style a point, both figures


def test_the_transmission_angle_on_0_to_180_with_the_working_band(tmp_path, kept):
    """The crank-rocker's mu is drawn as computed, on [0, 180] deg (not folded about 90), the
    axis 0-180 with the 40-140 deg band shaded; its least value is the closed form's
    cos mu = (b^2 + c^2 - (d - a)^2) / (2 b c) at the crank along the ground (26.384 deg),
    to the sweep's 1-degree steps (the curve is flat there: 0.01 deg covers it)."""
    _sweep(tmp_path, "four_bar", "--steps", "361", "--plot", str(tmp_path / "f.png"))
    ax = _panel(kept[0], "transmission angle")
    assert ax.get_ylim() == (0.0, 180.0)
    (band,) = [p for p in ax.patches if p.get_gid() == "transmission band"]
    assert (band.get_y(), band.get_y() + band.get_height()) == pytest.approx((40.0, 140.0))  # a Rectangle
    (mu,) = [x for x in ax.get_lines() if x.get_label() == "B (coupler-rocker)"]
    a, b, c, d = 40.0, 120.0, 80.0, 100.0
    least = math.degrees(math.acos((b * b + c * c - (d - a) ** 2) / (2 * b * c)))
    assert np.nanmin(mu.get_ydata()) == pytest.approx(least, abs=0.01)


def test_rates_in_a_unit_that_keeps_them_under_five_digits(tmp_path, kept):
    """The four-bar's P: speed up to 0.81 m/s stays in mm/s (808), acceleration up to 15.5
    m/s^2 is drawn in m/s^2, not as 15,500 mm/s^2."""
    _sweep(tmp_path, "four_bar", "--plot", str(tmp_path / "f.png"))
    speed, acceleration = _panel(kept[0], "P: speed"), _panel(kept[0], "P: acceleration")
    assert "[mm/s]" in speed.get_ylabel() and "[m/s²]" in acceleration.get_ylabel()
    top = max(np.nanmax(x.get_ydata()) for x in acceleration.get_lines() if x.get_label() == "P")
    assert 10.0 < top < 1e4


def _overlaps(boxes) -> list:
    return [(a, b) for (a, x), (b, y) in itertools.combinations(boxes, 2) if x.overlaps(y)]


def test_timing_labels_do_not_overlap_each_other_or_the_points_names(tmp_path, kept):
    """Every 30 deg of the four-bar's crank, on P's path: the labels' boxes meet neither
    each other nor a point's name (300 deg sat on A before)."""
    _sweep(tmp_path, "four_bar", "--paths", str(tmp_path / "p.png"), "--timing-marks", "30 deg")
    fig = kept[0]
    renderer = fig.canvas.get_renderer()
    texts = [t for t in fig.axes[0].texts if t.get_visible() and t.get_text()]
    timing = [t for t in texts if (t.get_gid() or "").startswith("timing")]
    assert len(timing) >= 10  # most of the 12 marks keep their label
    assert not _overlaps([(t.get_text(), t.get_window_extent(renderer)) for t in texts])


def test_a_guide_spans_the_stroke_not_more(tmp_path, kept):
    """The slider-crank's guide is drawn over what moves along it (the crank's circle and
    the piston's stroke) and a margin of 8 % of the mechanism's largest link, under 6 % of
    what is drawn (before: to 1.5 times that link past the guide's origin, 25 mm past the
    piston's stroke, 10 % of the drawing; a 380 mm guide shrank a mechanism to a fifth)."""
    _sweep(tmp_path, "slider_crank", "--paths", str(tmp_path / "p.png"))
    ax = kept[0].axes[0]
    (guide,) = [x for x in ax.get_lines() if x.get_gid() == "guide"]
    others = np.vstack([x.get_xydata() for x in ax.get_lines() if x.get_gid() != "guide" and len(x.get_xydata())])
    span = np.ptp(others[:, 0])
    g = guide.get_xdata()
    assert max(g) - others[:, 0].max() <= 0.06 * span and others[:, 0].min() - min(g) <= 0.06 * span
    (x0, x1) = ax.get_xlim()
    assert x1 - x0 <= 1.3 * span  # the mechanism fills the axes' width (6 % margins each side)


def test_svg_text_is_text_and_titles_are_inside_the_figure(tmp_path, kept):
    """An SVG figure keeps its words as <text> (editable, searchable), and every title, the
    figure's and the panels', lies inside the figure as saved."""
    _sweep(tmp_path, "four_bar", "--plot", str(tmp_path / "f.svg"))
    svg = (tmp_path / "f.svg").read_text(encoding="utf-8")
    assert "<text" in svg and "transmission angle" in svg
    fig = kept[0]
    renderer = fig.canvas.get_renderer()
    inside = fig.bbox
    for title in [fig._suptitle, *(ax.title for ax in fig.axes if ax.get_visible())]:
        if title is None or not title.get_text():
            continue
        box = title.get_window_extent(renderer)
        assert inside.x0 <= box.x0 and box.x1 <= inside.x1 and inside.y0 <= box.y0 and box.y1 <= inside.y1, \
            title.get_text()
