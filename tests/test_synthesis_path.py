"""Four-bar path generation (pinmech synth): the closed form and its exact Jacobian against
the law of cosines and central differences, recovery of the bundled four-bar from points
of its coupler curve solved by the engine, and the defects a synthesis must never return.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.fourbar import folds, point_jacobian, pose
from pinmech.design.synthesis.linkage import engine_check, write_linkage
from pinmech.design.synthesis.motion import CAUSES
from pinmech.design.synthesis.objective import evaluate_path as evaluate
from pinmech.design.synthesis.search import synthesise
from tests.tolerance import rounding

ROOT = Path(__file__).resolve().parents[1]
# The bounds of the bundled example: ground pivots in two 120 mm squares, links 10-200 mm.
LOWER = np.array([-0.06, -0.06, 0.04, -0.06, 0.01, 0.04, 0.02, -0.15, -0.15])
UPPER = np.array([0.06, 0.06, 0.16, 0.06, 0.08, 0.2, 0.16, 0.15, 0.15])


def _bundled() -> np.ndarray:
    """models/linkages/four_bar.toml as (O2, O4, crank, coupler, rocker, along, across):
    A = (40, 0) mm, B by the compass left of A -> O4, P = (100, 30) mm at the drawn pose."""
    A, O4, P = np.array([0.04, 0.0]), np.array([0.1, 0.0]), np.array([0.1, 0.03])
    d = O4 - A
    D = np.linalg.norm(d)
    a = (0.12**2 - 0.08**2 + D**2) / (2 * D)
    u = d / D
    B = A + a * u + math.sqrt(0.12**2 - a * a) * np.array([-u[1], u[0]])
    ex = (B - A) / 0.12
    ey = np.array([-ex[1], ex[0]])
    return np.array([0, 0, 0.1, 0, 0.04, 0.12, 0.08, (P - A) @ ex, (P - A) @ ey])


def _engine_points(crank_deg: np.ndarray) -> np.ndarray:
    """P of the bundled drawn four-bar solved by the engine at these crank angles [m]."""
    from pinmech.io.scene import Scene
    from pinmech.io.sweep import Sweep

    sweep = Sweep.from_scene(Scene.load(ROOT / "models/scenes/four_bar_drawn.toml"))
    wanted = np.radians(crank_deg)
    dense = np.radians(np.arange(60.0, 60.0 - 360.0, -1.0))  # from the scene's 60 deg, one way
    dense = np.unique(np.concatenate((dense, wanted)))[::-1]
    rows = {round(p.value, 12): p.motion.points["P"].position[:2] for p in sweep.poses(dense)}
    return np.array([rows[round(w, 12)] for w in wanted])


def _spec(targets, timing=None, **kw) -> SynthesisSpec:
    return SynthesisSpec(Path("test.toml"), "test", "path", "four-bar", np.asarray(targets), timing, LOWER, UPPER,
                         **kw)


def test_closed_form_keeps_the_link_lengths_and_the_drawn_point():
    # The drawn pose (crank at 0) puts P at (100, 30) mm, as the file draws it; at every
    # crank angle |AB| = coupler and |O4 B| = rocker (law of cosines' triangle), to rounding.
    z = _bundled()
    theta = np.linspace(-math.pi, math.pi, 73)[None]
    p = pose(z[None], np.array([1.0]), theta)
    assert np.allclose(pose(z[None], np.array([1.0]), np.zeros((1, 1))).P[0, 0], [0.1, 0.03], atol=rounding(0.2))
    assert np.allclose(np.linalg.norm(p.B - p.A, axis=-1), 0.12, atol=rounding(0.2))
    assert np.allclose(np.linalg.norm(p.B - z[2:4], axis=-1), 0.08, atol=rounding(0.2))
    assert p.closes.all()  # a crank-rocker: the crank turns fully


def test_point_jacobian_matches_central_differences():
    # Exact dP/dz and dP/dtheta (implicit-function theorem) against central differences,
    # step 1e-6 of the unit: truncation ~h^2 |P'''| ~ 1e-12 m, rounding ~1e-16/1e-6: 1e-9 holds.
    z = _bundled() + np.array([0.003, -0.002, 0.001, 0.004, 0.0, 0.0, 0.0, 0.0, 0.0])
    theta = np.linspace(0.2, 5.5, 7)
    _, dz, dt = point_jacobian(z, 1.0, theta)
    h = 1e-6
    for k in range(9):
        e = np.zeros(9)
        e[k] = h
        fd = (pose((z + e)[None], np.ones(1), theta[None]).P[0] - pose((z - e)[None], np.ones(1), theta[None]).P[0]) / (2 * h)
        assert np.abs(fd - dz[:, :, k]).max() < 1e-9, k
    fd = (pose(z[None], np.ones(1), (theta + h)[None]).P[0] - pose(z[None], np.ones(1), (theta - h)[None]).P[0]) / (2 * h)
    assert np.abs(fd - dt).max() < 1e-9


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_recovers_the_bundled_four_bar_from_ten_engine_points(tmp_path, seed):
    # Ten points of the bundled four-bar's coupler curve, solved by the engine (Newton on the
    # URDF the drawn linkage builds, not the closed form), the linkage hidden. The linkage
    # found meets them within 1e-8 of its size, and the engine, sweeping the written
    # linkage from the first target's pose, meets them within 1e-8 too: one assembly, one way.
    # On every seed of five: DE is a heuristic, and a run that settles in a local optimum
    # (seed 3 did, 1.3e-2 of the size off, before a settled run restarted) restarts with the
    # next seed of the stream. About 8 to 18 s a seed on the shared 2-core machine.
    crank = np.arange(40.0, -230.0, -30.0)  # the crank turning clockwise from 40 deg
    targets = _engine_points(crank)
    result = synthesise(_spec(targets, seed=seed, population=15, generations=400, keep=1))
    best = result.linkages[0]
    assert best.meets(1e-8)
    linkage, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    check = engine_check(scene, best, targets)
    assert check.errors.max() <= 1e-8 * best.size
    assert best.way == -1  # the crank turns as the targets were taken: clockwise


def _triple_rocker() -> tuple[np.ndarray, np.ndarray]:
    """A triple rocker (ground 100, crank 60, coupler 50, rocker 70 mm: s + l = 150 > p + q =
    120) and ten points of its coupler curve: five on the left assembly up to a fold, five
    on the right one after it. A defect-blind search meets them exactly with this linkage."""
    z = np.array([0, 0, 0.1, 0, 0.06, 0.05, 0.07, 0.03, 0.02])
    f, _ = folds(z[None])
    limit = float(np.nanmax(f[0][(f[0] > 0) & (f[0] < math.pi)]))  # the upper fold of the crank
    before = np.linspace(limit - 1.0, limit - 0.05, 5)
    after = np.linspace(limit - 0.05, limit - 1.0, 5)  # the crank back down, on the other assembly
    P1 = pose(z[None], np.array([1.0]), before[None]).P[0]
    P2 = pose(z[None], np.array([-1.0]), after[None]).P[0]
    return z, np.vstack((P1, P2))


def test_defective_linkage_is_never_an_answer(tmp_path):
    # The hidden linkage meets all ten targets only by passing its fold (a branch defect on
    # the bench). Scored on either assembly it does not meet them (the other five are not
    # on its curve there); the answers found are each checked by the engine's continuation
    # (one assembly, one way: a fold or an assembly change would raise); the candidates
    # rejected are counted by cause.
    z, targets = _triple_rocker()
    spec = _spec(targets, seed=1, population=10, generations=60, keep=2)
    for s in (1.0, -1.0):
        out = evaluate(spec, s, z[None])
        assert out.causes[0] or out.values[0] > 1e-4  # not met: a 1e-2 relative miss at least
    result = synthesise(spec)
    assert sum(result.rejected.values()) > 0 and set(result.rejected) <= set(CAUSES)
    for lk in result.linkages:
        _, scene = write_linkage(lk, tmp_path / f"found_{len(list(tmp_path.iterdir()))}", "defect", "test.toml")
        check = engine_check(scene, lk, targets)
        assert np.allclose(check.errors, lk.errors, atol=1e-9 * lk.size)  # the report is the engine's


def test_timing_recovery_is_the_same_on_one_and_two_dask_workers():
    # Prescribed crank turns (timing): the same seed gives the same linkage bit for bit on
    # LocalClusters of 1 and 2 worker processes (the population is split differently).
    pytest.importorskip("distributed")
    z = _bundled()
    turns = np.radians(np.arange(0.0, 300.0, 40.0))
    targets = pose(z[None], np.ones(1), (0.5 + turns)[None]).P[0]
    spec = _spec(targets, timing=turns, seed=4, population=8, generations=25, keep=1)
    one, two = synthesise(spec, workers=1), synthesise(spec, workers=2)
    assert one.evaluations == two.evaluations and one.rejected == two.rejected
    assert [lk.z.tolist() for lk in one.linkages] == [lk.z.tolist() for lk in two.linkages]
