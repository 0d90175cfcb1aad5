"""Slider-crank synthesis: the bundled offset slider-crank (models/linkages/slider_crank.toml:
crank 40 mm, rod 130 mm, slide along x at 50 mm) solved by the engine, sampled, hidden, and
recovered by path and by function generation without defects; the written linkage swept
by the engine meets the targets again. And its fold: the rod square to the slide."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.linkage import engine_check, write_linkage
from pinmech.design.synthesis.search import synthesise
from pinmech.design.synthesis.slider import folds, pose
from tests.tolerance import rounding

ROOT = Path(__file__).resolve().parents[1]
CRANK = np.arange(20.0, 300.0, 30.0)  # deg: ten crank angles, ccw, on the bundled linkage's assembly


def _engine_pins(tmp_path: Path, crank_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A and B [m] of the bundled drawn slider-crank, solved by the engine's sweep from its
    drawn pose (crank along x, B ahead on the slide) at these crank angles."""
    from pinmech.io.scene import Scene
    from pinmech.io.sweep import Sweep

    scene = tmp_path / "bundled_scene.toml"
    linkage = (ROOT / "models/linkages/slider_crank.toml").as_posix()
    scene.write_text(f'title = "bundled slider-crank"\nlinkage = "{linkage}"\n'
                     '[drivers.O]\nangle = "0 deg"\n[report]\npoints = ["A", "B"]\n', encoding="utf-8")
    sweep = Sweep.from_scene(Scene.load(scene))
    dense = np.radians(np.unique(np.concatenate((np.arange(0.0, 300.0, 1.0), crank_deg))))
    rows = {round(p.value, 12): (p.motion.points["A"].position[:2], p.motion.points["B"].position[:2])
            for p in sweep.poses(dense)}
    got = [rows[round(math.radians(c), 12)] for c in crank_deg]
    return np.array([g[0] for g in got]), np.array([g[1] for g in got])


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_path_synthesis_recovers_the_bundled_slider_crank(tmp_path, seed):
    # A coupler point on the bundled rod, 60 mm along A -> B and 20 mm to its left, taken
    # from the engine's A and B at ten crank angles; the linkage hidden, the search meets the
    # points within 1e-8 of the linkage's size (130 mm) on each of five seeds (3 to 5 s
    # each), and the engine sweeping the written drawn linkage does too (its Newton
    # tolerance is far below 1e-8).
    A, B = _engine_pins(tmp_path, CRANK)
    w = (B - A) / np.linalg.norm(B - A, axis=1)[:, None]
    targets = A + 0.06 * w + 0.02 * np.stack((-w[:, 1], w[:, 0]), -1)
    lower = np.array([-0.06, -0.06, math.radians(-30), -0.1, 0.01, 0.04, -0.15, -0.15])
    upper = np.array([0.06, 0.06, math.radians(30), 0.1, 0.08, 0.2, 0.15, 0.15])
    spec = SynthesisSpec(Path("test.toml"), "test", "path", "slider-crank", targets, None, lower, upper,
                         seed=seed, population=15, generations=400, keep=1)
    best = synthesise(spec).linkages[0]
    assert best.topology == "slider-crank" and best.meets(1e-8)
    assert best.grashof == "crank"  # 40 + 50 <= 130: the crank turns fully (no fold anywhere)
    _, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    check = engine_check(scene, best, targets)
    assert check.errors.max() <= 1e-8 * best.size


def _rod_poses(A: np.ndarray, B: np.ndarray):
    """The rod's poses from its pins A, B [m]: a point 60 mm along AB and 20 mm across it,
    the part's line 17 deg from AB; and the search's bounds for a slider-crank's motion."""
    w = (B - A) / np.linalg.norm(B - A, axis=1)[:, None]
    places = A + 0.06 * w + 0.02 * np.stack((-w[:, 1], w[:, 0]), -1)
    angles = np.arctan2(w[:, 1], w[:, 0]) + math.radians(17.0)
    lower = np.array([-0.06, -0.06, math.radians(-30), -0.1, 0.01, 0.04, -0.15, -0.15])
    upper = np.array([0.06, 0.06, math.radians(30), 0.1, 0.08, 0.2, 0.15, 0.15])
    return places, angles, lower, upper

