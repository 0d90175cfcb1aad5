"""Six-bar synthesis on the engine (design/synthesis/sixbar.py): recovery of the bundled
Watt six-bar from points of a coupler point of its last dyad, a function of a Stephenson,
a target set only a defective linkage meets, and the same linkage on 1 and 2 Dask workers.

References: the Watt's and Stephenson's positions in closed form, written here with numpy
apart from pinmech (two, then three successive circle intersections by the law of
cosines); the linkages found are also swept again by the engine from their written files.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from pinmech.design.synthesis.file import parse_synthesis
from pinmech.design.synthesis.search import synthesise
from pinmech.design.synthesis.tasks import evaluate
from pinmech.design.synthesis.sixbar_output import crank_values, write_linkage
from pinmech.exceptions import SceneError

ROOT = Path(__file__).resolve().parents[1]
SYNTHESIS = ROOT / "models" / "synthesis"
# models/linkages/watt.toml: O2 (0, 0), O4 (100, 0), O6 (190, 30) mm; crank 40, coupler
# 120, rocker O4 B 80, O4 C 60, B C 50, link5 C D 90, link6 O6 D 70 mm; and the coupler point
# P on link5 at CP = 50 mm from C, DP = 60 mm from D, left of C -> D.
WATT = {"link5": 0.09, "link6": 0.07, "CP": 0.05, "DP": 0.06}


def _meet(a: np.ndarray, b: np.ndarray, ra: float, rb: float, side: float = 1.0) -> np.ndarray:
    """The meeting point of the circles (a, ra), (b, rb), left (side +1) or right of a -> b
    (law of cosines); NaN where they do not meet."""
    d = np.linalg.norm(b - a, axis=-1)[..., None]
    along = (d * d + ra * ra - rb * rb) / (2 * d)
    u = (b - a) / d
    with np.errstate(invalid="ignore"):
        h = np.sqrt(ra * ra - along * along)
    return a + along * u + side * h * np.stack((-u[..., 1], u[..., 0]), -1)


def watt_pose(theta: np.ndarray, link5: float, link6: float, CP: float, DP: float) -> tuple[np.ndarray, np.ndarray]:
    """P [m] (n, 2) and link5's angle atan2(D - C) [rad] (n,) of models/linkages/watt.toml's
    first loop and O6 with this last dyad, at crank angles theta [rad]."""
    theta = np.asarray(theta, dtype=float)
    O4, O6 = np.broadcast_to([0.1, 0.0], (*theta.shape, 2)), np.broadcast_to([0.19, 0.03], (*theta.shape, 2))
    A = 0.04 * np.stack((np.cos(theta), np.sin(theta)), -1)
    B = _meet(A, O4, 0.12, 0.08)
    C = _meet(O4, B, 0.06, 0.05, -1.0)
    D = _meet(C, O6, link5, link6)
    return _meet(C, D, CP, DP), np.arctan2(D[..., 1] - C[..., 1], D[..., 0] - C[..., 0])


def watt_point(theta: np.ndarray, link5: float, link6: float, CP: float, DP: float) -> np.ndarray:
    """P of the Watt six-bar at crank angles theta [rad] [m], (n, 2)."""
    return watt_pose(theta, link5, link6, CP, DP)[0]


def _watt_spec(targets: np.ndarray, turns: np.ndarray, bounds: dict, **kw):
    raw = {"task": "path", "topology": "watt", "scene": "../scenes/watt_params.toml", "point": "P",
           "targets": [[f"{float(x)!r} m", f"{float(y)!r} m"] for x, y in targets],
           "timing": [f"{float(t)!r} rad" for t in turns],
           "bounds": {k: [f"{float(lo)!r} m", f"{float(hi)!r} m"] for k, (lo, hi) in bounds.items()}, **kw}
    return parse_synthesis(raw, SYNTHESIS / "inline.toml")


def _engine_sweep(scene: Path, values: np.ndarray, name: str) -> np.ndarray:
    """The written scene swept by the engine (pinmech sweep's Sweep) from its drawn pose
    through the crank values (increasing) [rad], 1 deg steps: the point's x, y [m]."""
    from pinmech.io.scene import Scene
    from pinmech.io.sweep import Sweep

    sweep = Sweep.from_scene(Scene.load(scene))
    dense = np.unique(np.concatenate((np.arange(sweep.start, values.max(), math.radians(1.0)), values)))
    rows = {round(p.value, 12): p.motion.points[name].position[:2] for p in sweep.poses(dense)}
    return np.array([rows[round(v, 12)] for v in values])


def test_recovers_the_bundled_watt_from_ten_points_of_its_last_dyad(tmp_path):
    # Ten points of P (on link5) at crank angles 60..330 deg, from the closed form, with their
    # timing (the crank's turns from the first); the four params of the last dyad and P
    # hidden in a box of +-3 mm about them (the first loop and O6 as drawn). The linkage
    # found meets the closed form within 1e-8 of its size (190 mm), its written files swept
    # by the engine from their drawn pose meet them within 1e-8 of its size too, and its
    # params are the hidden ones (within 1e-6 m: the targets fix them). Run time 6 s here
    # (DE stops once a refined candidate meets the targets within 1e-10 of its size).
    theta = np.radians(60.0 + 30.0 * np.arange(10))
    targets = watt_point(theta, **WATT)
    bounds = {k: (v - 0.003, v + 0.003) for k, v in WATT.items()}
    spec = _watt_spec(targets, theta - theta[0], bounds, seed=1, population=6, generations=30, keep=1,
                      constraints={"transmission": "20 deg", "pins": ["B", "D"]})
    result = synthesise(spec)
    best = result.linkages[0]
    assert best.meets(1e-8)
    np.testing.assert_allclose(best.z, list(WATT.values()), atol=1e-6)
    found = watt_point(best.theta, *best.z)
    assert np.max(np.linalg.norm(found - targets, axis=1)) <= 1e-8 * best.size
    _, scene = write_linkage(spec, best, tmp_path / "watt")
    swept = _engine_sweep(scene, crank_values(best, 0.0), "P")
    assert np.max(np.linalg.norm(swept - targets, axis=1)) <= 1e-8 * best.size


def stephenson_point(theta: np.ndarray, link5: float, link6: float, CP: float, DP: float) -> np.ndarray:
    """P on link5 of models/linkages/stephenson_params.toml's four-bar, C (70, 70 mm from A,
    B) and O6 (165, 105) mm, at crank angles theta [rad] [m], (n, 2)."""
    theta = np.asarray(theta, dtype=float)
    O4, O6 = np.broadcast_to([0.1, 0.0], (*theta.shape, 2)), np.broadcast_to([0.165, 0.105], (*theta.shape, 2))
    A = 0.04 * np.stack((np.cos(theta), np.sin(theta)), -1)
    B = _meet(A, O4, 0.12, 0.08)
    C = _meet(A, B, 0.07, 0.07)
    D = _meet(C, O6, link5, link6)
    return _meet(C, D, CP, DP)


def test_recovers_a_stephenson_from_points_without_timing():
    # A point of the Stephenson's link5 draws a closed loop: ten points of it (crank 20..290
    # deg) in order, without timing; each target's crank value is the nearest point of the
    # candidate's curve, then refined. The four params of link5, link6 and P hidden in a
    # box of +-2 mm: the linkage found meets the closed form within 1e-8 of its size (165
    # mm), the crank values it reports are the hidden ones (within 1e-6 rad).
    hidden = {"link5": 0.12, "link6": 0.09, "CP": 0.06, "DP": 0.07}
    theta = np.radians(20.0 + 30.0 * np.arange(10))
    targets = stephenson_point(theta, **hidden)
    raw = {"task": "path", "topology": "stephenson", "scene": "../scenes/stephenson_params.toml", "point": "P",
           "targets": [[f"{float(x)!r} m", f"{float(y)!r} m"] for x, y in targets], "seed": 1, "population": 6,
           "generations": 30, "keep": 1,
           "bounds": {k: [f"{v - 0.002!r} m", f"{v + 0.002!r} m"] for k, v in hidden.items()}}
    best = synthesise(parse_synthesis(raw, SYNTHESIS / "inline.toml")).linkages[0]
    assert best.meets(1e-8)
    found = stephenson_point(best.theta, *best.z)
    assert np.max(np.linalg.norm(found - targets, axis=1)) <= 1e-8 * best.size
    np.testing.assert_allclose(np.mod(best.theta, 2 * math.pi), theta, atol=1e-6)


def test_targets_met_only_across_a_fold_of_the_second_loop_give_no_answer():
    # link5 = 50, link6 = 40 mm: |C O6| reaches 94.9 mm near crank 231 deg, beyond their
    # 90 mm sum, so the second loop folds and does not close there on any assembly. Points
    # of P before the gap (60..150 deg) and after it (300, 330 deg) with their timing are met
    # exactly by this linkage only by a jump across the gap (a circuit defect). In a box of
    # +-2 mm (every sum below 94.9 mm) no candidate turns its crank through: no answer, and
    # every rejected candidate counted by cause.
    hidden = {"link5": 0.05, "link6": 0.04, "CP": 0.05, "DP": 0.06}
    theta = np.radians([60.0, 90.0, 120.0, 150.0, 300.0, 330.0])
    targets = watt_point(theta, **hidden)
    assert np.all(np.isfinite(targets))  # every target is on the hidden linkage's curve
    assert np.any(np.isnan(watt_point(np.radians(np.arange(150.0, 300.0)), **hidden)))  # the gap
    bounds = {k: (v - 0.002, v + 0.002) for k, v in hidden.items()}
    spec = _watt_spec(targets, theta - theta[0], bounds, seed=2, population=5, generations=4, keep=1)
    hidden_row = np.array([*hidden.values(), theta[0]])
    assert evaluate(spec, 1.0, hidden_row[None]).causes == ["fold within the turn"]  # the hidden one too
    result = synthesise(spec)
    assert result.linkages == []
    assert result.rejected["fold within the turn"] > 0
    assert sum(result.rejected.values()) == result.evaluations


def test_a_crank_range_given_by_the_template_scene_is_followed_instead_of_a_turn(tmp_path):
    # The same folding second loop (link5 50, link6 40 mm), its template scene sweeping the
    # crank from 0 to 150 deg only, where it closes: the candidates are followed over that
    # range, and the hidden linkage is found from seven timed points of it within 1e-8 of
    # its size (the closed form).
    scene = tmp_path / "watt_range.toml"
    scene.write_text(f'linkage = "{(ROOT / "models/linkages/watt_params.toml").as_posix()}"\n'
                     '[drivers.O2]\nangle = "0 deg"\n[sweep]\nfrom = "0 deg"\nto = "150 deg"\n', encoding="utf-8")
    hidden = {"link5": 0.05, "link6": 0.04, "CP": 0.05, "DP": 0.06}
    theta = np.radians(20.0 * np.arange(1, 8))
    targets = watt_point(theta, **hidden)
    bounds = {k: (v - 0.002, v + 0.002) for k, v in hidden.items()}
    spec = _watt_spec(targets, theta - theta[0], bounds, seed=1, population=6, generations=30, keep=1,
                      scene=str(scene))
    best = synthesise(spec).linkages[0]
    assert best.meets(1e-8)
    found = watt_point(best.theta, *best.z)
    assert np.max(np.linalg.norm(found - targets, axis=1)) <= 1e-8 * best.size


def test_stephenson_function_pairs_of_a_closed_form_are_met(tmp_path):
    # The bundled Stephenson function file's pairs come from the closed form (A, B, C on the
    # coupler, D): its hidden dyad (link5 120, link6 90 mm, O6 (160, 110) mm, crank from 30
    # deg) meets them within the pairs' rounding (1e-6 deg); a small search in a box of
    # +-1 mm about it finds a linkage meeting them within 1e-6 deg too.
    from pinmech.design.synthesis.file import load_synthesis

    spec = load_synthesis(SYNTHESIS / "stephenson_function.toml")
    theta = math.radians(30.0) + spec.targets[:, 0]
    O4, O6 = np.array([0.1, 0.0]), np.array([0.16, 0.11])
    A = 0.04 * np.stack((np.cos(theta), np.sin(theta)), -1)
    B = _meet(A, np.broadcast_to(O4, A.shape), 0.12, 0.08)
    C = _meet(A, B, 0.07, 0.07)
    D = _meet(C, np.broadcast_to(O6, A.shape), 0.12, 0.09)
    phi = np.unwrap(np.arctan2(D[:, 1] - O6[1], D[:, 0] - O6[0]))
    np.testing.assert_allclose(phi - phi[0], spec.targets[:, 1], atol=math.radians(1e-6))
    hidden = np.array([0.12, 0.09, 0.16, 0.11])
    small = dataclasses.replace(spec, lower=hidden - 0.001, upper=hidden + 0.001, population=5, generations=10,
                                keep=1)
    best = synthesise(small).linkages[0]
    assert np.max(best.errors) <= math.radians(1e-6)


def test_same_seed_gives_the_same_six_bar_on_one_and_two_dask_workers():
    # The population split differently over 1 and 2 worker processes, each drawing its own
    # template: the same candidates, causes and linkage bit for bit.
    pytest.importorskip("distributed")
    theta = np.radians(60.0 + 30.0 * np.arange(6))
    targets = watt_point(theta, **WATT)
    bounds = {k: (v - 0.003, v + 0.003) for k, v in WATT.items()}
    spec = _watt_spec(targets, theta - theta[0], bounds, seed=3, population=5, generations=3, keep=1)
    one, two = synthesise(spec, workers=1), synthesise(spec, workers=2)
    assert one.evaluations == two.evaluations and one.rejected == two.rejected
    assert one.linkages and [lk.z.tolist() for lk in one.linkages] == [lk.z.tolist() for lk in two.linkages]


@pytest.mark.parametrize("change, key", [
    ({"scene": "../scenes/four_bar.toml"}, "scene"),
    ({"point": "Q"}, "point"),
    ({"bounds": {"nope": ["1 mm", "2 mm"]}}, "bounds"),
    ({"bounds": {"link5": ["90 mm", "80 mm"]}}, "bounds.link5"),
    ({"constraints": {"transmission": "20 deg"}}, "constraints.transmission"),
    ({"constraints": {"pins": ["Z"]}}, "constraints.pins"),
    ({"constraints": {"grashof": "crank-rocker"}}, "constraints"),
    ({"task": "motion"}, "targets"),  # a motion takes poses
    ({"output": "link6"}, "output"),
])
def test_every_bad_key_of_a_six_bar_file_is_named(change, key):
    # One line naming the file and the key, whatever is wrong.
    raw = {"task": "path", "topology": "watt", "scene": "../scenes/watt_params.toml",
           "targets": [["150 mm", "80 mm"], ["150 mm", "90 mm"], ["140 mm", "100 mm"]],
           "bounds": {"link5": ["80 mm", "100 mm"]}, **change}
    with pytest.raises(SceneError) as err:
        parse_synthesis(raw, SYNTHESIS / "inline.toml")
    assert key in str(err.value) and "inline.toml" in str(err.value) and "\n" not in str(err.value)
