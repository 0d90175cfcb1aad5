"""Grid studies (pinmech/design/study/grid.py) against the four-bar's closed form.

A 1-D grid of the bundled four-bar's crank length a (coupler b = 120, rocker c = 80,
ground d = 100 mm) checked against two independent references:
- the rocker's swing (max - min of its angle over a turn) from the law of cosines
  (scripts/closed_form.py, `four_bar`, at the same crank angles, and at its extreme
  positions, where the crank and the coupler are in line);
- which grid points turn fully, from Grashof's condition for a crank: s + l <= p + q with
  the crank shortest. Every other point is counted as failed, with a cause, never dropped.
"""

from __future__ import annotations

from pathlib import Path

import closed_form
import numpy as np
import pytest

from pinmech.design.study.grid import cycle_range, failures
from pinmech.design.study.run import study
from pinmech.design.study.file import load_study, parse_study
from pinmech.design.study.report import grid_table, summary
from pinmech.exceptions import SceneError
from tests.tolerance import rounding

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
B, C, D = 0.120, 0.080, 0.100  # coupler, rocker, ground of models/four_bar.urdf [m]


def _crank_grid(start_mm: float, stop_mm: float, count: int, steps: int = 73, batch: int = 64) -> dict:
    return {"scene": "../scenes/four_bar.toml", "kind": "grid", "steps": steps, "batch": batch,
            "params": {"crank": {"joint": "A", "component": "x"}},
            "grid": {"crank": {"from": f"{start_mm} mm", "to": f"{stop_mm} mm", "count": count}},
            "outputs": {"links": ["rocker"]}}


@pytest.fixture(scope="module")
def crank_grid():
    """a = 11, 16, ..., 91 mm: no point on Grashof's boundary a = 60 mm (a change point)."""
    return study(parse_study(_crank_grid(11, 91, 17), STUDIES / "inline.toml"))


def test_grid_points_that_fail_are_those_grashof_says_cannot_turn(crank_grid):
    p, y, causes = crank_grid.variants
    a = p[:, 0]
    lengths = np.column_stack([a, np.full_like(a, B), np.full_like(a, C), np.full_like(a, D)])
    s, l = lengths.min(axis=1), lengths.max(axis=1)
    crank = (a == s) & (s + l <= lengths.sum(axis=1) - s - l)  # Grashof, crank shortest
    np.testing.assert_array_equal(np.array([not c for c in causes]), crank)
    assert sum(failures(list(causes)).values()) == int((~crank).sum()) == 7  # a = 61 .. 91 mm
    assert np.isnan(y[~crank]).all()  # failed points marked, kept in the table
    table = grid_table(crank_grid)
    assert len(table["point"]) == 17 and sum(bool(c) for c in table["cause"]) == 7
    assert summary(crank_grid)["failures"] == failures(list(causes))


def test_rocker_swing_matches_the_law_of_cosines_at_the_same_crank_angles(crank_grid):
    p, y, causes = crank_grid.variants
    lo, hi = cycle_range(y, crank_grid.kinds)
    theta2 = crank_grid.values  # the crank angle is the driver joint's value: A lies on its x axis
    for i, cause in enumerate(causes):
        if cause:
            continue
        theta4 = np.unwrap(closed_form.four_bar(theta2, 0.0, 0.0, p[i, 0], B, C, D, +1).theta4)
        # 1e-8 rad: the loops close to ~1e-10 m on 80 mm links, far below it; a wrong
        # assembly or length moves the swing by degrees.
        np.testing.assert_allclose(hi[i, 0] - lo[i, 0], np.ptp(theta4), rtol=0, atol=1e-8)


def test_rocker_swing_at_its_extreme_positions():
    """The rocker's extremes, with the crank and the coupler in line (|AO4| = b + a, b - a):
    gamma = angle at O4 between O4O2 and O4B, cos gamma = (c^2 + d^2 - e^2) / (2 c d)."""
    res = study(parse_study(_crank_grid(20, 50, 4, steps=1441), STUDIES / "inline.toml"))
    p, y, causes = res.variants
    lo, hi = cycle_range(y, res.kinds)
    a = p[:, 0]
    gamma = [np.arccos((C**2 + D**2 - e**2) / (2 * C * D)) for e in (B + a, B - a)]
    swing = np.abs(gamma[0] - gamma[1])
    # 1441 poses: 0.25 deg apart; the sampled max misses the true one by at most
    # max|d2 theta4/d theta2^2| (h/2)^2 / 2 < 2 * (2.2e-3)^2 / 2 ~ 5e-6 rad a side: 2e-5 rad.
    assert not any(causes)
    np.testing.assert_allclose(hi[:, 0] - lo[:, 0], swing, rtol=0, atol=2e-5)
    assert np.all(hi[:, 0] - lo[:, 0] <= swing + 1e-9)


