"""The report's printed sheet: one page on A4 and on Letter, filled, with a design table whose
numbers are the design summary's (which tests/test_design_summary*.py checks against closed
forms), and a crank-rocker's swing and time ratio checked here against the textbook's.
"""

from __future__ import annotations

import html
import json
import math
import re

import pytest

from pinmech.cli import main
from tests.conftest import SCENES

KEY = re.compile(r'<span data-key="([^"]+)">([^<]+)</span>')


def _report(tmp_path, name: str, *extra: str) -> str:
    out = tmp_path / f"{name}.html"
    assert main(["report", str(SCENES / f"{name}.toml"), "-o", str(out), *extra]) == 0
    return out


def _word_rows(pdf) -> tuple[list[float], float]:
    """The lower edge of every word on page 1 [pt] and the page's height [pt] (pdftotext -bbox)."""
    import subprocess

    out = subprocess.run(["pdftotext", "-bbox", "-f", "1", "-l", "1", str(pdf), "-"], check=True,
                         capture_output=True, text=True).stdout
    height = float(re.search(r'<page width="[0-9.]+" height="([0-9.]+)"', out).group(1))
    return [float(y) for y in re.findall(r'<word xMin="[0-9.]+" yMin="[0-9.]+" xMax="[0-9.]+" yMax="([0-9.]+)"', out)], height


@pytest.mark.browser
@pytest.mark.parametrize("name", ["four_bar", "slider_crank", "jansen_leg"])
def test_the_sheet_prints_on_one_page_of_a4_and_of_letter(tmp_path, name):
    """Chromium prints the page on each paper: one page, and not half empty (its last words,
    the line naming what stays on screen, below the page's middle). The Jansen leg, with three
    loops, ten dyad and output rows and eight lines of dimensions, is the crowded case."""
    from tests.browser import pdf_pages, print_pdf

    page = _report(tmp_path, name)
    for paper in ("A4", "letter"):
        pdf = print_pdf(page, tmp_path / f"{name}_{paper}.pdf", paper=paper)
        assert pdf_pages(pdf) == 1, paper
        bottoms, height = _word_rows(pdf)
        assert max(bottoms) > 0.6 * height, paper
    text = page.read_text(encoding="utf-8")
    assert "<h2>Given</h2>" in text and 'class="pose"' in text and '<table class="design">' in text


def _summary(tmp_path, name: str) -> dict:
    """The design summary as `pinmech sweep --summary-json` writes it (a finer sweep than the page's)."""
    out = tmp_path / f"{name}.json"
    assert main(["sweep", str(SCENES / f"{name}.toml"), "--steps", "361", "--csv", str(tmp_path / "x.csv"),
                 "--summary-json", str(out)]) == 0
    return json.loads(out.read_text(encoding="utf-8"))


def _in_table_units(key: str, value: float, rocker: bool) -> float:
    """A summary value [SI] in the table's unit: degrees for angles, mm for lengths, Q as it is."""
    if key.endswith("time_ratio"):
        return value
    if key.endswith("stroke") or (key.endswith(".value") and not rocker):
        return 1000 * value
    return math.degrees(value)


def _lookup(summary: dict, key: str):
    node = summary
    for part in key.split("."):
        node = node[int(part)] if part.isdigit() else node[part]
    return node


@pytest.mark.parametrize("name", ["four_bar", "slider_crank", "crank_shaper"])
def test_the_design_tables_numbers_are_the_design_summarys(tmp_path, name):
    """Every number of the design table is the summary's to the 6 significant figures printed:
    within half a unit of the 6th figure, or of 1e-6 (deg, mm) where the table rounds a value at
    rounding level to 0 (the crank-shaper's pressure angle, 5e-14 deg). The page's 121 poses and
    the summary's 361 locate limit positions to 1e-12 and extremes to rounding, far inside that."""
    summary = _summary(tmp_path, name)
    cells = KEY.findall(_report(tmp_path, name).read_text(encoding="utf-8"))
    assert len(cells) >= 4
    for key, shown in cells:
        rocker = not key.startswith("outputs") or _lookup(summary, ".".join(key.split(".")[:2]))["kind"] == "rocker"
        expected = _in_table_units(key, _lookup(summary, key), rocker)
        half_unit = max(0.5 * 10 ** (math.floor(math.log10(abs(expected))) - 5) if expected else 0.0, 5e-7)
        assert abs(float(html.unescape(shown)) - expected) <= half_unit, key


def test_a_crank_rockers_swing_and_time_ratio_in_the_table_are_the_textbooks(tmp_path):
    """The bundled crank-rocker: ground d = 100, crank a = 40, coupler b = 120, rocker c = 80 mm.
    At the limit positions crank and coupler are in line, O2B = b + a (extended) or b - a
    (folded); the law of cosines in triangle O2-O4-B gives the rocker's angle psi at O4 and
    the crank's angle at O2 (folded: pointing away from B, 180 deg on). Swing = psi_folded -
    psi_extended; the slow stroke takes alpha = 180 deg + (angle_folded - angle_extended) of
    the crank, Q = alpha / (360 deg - alpha) (Norton, Design of Machinery, sec. 3.3)."""
    d, a, b, c = 100.0, 40.0, 120.0, 80.0

    def at_o4(length: float) -> float:
        return math.degrees(math.acos((d * d + c * c - length * length) / (2 * d * c)))

    def at_o2(length: float) -> float:
        return math.degrees(math.acos((d * d + length * length - c * c) / (2 * d * length)))

    swing = at_o4(b + a) - at_o4(b - a)
    alpha = 180.0 + at_o2(b - a) - at_o2(b + a)
    q = alpha / (360.0 - alpha)
    text = _report(tmp_path, "four_bar", "--steps", "61").read_text(encoding="utf-8")
    cells = dict(KEY.findall(text))
    six = 5e-6  # half a unit of the 6th significant figure, relative
    assert float(cells["outputs.0.swing"]) == pytest.approx(swing, rel=six)
    assert float(cells["outputs.0.time_ratio"]) == pytest.approx(q, rel=six)
    assert float(cells["outputs.0.slow_stroke_driver_angle"]) == pytest.approx(alpha, rel=six)
    # the crank turns counter-clockwise (120 rpm): from the extended toggle (rocker at its least
    # angle) to the folded one is the slow stroke, min -> max
    assert re.search(r"slow stroke min → max over <span", text)
    assert "crank-rocker</b>, Barker I-2 GCRR" in text
