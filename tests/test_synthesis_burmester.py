"""Burmester's four-pose construction: the centre-point curve of four poses of the bundled
four-bar's coupler (solved by the engine), checked against the four-pose condition in
plain vector geometry, and a four-bar made of two of its dyads swept by the engine."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinmech.design.synthesis.burmester import dyads
from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.fourbar import pose
from pinmech.design.synthesis.linkage import engine_check, write_linkage
from pinmech.design.synthesis.poses import evaluate_poses, refined_poses
from pinmech.design.synthesis.tasks import classical_rows
from tests._engine_poses import engine_poses

ROOT = Path(__file__).resolve().parents[1]
CRANK = np.array([65.0, 125.0, 185.0, 245.0])  # deg: four poses of the hidden crank-rocker
WIDE_LOWER = np.array([-0.5, -0.5, -0.5, -0.5, 0.002, 0.002, 0.002, -0.5, -0.5])
WIDE_UPPER = np.array([0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5])


def _rotate(v: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _circle_through(p1: np.ndarray, p2: np.ndarray, p3: np.ndarray) -> np.ndarray:
    """The centre of the circle through three points: the perpendicular bisectors meet,
    2 (p_k - p_1) . c = |p_k|^2 - |p_1|^2, k = 2, 3."""
    A = 2 * np.array([p2 - p1, p3 - p1])
    b = np.array([p2 @ p2 - p1 @ p1, p3 @ p3 - p1 @ p1])
    return np.linalg.solve(A, b)


def test_centre_points_see_their_circle_point_on_one_circle():
    # The four-pose condition in vector form: a moving point C (given at the first pose) is
    # carried to C_j = P_j + R(alpha_j - alpha_1)(C - P_1); (M, C) is a Burmester dyad when
    # the four C_j are at one distance from M. Rounding grows with the dyad's radius, so
    # the spread is bounded by 1e-9 of the larger of that radius and the poses' size.
    places, angles = engine_poses(CRANK)
    M, C = dyads(places, angles)
    assert len(M) >= 40  # the curve has points for most of the 72 turns beta_2
    size = float(np.max(np.linalg.norm(places - places[0], axis=1)))
    for m, c in zip(M, C):
        moved = [places[j] + _rotate(c - places[0], angles[j] - angles[0]) for j in range(4)]
        radii = np.array([np.linalg.norm(cj - m) for cj in moved])
        assert np.ptp(radii) <= 1e-9 * max(size, radii.max())


def test_centre_points_lie_on_the_inverse_motions_circle_point_curve():
    # The same curve seen the other way (Burmester's inversion): a ground point M, carried
    # back into the first pose's frame from each pose, m_j = P_1 + R(alpha_1 - alpha_j)(M - P_j),
    # gives four points on one circle. The hidden linkage's ground pivots O2 (0, 0) and O4
    # (0.1, 0) must pass this check (they are centre points), and every computed M too.
    places, angles = engine_poses(CRANK)

    def spread(m: np.ndarray) -> float:
        back = [places[0] + _rotate(m - places[j], angles[0] - angles[j]) for j in range(4)]
        centre = _circle_through(*back[:3])
        return abs(np.linalg.norm(back[3] - centre) - np.linalg.norm(back[0] - centre)) / max(
            np.linalg.norm(back[0] - centre), 0.05)

    assert spread(np.array([0.0, 0.0])) < 1e-9 and spread(np.array([0.1, 0.0])) < 1e-9
    assert spread(np.array([0.03, 0.02])) > 1e-3  # a point off the curve fails it
    M, _ = dyads(places, angles)
    assert max(spread(m) for m in M) < 1e-9


def test_a_burmester_dyad_pair_carries_the_coupler_through_the_four_poses(tmp_path):
    # Two dyads of the curve make a four-bar; the best pair free of defects (branch,
    # circuit, order, as the search checks) meets the four poses as it stands: its crank
    # pin, carried rigidly with the coupler, gives the crank angle at each pose, where the
    # closed-form position meets the pose to 1e-9 of the poses' size and 1e-9 rad. Refined
    # and written (four poses leave a two-parameter family: the refinement may slide along
    # it), the engine sweeping the written linkage meets the poses to 1e-8 of the
    # linkage's size and 1e-8 rad (the engine's Newton tolerance is far below).
    places, angles = engine_poses(CRANK)
    spec = SynthesisSpec(Path("test.toml"), "test", "motion", "four-bar", places, None, WIDE_LOWER, WIDE_UPPER,
                         seed=1, population=15, generations=1, keep=1, angles=angles)
    rows = classical_rows(spec)
    assert len(rows) > 100
    size = float(np.max(np.linalg.norm(places - places[0], axis=1)))
    best = None
    for s in (1.0, -1.0):
        values = evaluate_poses(spec, s, rows).values
        k = int(np.argmin(values))
        if best is None or values[k] < best[0]:
            best = (values[k], s, rows[k])
    value, s, row = best
    assert value < 1e-6  # sampled crank angles: near, not at, the poses
    lk = refined_poses(spec, s, row)
    assert lk is not None and lk.meets(1e-8)
    z, gamma = row[:9], row[9]
    pin = places[0] - _rotate(z[7:9], angles[0] - gamma)  # A at the first pose
    pins = [places[j] + _rotate(pin - places[0], angles[j] - angles[0]) for j in range(4)]
    theta = np.array([[math.atan2(a[1] - z[1], a[0] - z[0]) for a in pins]])
    exact = pose(z[None], np.array([s]), theta)
    turn = np.arctan2(exact.B[0, :, 1] - exact.A[0, :, 1], exact.B[0, :, 0] - exact.A[0, :, 0]) + gamma - angles
    assert np.linalg.norm(exact.P[0] - places, axis=1).max() <= 1e-9 * size
    assert np.abs(np.mod(turn + math.pi, 2 * math.pi) - math.pi).max() <= 1e-9
    _, scene = write_linkage(lk, tmp_path / "burmester", "burmester", "test.toml")
    check = engine_check(scene, lk, places, angles)
    assert check.errors.max() <= 1e-8 * lk.size and check.angle_errors.max() <= 1e-8
