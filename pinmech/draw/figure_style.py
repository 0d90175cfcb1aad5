"""How every figure is drawn: one colour and one marker a point, and the matplotlib settings
figures are saved with.

A point is told apart from the others
by both (in grey print, or for a reader who does not tell red from green, the marker is
enough), and never shares its colour with another point of the figure.

Links keep their own colours (`pinmech.model.display`); points take Okabe and Ito's palette
for colour-blind readers, keyed by the point's place in the figure's list of points, and a
marker from a list of a different length, so that (colour, marker) pairs repeat only after
56 points.
"""

from __future__ import annotations

#: Okabe and Ito's colours (blue, vermillion, bluish green, reddish purple, orange, sky blue,
#: black, grey): told apart by colour-blind readers; yellow left out (unreadable on white).
POINT_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#7F7F7F")
#: Markers, fewer than the colours: the k-th point's pair differs from every other's up to 56.
POINT_MARKERS = ("o", "s", "^", "D", "v", "P", "X")


def point_style(index: int) -> tuple[str, str]:
    """(colour "#rrggbb", matplotlib marker) of the `index`-th point of a figure."""
    return POINT_COLOURS[index % len(POINT_COLOURS)], POINT_MARKERS[index % len(POINT_MARKERS)]


def point_styles(names) -> dict[str, tuple[str, str]]:
    """Point name -> (colour, marker), in the order the names are given."""
    return {name: point_style(k) for k, name in enumerate(names)}


#: Agg draws a long line in pieces of this many vertices: a million-pose sweep's curves
#: (20,000 kept points, dense zigzags) took 278 MB to draw in one piece, 163 MB in these
#: (scripts/sweep_memory.py).
AGG_CHUNK = 1000
#: matplotlib settings every saved figure is drawn with: long paths in chunks, SVG text as
#: text (editable, searchable), not as glyph outlines.
FIGURE_RC = {"agg.path.chunksize": AGG_CHUNK, "svg.fonttype": "none"}
