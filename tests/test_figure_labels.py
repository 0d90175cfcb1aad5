"""The numbers a synthesis figure puts beside its targets stay readable where targets crowd
or coincide (a Watt's path passed out and back: pose 4 and pose 9 at one place), and stay
inside the axes, off the title (design/figure_file.number_points)."""

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from pinmech.design.figure_file import number_points  # noqa: E402


def _label_boxes(fig, ax):
    """Each number's text box on the canvas [pixels] (its leader line left out), after a draw."""
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    return [Text.get_window_extent(t, renderer) for t in ax.texts]


def test_crowded_and_coinciding_targets_get_numbers_that_do_not_overlap():
    """Ten targets on an arc, traversed out and back (pairs 1 mm apart at most) in a
    200 mm wide drawing: no two numbers' boxes overlap, each number is its target's."""
    angles = np.radians(np.r_[np.linspace(20, 110, 5), np.linspace(110, 20, 5) + 0.3])
    targets = np.c_[150 + 40 * np.cos(angles), 60 + 40 * np.sin(angles)]
    fig, ax = plt.subplots(figsize=(6.4, 5.0))
    ax.plot([0, 200], [0, 110], "k-")  # the linkage's extent: the targets crowd in a corner
    ax.plot(*targets.T, "x")
    ax.set_aspect("equal")
    ax.set_title("ten targets")
    number_points(ax, targets)
    boxes = _label_boxes(fig, ax)
    assert [t.get_text() for t in ax.texts] == [str(k) for k in range(1, 11)]
    for i in range(len(boxes)):
        for j in range(i):
            assert not boxes[i].overlaps(boxes[j]), f"labels {j + 1} and {i + 1} overlap"
    plt.close(fig)


def test_numbers_stay_inside_the_axes_and_off_the_title():
    """Targets along the top edge of the data: the axes grow to hold their numbers, so no
    number's box reaches into the title's."""
    targets = np.c_[np.linspace(0, 100, 6), np.full(6, 50.0)]
    fig, ax = plt.subplots(figsize=(6.4, 5.0))
    ax.plot([0, 100], [0, 50], "k-")
    ax.plot(*targets.T, "x")
    ax.set_aspect("equal")
    ax.set_title("targets on the top edge")
    number_points(ax, targets)
    boxes = _label_boxes(fig, ax)
    title = ax.title.get_window_extent(fig.canvas.get_renderer())
    frame = ax.get_window_extent(fig.canvas.get_renderer())
    for box in boxes:
        assert not box.overlaps(title)
        assert frame.y0 <= box.y0 and box.y1 <= frame.y1  # inside the axes' frame
    plt.close(fig)
