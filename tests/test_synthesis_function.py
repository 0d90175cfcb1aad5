"""Four-bar function generation: Chebyshev's spacing against its published values,
Freudenstein's three-point solution against the bundled four-bar solved by the engine,
and the synthesis recovering that four-bar from crank-rocker pairs."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pinmech.design.synthesis.freudenstein import chebyshev_spacing, freudenstein_k, link_lengths
from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.linkage import engine_check, write_linkage
from pinmech.design.synthesis.search import synthesise

ROOT = Path(__file__).resolve().parents[1]


def _engine_angles(crank_deg: np.ndarray) -> np.ndarray:
    """The bundled drawn four-bar's rocker angle [rad] (O4 -> B from x) solved by the engine
    at these crank angles (the scene starts at 60 deg; continuation, one way)."""
    from pinmech.io.scene import Scene
    from pinmech.io.sweep import Sweep

    sweep = Sweep.from_scene(Scene.load(ROOT / "models/scenes/four_bar_drawn.toml"))
    wanted = np.radians(crank_deg)
    dense = np.unique(np.concatenate((np.radians(np.arange(60.0, 181.0, 1.0)), wanted)))
    rows = {round(p.value, 12): p.motion.links["rocker"].angle for p in sweep.poses(dense)}
    return np.array([rows[round(w, 12)] for w in wanted])


def test_chebyshev_spacing_is_the_published_one():
    # Norton, Design of Machinery, Chebyshev spacing of 3 precision points over 1 <= x <= 2:
    # x = 1.067, 1.500, 1.933 (printed to 3 decimals: 5e-4 holds).
    assert np.allclose(chebyshev_spacing(1.0, 2.0, 3), [1.067, 1.5, 1.933], atol=5e-4)


def test_freudenstein_three_points_give_the_bundled_four_bar():
    # Three (crank, rocker) angle pairs of the bundled four-bar (ground 100, crank 40,
    # coupler 120, rocker 80 mm), solved by the engine (Newton on its URDF): the linear
    # 3x3 solve gives K1 = d/a = 2.5, K2 = d/c = 1.25, K3 = (a^2 - b^2 + c^2 + d^2)/(2ac)
    # = 0.5625, and the lengths back (to the engine's closure tolerance, 1e-9).
    crank = np.array([70.0, 110.0, 160.0])
    k = freudenstein_k(np.radians(crank), _engine_angles(crank))
    assert np.allclose(k, [2.5, 1.25, 0.5625], atol=1e-9)
    assert np.allclose(link_lengths(k, 0.1), [0.04, 0.12, 0.08], atol=1e-10)


def test_function_synthesis_recovers_the_bundled_four_bar(tmp_path):
    # Six pairs (crank turn, rocker turn) of the bundled four-bar, from the engine; the
    # synthesis (ground 100 mm) meets them within 1e-8 rad without defects, and the engine
    # sweeping the written linkage gives the same rocker angles within 1e-8 rad.
    crank = np.array([70.0, 85.0, 100.0, 120.0, 140.0, 170.0])
    phi = _engine_angles(crank)
    pairs = np.column_stack((np.radians(crank - crank[0]), phi - phi[0]))
    spec = SynthesisSpec(Path("test.toml"), "test", "function", "four-bar", pairs, None,
                         np.array([0.02, 0.02, 0.02]), np.array([0.3, 0.3, 0.3]), ground=0.1,
                         seed=1, population=15, generations=200, keep=1)
    best = synthesise(spec).linkages[0]
    assert best.meets(1e-8)
    _, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    assert engine_check(scene, best, pairs).errors.max() < 1e-8