def test_function_synthesis_recovers_the_bundled_slider_crank(tmp_path):
    # Six pairs (crank turn, piston travel along x) from the engine's B; the search varies
    # crank, rod, offset and the first crank angle, and meets the travels within 1e-8 of
    # the linkage's size; the engine sweeping the written linkage moves its block as asked.
    A, B = _engine_pins(tmp_path, CRANK[:6])
    pairs = np.stack((np.radians(CRANK[:6] - CRANK[0]), B[:, 0] - B[0, 0]), -1)
    spec = SynthesisSpec(Path("test.toml"), "test", "function", "slider-crank", pairs, None,
                         np.array([0.01, 0.04, -0.1]), np.array([0.1, 0.3, 0.1]), seed=1, population=15,
                         generations=400, keep=1)
    best = synthesise(spec).linkages[0]
    assert best.meets(1e-8)
    _, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    check = engine_check(scene, best, pairs)
    assert check.errors.max() <= 1e-8 * best.size


def test_the_slider_cranks_folds_are_where_the_rod_is_square_to_the_slide():
    # A crank that cannot turn fully (crank 60 + offset 20 > rod 50 mm; slide along x at
    # y = 20 mm): the rod reaches the slide while |A_y - 20 mm| <= 50 mm, A_y = 60 sin(theta),
    # so the folds are at sin(theta) = (20 +- 50) / 60 (the + one beyond reach): theta =
    # asin(-0.5) = -30 deg and 180 + 30 = 210 deg. Between them (210 to 330 deg) the rod
    # cannot reach; just outside it does, nearly square to the slide (its x within
    # rod * sqrt(2 * 60 mm * cos(30 deg) * 1e-8 rad / 50 mm) ~ 7e-6 m of zero).
    z = np.array([[0.0, 0.0, 0.0, 0.02, 0.06, 0.05, 0.0, 0.0]])
    angles, _ = folds(z)
    found = np.sort(np.mod(np.degrees(angles[0][np.isfinite(angles[0])]), 360.0))
    assert np.allclose(found, [210.0, 330.0], atol=rounding(360.0))  # acos/asin rounding only
    tiny = 1e-8  # rad
    outside = np.radians(found) + np.array([-tiny, tiny])
    inside = np.radians(found) + np.array([tiny, -tiny])
    assert not pose(z, np.array([1.0]), inside[None]).closes.any()
    for s in (1.0, -1.0):  # both assemblies meet at the fold
        p = pose(z, np.array([s]), outside[None])
        rod = p.B[0] - p.A[0]
        assert p.closes.all() and np.all(np.abs(rod[:, 0]) < 1e-5) and np.allclose(np.abs(rod[:, 1]), 0.05, atol=1e-9)


def test_motion_synthesis_recovers_the_bundled_slider_crank(tmp_path):
    # Seven poses of the bundled rod: the place of its point 60 mm along A -> B and 20 mm to
    # its left, and a part's angle 17 deg from the rod's line, from the engine's A and B.
    # The linkage hidden, the search (the rod's angle offset gamma searched too) meets the
    # places within 1e-8 of the linkage's size and the angles within 1e-8 rad; the engine,
    # sweeping the written linkage, reports the rod's point and angle as closely.
    crank = CRANK[:7]
    A, B = _engine_pins(tmp_path, crank)
    places, angles, lower, upper = _rod_poses(A, B)
    spec = SynthesisSpec(Path("test.toml"), "test", "motion", "slider-crank", places, None, lower, upper,
                         seed=1, population=15, generations=400, keep=1, angles=angles)
    best = synthesise(spec).linkages[0]
    assert best.topology == "slider-crank" and best.task == "motion" and best.meets(1e-8)
    np.testing.assert_allclose(best.z[3:6], [0.05, 0.04, 0.13], atol=1e-8 * 0.13)  # offset, crank, rod: the hidden
    _, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    check = engine_check(scene, best, places, angles)
    assert check.errors.max() <= 1e-8 * best.size and check.angle_errors.max() <= 1e-8