def test_least_transmission_angle_matches_the_law_of_cosines(crank_grid):
    """Norton's mu (ABO4, acute form) is extreme where |AO4| is: with the crank along the
    ground (theta2 = 0, 180 deg, both among the 73 poses from 60 deg in 5 deg steps),
    |AO4| = d - a, d + a and cos mu = (b^2 + c^2 - |AO4|^2) / (2 b c). Each point's own
    lengths: a linkage left at the nominal's pins would give one value for all."""
    p, _, causes = crank_grid.variants
    mu = crank_grid.transmission
    ok = np.array([not c for c in causes])
    a = p[ok, 0]
    ends = [np.degrees(np.arccos((B**2 + C**2 - e**2) / (2 * B * C))) for e in (D - a, D + a)]
    least = np.minimum(np.minimum(ends[0], 180 - ends[0]), np.minimum(ends[1], 180 - ends[1]))
    # 1e-6 deg: the loops close to ~1e-10 m (~1e-7 deg on 80 mm links).
    np.testing.assert_allclose(np.degrees(mu[ok]), least, rtol=0, atol=1e-6)
    assert np.isnan(mu[~ok]).all()
    np.testing.assert_allclose(grid_table(crank_grid)["least acute transmission angle [deg]"][0], least[0], atol=1e-6)


def test_least_transmission_angle_over_a_ground_grid_uses_each_points_pivot():
    """As above over the ground length d (a = 40 mm): the transmission angle reads the
    ground pivot O4, so a linkage built once at the nominal would give d = 100 mm throughout."""
    raw = _crank_grid(85, 155, 8)
    raw["params"] = {"ground": {"joint": "O4", "component": "x"}}
    raw["grid"] = {"ground": {"from": "85 mm", "to": "155 mm", "count": 8}}
    res = study(parse_study(raw, STUDIES / "inline.toml"))
    p, _, causes = res.variants
    assert not any(causes)  # Grashof: 40 + max(120, d) <= 80 + min(120, d) for 80 <= d <= 160 mm
    a, d = 0.040, p[:, 0]
    ends = [np.degrees(np.arccos((B**2 + C**2 - e**2) / (2 * B * C))) for e in (d - a, d + a)]
    least = np.minimum(np.minimum(ends[0], 180 - ends[0]), np.minimum(ends[1], 180 - ends[1]))
    np.testing.assert_allclose(np.degrees(res.transmission), least, rtol=0, atol=1e-6)  # 1e-6 deg as above


def test_grid_results_do_not_depend_on_the_batching(crank_grid):
    other = study(parse_study(_crank_grid(11, 91, 17, batch=3), STUDIES / "inline.toml"))
    for x, z in zip(crank_grid.variants[:2], other.variants[:2]):
        np.testing.assert_array_equal(x, z)
    assert crank_grid.variants[2] == other.variants[2]
    np.testing.assert_array_equal(crank_grid.transmission, other.transmission)


def test_bundled_grid_study_parses():
    spec = load_study(STUDIES / "four_bar_grid.toml")
    assert spec.kind == "grid" and [a.name for a in spec.grid] == ["crank", "ground"]
    np.testing.assert_allclose(spec.grid[0].values[-1], 0.080, rtol=0, atol=rounding(0.080))  # 20 .. 80 mm


@pytest.mark.parametrize("change, key", [
    ({"grid": {"coupler": {"from": "1 mm", "to": "2 mm", "count": 2}}}, "grid.coupler"),
    ({"grid": {"crank": {"from": "50 mm", "to": "20 mm", "count": 3}}}, "grid.crank"),
    ({"grid": {"crank": {"from": "20 mm", "to": "50 mm"}}}, "grid.crank"),
    ({"grid": {"crank": {"from": "20 mm", "to": "50 mm", "count": 0}}}, "grid.crank.count"),
    ({"grid": {"crank": {"from": "20 mm", "to": "50 mm", "count": 1}}}, "grid.crank"),
    ({"grid": {"crank": {"from": "20 mm", "to": "50 mm", "count": 3, "step": 1}}}, "grid.crank"),
    ({"grid": {c: {"from": "20 mm", "to": "50 mm", "count": 2} for c in "abcd"}}, "grid"),
    ({"grid": {}}, "grid"),
    ({"kind": "tolerance"}, "grid"),
])
def test_bad_grid_is_a_scene_error_naming_the_key(change, key):
    raw = {**_crank_grid(11, 91, 17), **change}
    with pytest.raises(SceneError) as err:
        parse_study(raw, STUDIES / "inline.toml")
    assert key in str(err.value) and "inline.toml" in str(err.value)


