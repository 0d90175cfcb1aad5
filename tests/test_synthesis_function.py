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


def _freudenstein_rocker(a: float, b: float, c: float, d: float, theta2: np.ndarray, open_: bool = True) -> np.ndarray:
    """The rocker's absolute angle theta4 [rad] at crank angles theta2, both from the ground
    line O2 -> O4: Freudenstein's closed form as Norton writes it (Design of Machinery,
    eq. 4.10): theta4 = 2 atan2(-B -+ sqrt(B^2 - 4AC), 2A), with A = cos t2 - K1 - K2 cos t2
    + K3, B = -2 sin t2, C = K1 - (K2 + 1) cos t2 + K3 (the open circuit takes the minus)."""
    k1, k2, k3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    A = np.cos(theta2) - k1 - k2 * np.cos(theta2) + k3
    B = -2 * np.sin(theta2)
    C = k1 - (k2 + 1) * np.cos(theta2) + k3
    root = np.sqrt(B * B - 4 * A * C)
    return 2 * np.arctan2(-B - root if open_ else -B + root, 2 * A)


def test_function_synthesis_in_freudensteins_absolute_angles_recovers_the_four_bar(tmp_path):
    # Freudenstein's setting: the pairs are the crank's and the rocker's absolute angles
    # from the ground line (theta2 = 40 .. 120 deg, not from 0), written in the file with
    # pair_angles = "absolute". Five exact pairs of the crank-rocker 40/120/80 on ground
    # 100 mm fix K1, K2, K3 (three would), so the lengths come back to the refinement's
    # rounding (1e-10 of the size) and the rocker's angles within 1e-9 rad.
    from pinmech.design.synthesis.file import load_synthesis

    theta2 = np.radians([40.0, 60.0, 80.0, 100.0, 120.0])
    theta4 = _freudenstein_rocker(0.04, 0.12, 0.08, 0.1, theta2)
    pairs = ", ".join(f'["{float(np.degrees(t))!r} deg", "{float(np.degrees(p))!r} deg"]' for t, p in zip(theta2, theta4))
    path = tmp_path / "absolute.toml"
    path.write_text(f'''title = "Freudenstein"
task = "function"
topology = "four-bar"
ground = "100 mm"
pair_angles = "absolute"
seed = 1
population = 10
generations = 50
keep = 1
pairs = [{pairs}]
[bounds]
crank = ["20 mm", "200 mm"]
coupler = ["20 mm", "200 mm"]
rocker = ["20 mm", "200 mm"]
''')
    spec = load_synthesis(path)
    # the file's degrees (shortest repr) back to radians: within an ulp or two of the angles
    assert np.allclose(spec.start, (theta2[0], theta4[0]), rtol=0, atol=4e-16)
    best = synthesise(spec).linkages[0]
    assert np.allclose(best.z[4:7], [0.04, 0.12, 0.08], rtol=0, atol=1e-10)
    assert best.errors.max() <= 1e-9
    assert (best.theta[0], best.phi0) == spec.start  # the file's own start, not one the search moved
    _, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    assert engine_check(scene, best, spec.targets).errors.max() < 1e-9


def test_turns_stay_the_default_and_absolute_pairs_without_the_key_are_refused(tmp_path):
    import pytest

    from pinmech.design.synthesis.file import load_synthesis
    from pinmech.exceptions import SceneError

    path = tmp_path / "f.toml"
    body = '''task = "function"
ground = "100 mm"
pairs = [["40 deg", "80 deg"], ["60 deg", "90 deg"], ["80 deg", "100 deg"]]
[bounds]
crank = ["20 mm", "200 mm"]
coupler = ["20 mm", "200 mm"]
rocker = ["20 mm", "200 mm"]
'''
    path.write_text(body)
    with pytest.raises(SceneError, match='pair_angles = "absolute"'):
        load_synthesis(path)
    path.write_text('topology = "slider-crank"\npair_angles = "absolute"\n' + body.replace('ground = "100 mm"\n', "")
                    .replace("coupler", "rod").replace("rocker", "offset"))
    with pytest.raises(SceneError, match="for a four-bar's function"):
        load_synthesis(path)
