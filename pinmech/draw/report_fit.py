"""How tall the report's figures may be drawn for its sheet to print on one page, on A4 and
on Letter alike (the smaller of each: 210 mm wide, 279.4 mm high), from how much text the
Given and Design tables hold.

The estimate is deliberately pessimistic (every wrapped line counted, a character as wide as
7 pt text's average letter): a page that fits by it fits in print. Where even the smallest
readable figures do not fit, the sweep and paths figures stay on the HTML page, off paper.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

PAGE_MM = (210.0 - 2 * 9.0, 279.4 - 2 * 9.0)  # printable width, height [mm]: A4's width, Letter's height, 9 mm margins
SLACK_MM = 8.0  # kept free for what the estimate misses (rounding of line boxes, borders) [mm]
LINE_MM = 7 * 1.2 * 25.4 / 72  # one 7 pt line at line-height 1.2 [mm]
CHAR_MM = 7 * 0.55 * 25.4 / 72  # an average character of 7 pt sans-serif, rounded up [mm]
CAPTION_LINE_MM = 6.5 * 1.2 * 25.4 / 72  # a caption line, 6.5 pt [mm]
HEAD_MM, HEADING_MM, FIGURE_GAP_MM = 12.0, 7.0, 3.5  # title and meta; an h2 with its margins; a figure's margins
LARGEST_MM, SMALLEST_MM = 52.0, 30.0  # figure heights [mm]: as drawn when there is room; the least readable
POSE_EXTRA_MM = 8.0  # the drawing of the mechanism is drawn that much taller than the other figures


@dataclass(frozen=True)
class SheetFit:
    """Figure heights for the printed sheet [mm]; `sweep_printed` False: the sweep's row is off paper."""

    figure_mm: float
    pose_mm: float
    sweep_printed: bool


def fit(given_rows: list[tuple[str, list[str]]], design_rows: list[tuple[str, str]], *, rows_of_figures: int) -> SheetFit:
    """The tallest figures that keep the sheet on one page; `rows_of_figures` the rows of two
    figures under the drawing (the polygons, the sweep and paths)."""
    given = sum(_table_row(h, lines, 0.15, 0.85, PAGE_MM[0]) for h, lines in given_rows) + HEADING_MM
    half = (PAGE_MM[0] - 4.0) / 2
    design = HEADING_MM + 3 * CAPTION_LINE_MM + sum(
        _table_row(h, [_plain(x) for x in cell.split("<br>")], 0.32, 0.68, half) for h, cell in design_rows)
    for rows in range(rows_of_figures, -1, -1):
        budget = PAGE_MM[1] - SLACK_MM - HEAD_MM - given - CAPTION_LINE_MM  # the last line: what is off paper
        for height in range(int(LARGEST_MM), int(SMALLEST_MM) - 1, -1):
            pose_row = max(height + POSE_EXTRA_MM + 3 * CAPTION_LINE_MM + FIGURE_GAP_MM, design)
            figure_rows = rows * (height + 4 * CAPTION_LINE_MM + FIGURE_GAP_MM)
            if pose_row + figure_rows <= budget:
                return SheetFit(float(height), height + POSE_EXTRA_MM, rows == rows_of_figures)
    return SheetFit(SMALLEST_MM, SMALLEST_MM + POSE_EXTRA_MM, False)


def _table_row(heading: str, lines: list[str], head_share: float, cell_share: float, width: float) -> float:
    """A table row's height [mm]: the taller of its heading and its cell, every line wrapped."""
    def wrapped(text: str, share: float) -> int:
        per_line = max(1, int((share * width - 2.4) / CHAR_MM))
        return max(1, math.ceil(len(text) / per_line))

    cell = sum(wrapped(x, cell_share) for x in lines) or 1
    return max(cell, wrapped(heading, head_share)) * LINE_MM + 1.0


def _plain(cell: str) -> str:
    """A cell's text, tags dropped."""
    return re.sub(r"<[^>]+>", "", cell)
