"""Labels that do not overlap: each label tries the places around its anchor in turn (the
side away from the path's middle first) and takes the first whose box meets no label
already placed (the points' names included); a label with no free place is left out, its
mark still drawn (its neighbours' labels tell its value).

Placement waits until the figure's layout is final (`settle`, called by the figure's saver
after `tight_layout`): a label's box is measured in display units, which move with the layout.
"""

from __future__ import annotations

import numpy as np

#: Offsets tried [points] with their alignment: right-above first, then round the anchor.
PLACES = ((4, 4, "left", "bottom"), (4, -4, "left", "top"), (-4, 4, "right", "bottom"), (-4, -4, "right", "top"),
          (0, 6, "center", "bottom"), (0, -6, "center", "top"), (7, 0, "left", "center"), (-7, 0, "right", "center"))
PENDING = "_pinmech_labels"  # the figure's attribute holding the labels still to place


def defer(ax, text: str, anchor, away, **style) -> None:
    """A label of `anchor` (data coordinates) to place once the layout is final; `away`: a
    point the label would rather face away from (the path's middle), or None."""
    pending = ax.figure.__dict__.setdefault(PENDING, [])
    pending.append((ax, text, np.asarray(anchor, float), None if away is None else np.asarray(away, float), style))


def settle(fig) -> list:
    """Place every deferred label of the figure; the annotations placed."""
    pending = fig.__dict__.pop(PENDING, [])
    if not pending:
        return []
    renderer = fig.canvas.get_renderer()
    for ax in {p[0] for p in pending}:
        ax.apply_aspect()
    taken = [t.get_window_extent(renderer) for ax in {p[0] for p in pending} for t in ax.texts if t.get_visible()]
    placed = []
    for ax, text, anchor, away, style in pending:
        for dx, dy, ha, va in _ordered(anchor, away):
            label = ax.annotate(text, anchor, xytext=(dx, dy), textcoords="offset points", ha=ha, va=va, **style)
            box = label.get_window_extent(renderer)
            if not any(box.overlaps(other) for other in taken) and ax.bbox.contains(*box.p0) and ax.bbox.contains(*box.p1):
                taken.append(box)
                placed.append(label)
                break
            label.remove()
    return placed


def _ordered(anchor: np.ndarray, away: np.ndarray | None) -> list[tuple]:
    """The places, those facing away from `away` first."""
    if away is None:
        return list(PLACES)
    out = anchor - away
    return sorted(PLACES, key=lambda p: -(p[0] * out[0] + p[1] * out[1]) / (np.hypot(p[0], p[1]) * max(np.hypot(*out), 1e-300)))