def test_the_slider_point_of_three_poses_is_on_the_collinear_points_circle(tmp_path):
    # Sandor & Erdman's / Norton's three-position synthesis of the slider dyad: the rod points
    # whose three positions are collinear lie on one circle of the rod's frame. Three poses
    # of the bundled rod from the engine (the rod's point 60 mm along A -> B and 20 mm to its
    # left, the part 17 deg from A -> B): the block's pin B (on the slide y = 50 mm) is on it,
    # to rounding (1e-12 m: the poses are the engine's, Newton-converged to ~1e-15 m); and
    # the construction with the rod's own A and B gives the bundled linkage back: O2 at the
    # circumcentre of A's positions (0, 0), slide along x at 50 mm, crank 40, rod 130 mm.
    from pinmech.design.synthesis.slider_three_poses import slider_circle, slider_crank_row

    A, B = _engine_pins(tmp_path, np.array([20.0, 80.0, 140.0]))
    w = (B - A) / np.linalg.norm(B - A, axis=1)[:, None]
    n = np.stack((-w[:, 1], w[:, 0]), -1)
    places = A + 0.06 * w + 0.02 * n
    angles = np.arctan2(w[:, 1], w[:, 0]) + math.radians(17.0)
    frame = np.stack((np.cos(angles), np.sin(angles)), -1)  # the part's x axis at each pose

    def local(X: np.ndarray) -> np.ndarray:  # the rod frame's coordinates of X at the first pose
        r = X[0] - places[0]
        return np.array([r @ frame[0], frame[0, 0] * r[1] - frame[0, 1] * r[0]])

    centre, radius = slider_circle(places, angles)
    np.testing.assert_allclose(np.linalg.norm(local(B) - centre), radius, atol=rounding(0.2))
    row = slider_crank_row(places, angles, local(A), local(B))
    np.testing.assert_allclose(row[:8], [0, 0, 0, 0.05, 0.04, 0.13, 0.06, 0.02], atol=rounding(0.2))
    np.testing.assert_allclose(row[8], math.radians(17.0), atol=rounding(np.pi))


def test_every_three_pose_construction_carries_the_rod_through_the_poses():
    # Each slider-crank of the three-pose construction (crank pivots O2 on a grid, slider points
    # around the circle; those meeting the poses on two assemblies left out) carries its rod
    # point through the three places at the poses' angles: its closed form (design/synthesis/
    # slider.pose, on its assembly, at the crank's angles to A's three positions) to rounding.
    # The closed form takes B along the slide as sqrt(l^2 - h^2) (h: A's height over the slide),
    # whose rounding l^2 eps the root amplifies by kappa = l / sqrt(l^2 - h^2): near a fold (the
    # rod square to the slide, kappa up to 2e4 on this grid) B and the rod's angle carry kappa eps.
    from pinmech.design.synthesis.slider_three_poses import slider_crank_rows

    places = np.array([[0.09, 0.05], [0.082, 0.059], [0.065, 0.064]])
    angles = np.radians([33.0, 25.5, 21.7])
    rows = slider_crank_rows(places, angles, np.array([-0.1, -0.1]), np.array([0.1, 0.1]), 0.3)
    assert len(rows) > 100
    for row in rows:
        z, gamma, s = row[:8], row[8], row[9]
        e = np.stack((np.cos(angles - gamma), np.sin(angles - gamma)), -1)  # the rod A -> B at each pose
        A = places - z[6] * e - z[7] * np.stack((-e[:, 1], e[:, 0]), -1)
        theta = np.arctan2(A[:, 1] - z[1], A[:, 0] - z[0])
        p = pose(z[None], np.array([s]), theta[None])
        h = z[4] * np.sin(theta - z[2]) - z[3]
        kappa = z[5] / np.sqrt(z[5] ** 2 - h**2)  # the fold's amplification of rounding [-]
        size = np.abs(z[:8]).max()  # [m]
        np.testing.assert_allclose(np.linalg.norm(A - z[:2], axis=1), z[4], atol=rounding(size))
        np.testing.assert_allclose(p.P[0], places, atol=rounding(size, kappa))
        rod = p.B[0] - p.A[0]
        turn = np.arctan2(rod[:, 1], rod[:, 0]) + gamma - angles
        np.testing.assert_allclose(np.mod(turn + math.pi, 2 * math.pi) - math.pi, 0.0, atol=rounding(1.0, kappa))


def test_three_pose_motion_synthesis_meets_the_poses(tmp_path):
    # Three poses of the bundled rod (engine): the construction's slider-cranks within the
    # bounds join the search's starts (tested exact above), and the search (10 generations
    # at most) returns one that meets the poses within 1e-8 of its size and 1e-8 rad, free
    # of defects, the engine sweeping it agreeing. (Three poses leave the slider-crank three
    # free parameters: differential evolution alone finds one as well.)
    from pinmech.design.synthesis.tasks import classical_rows

    A, B = _engine_pins(tmp_path, np.array([20.0, 80.0, 140.0]))
    places, angles, lower, upper = _rod_poses(A, B)
    spec = SynthesisSpec(Path("test.toml"), "test", "motion", "slider-crank", places, None, lower, upper,
                         seed=1, population=5, generations=10, keep=1, angles=angles)
    starts = classical_rows(spec)
    assert len(starts) >= 5 and np.all((starts[:, :8] >= lower) & (starts[:, :8] <= upper))
    best = synthesise(spec).linkages[0]
    assert best.meets(1e-8)
    _, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    check = engine_check(scene, best, places, angles)
    assert check.errors.max() <= 1e-8 * best.size and check.angle_errors.max() <= 1e-8