def test_a_local_dask_cluster_gives_the_serial_grid(crank_grid):
    """Two worker processes (batches of 3 points) give the serial grid bit for bit."""
    pytest.importorskip("distributed")
    spec = parse_study(_crank_grid(11, 91, 17, batch=3), STUDIES / "inline.toml")
    on_dask = study(spec, workers=2)
    for x, z in zip(crank_grid.variants[:2], on_dask.variants[:2]):
        np.testing.assert_array_equal(x, z)
    assert crank_grid.variants[2] == on_dask.variants[2]
    np.testing.assert_array_equal(crank_grid.transmission, on_dask.transmission)


def test_a_three_parameter_grid_has_a_table_but_its_figure_is_refused_by_name(tmp_path):
    from pinmech.design.study.plot import grid_figure
    from pinmech.exceptions import OptionRefused

    raw = _crank_grid(30, 40, 2)
    raw["params"].update(ground={"joint": "O4", "component": "x"},
                         coupler={"cut": "B", "side": "parent", "component": "x"})
    raw["grid"].update(ground={"from": "100 mm", "to": "100 mm", "count": 1},
                       coupler={"from": "118 mm", "to": "122 mm", "count": 2})
    res = study(parse_study(raw, STUDIES / "inline.toml"))
    assert len(grid_table(res)["point"]) == 4
    # row-major, the last axis fastest; exact: the values are from + i (to - from) / (count - 1)
    np.testing.assert_allclose(res.variants[0] * 1e3, [[30, 100, 118], [30, 100, 122], [40, 100, 118], [40, 100, 122]],
                               rtol=rounding(1.0))
    with pytest.raises(OptionRefused, match="3 parameters"):
        grid_figure(res, tmp_path / "g.png")


@pytest.mark.parametrize("kind, change, key", [
    ("grid", {"params": {"crank": {"joint": "A", "component": "x", "sigma": "0.1 mm"}}}, "params.crank.sigma"),
    ("grid", {"params": {"crank": {"joint": "A", "component": "x", "tolerance": "0.1 mm"}}},
     "params.crank.tolerance"),
    ("grid", {"params": {"crank": {"joint": "A", "component": "x", "distribution": "uniform"}}},
     "params.crank.distribution"),
    ("grid", {"samples": 100}, "samples"),
    ("grid", {"seed": 7}, "seed"),
    ("sensitivity", {"params": {"crank": {"joint": "A", "component": "x", "k": 2}}}, "params.crank.k"),
    ("sensitivity", {"batch": 10}, "batch"),
    ("tolerance", {"params": {"crank": {"joint": "A", "component": "x", "sigma": "0.1 mm", "k": 2}}},
     "params.crank.k"),
    ("tolerance", {"params": {"crank": {"joint": "A", "component": "x", "tolerance": "0.1 mm",
                                        "distribution": "fixed"}}}, "params.crank.tolerance"),
])
def test_a_key_the_kind_would_ignore_is_refused_by_name(kind, change, key):
    """Before: a grid study's sigma or samples were read by nobody, in silence, as were a
    k beside sigma and a tolerance on a fixed parameter. Now each key that nothing would
    read is a SceneError naming the file and the key."""
    raw = {**_crank_grid(11, 91, 17), **change, "kind": kind}
    if kind != "grid":
        raw.pop("grid")
        raw.pop("batch") if kind == "sensitivity" else None
        raw.update(change)
    with pytest.raises(SceneError) as err:
        parse_study(raw, STUDIES / "inline.toml")
    assert key in str(err.value) and "inline.toml" in str(err.value)


def test_the_grids_transmission_extreme_is_named_as_sweeps_acute_least(crank_grid):
    """One convention with `sweep`: mu on [0, 180] deg, its extreme folded on [0, 90] named
    acute (the grid called it the 'least transmission angle', which sweep's summary gives
    for mu on [0, 180])."""
    from pinmech.design.study.report import grid_table, summary

    table = grid_table(crank_grid)
    assert "least acute transmission angle [deg]" in table and "least transmission angle [deg]" not in table
    found = summary(crank_grid)
    assert "transmission_angle_acute_least_deg" in found and "least_transmission_angle_deg" not in found
    assert found["transmission_angle_acute_least_deg"] == pytest.approx(np.nanmin(table["least acute transmission angle [deg]"]))
