"""The workspace measure's interval against closed forms: the five-bar's workspace is the
intersection of two annuli, whose area the lens formula gives (tests/test_workspace_study.py
derives it); a disc's area is pi r^2. Membership is the closed form itself here, so what is
checked is the refinement's interval: the exact area always inside it, and its half width
under the tolerance asked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pinmech.design.workspace.measure import measure, refined_measures
from tests.test_workspace_study import annuli_area, in_annuli


def _grid(step: float) -> list[np.ndarray]:
    """A grid over the five-bar's annuli (x -60 .. 160 mm, y -160 .. 160 mm) [m]."""
    return [np.arange(-0.06, 0.16 + step / 2, step), np.arange(-0.16, 0.16 + step / 2, step)]


def _annuli_membership(points: np.ndarray) -> dict[str, np.ndarray]:
    return {"ws": in_annuli(points)}


def _on_grid(coords: list[np.ndarray]) -> dict[str, np.ndarray]:
    return {"ws": in_annuli(np.stack(np.meshgrid(*coords, indexing="ij"), axis=-1))}


@pytest.mark.parametrize("tolerance", [0.2, 0.05, 0.01, 0.003])
def test_refined_annuli_area_holds_the_exact_area_within_the_tolerance_asked(tolerance):
    """On a 10 mm grid, each tolerance: the lens-formula area lies within value +- bound, and
    bound <= tolerance x value (the depth cap, 8 levels, is not what stops it)."""
    coords = _grid(0.01)
    exact = annuli_area()
    m = refined_measures(_on_grid(coords), coords, _annuli_membership, depth=8, tolerance=tolerance)["ws"]
    lo, hi = m.interval
    assert lo <= exact <= hi, (lo, exact, hi)
    assert m.bound <= tolerance * m.value, (m.bound, m.value)
    assert m.depth < 8 and not m.edge


def test_the_interval_shrinks_level_by_level_and_always_holds_the_exact_area():
    """Depth 0 .. 6 on a 10 mm grid: every interval holds the lens-formula area, and each level
    halves the width (the mixed cells' total area goes as boundary length x cell side; the
    ratio between levels is 1/2 to within the boundary's local wiggle, 0.4 .. 0.6 here)."""
    coords = _grid(0.01)
    exact = annuli_area()
    bounds = []
    for depth in range(7):
        m = refined_measures(_on_grid(coords), coords, _annuli_membership, depth=depth, tolerance=None)["ws"]
        lo, hi = m.interval
        assert lo <= exact <= hi, (depth, lo, exact, hi)
        bounds.append(m.bound)
    ratios = np.array(bounds[1:]) / np.array(bounds[:-1])
    assert np.all((0.4 < ratios) & (ratios < 0.6)), ratios


def test_the_unrefined_interval_is_the_grid_cells_between_all_in_and_any_in():
    """A disc of radius 30 mm on a 1 mm grid: pi r^2 within the unrefined interval, whose half
    width is the cells the circle crosses (about 2 pi r / h x 1.27 of them) over 2."""
    h, r = 1e-3, 0.03
    axis = np.arange(-0.04, 0.04 + h / 2, h)
    x, y = np.meshgrid(axis, axis, indexing="ij")
    m = measure(x**2 + y**2 <= r * r, (h, h))
    lo, hi = m.interval
    assert lo <= math.pi * r * r <= hi
    crossings = 2 * math.pi * r / h * 4 / math.pi  # mean |cos| + |sin| of the boundary's direction
    assert 0.5 * crossings < m.bound / (h * h) * 2 < 1.5 * crossings


def test_refinement_tests_only_new_points_and_keeps_keys_apart():
    """Two keys (the disc and its left half) refined together: each interval holds its own
    exact area (pi r^2 and pi r^2 / 2), and the points tested are counted once."""
    h, r = 4e-3, 0.03
    axis = np.arange(-0.042, 0.042 + h / 2, h)
    coords = [axis, axis]

    def member(p: np.ndarray) -> dict[str, np.ndarray]:
        disc = (p[..., 0] ** 2 + p[..., 1] ** 2) <= r * r
        return {"disc": disc, "left": disc & (p[..., 0] <= 0.0)}

    grid = member(np.stack(np.meshgrid(*coords, indexing="ij"), axis=-1))
    out = refined_measures(grid, coords, member, depth=4, tolerance=None)
    for key, exact in (("disc", math.pi * r * r), ("left", math.pi * r * r / 2)):
        lo, hi = out[key].interval
        assert lo <= exact <= hi, (key, lo, exact, hi)
    assert out["disc"].points == out["left"].points > 0
