"""Tolerance studies: Monte Carlo spread against the linear estimate, every variant against
the closed-form four-bar, and the failures of a non-Grashof family against the law of cosines."""

from __future__ import annotations

from pathlib import Path

import closed_form
import numpy as np

from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.file import load_study, parse_study
from pinmech.design.study.variant import StudyMechanism
from pinmech.design.study.tolerance import batches, deviation, run_batch, spread

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
NOMINAL = {"crank": 0.04, "coupler": 0.12, "rocker": 0.08, "ground": 0.10}  # a, b, c, d [m]


def _four_bar_study(params: dict, samples: int, steps: int = 37, seed: int = 7) -> StudyMechanism:
    where = {"crank": {"joint": "A"}, "ground": {"joint": "O4"}, "coupler": {"cut": "B", "side": "parent"},
             "rocker": {"cut": "B", "side": "child"}}
    table = {name: {**where[name], "component": "x", **spec} for name, spec in params.items()}
    raw = {"scene": "../scenes/four_bar.toml", "kind": "tolerance", "steps": steps, "samples": samples,
           "seed": seed, "batch": 50, "params": table, "outputs": {"points": ["P"], "links": ["rocker"]}}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def _run(sm: StudyMechanism):
    outputs = StudyOutputs(sm)
    return outputs, [run_batch(sm, outputs, b) for b in batches(sm.spec.samples, sm.spec.batch)]


def _lengths(sm: StudyMechanism, p: np.ndarray) -> np.ndarray:
    """(n, 4) a, b, c, d of each variant: the study's values, the others nominal."""
    names = [x.name for x in sm.spec.params]
    return np.column_stack([p[:, names.index(n)] if n in names else np.full(len(p), NOMINAL[n])
                            for n in ("crank", "coupler", "rocker", "ground")])


def _closed_outputs(theta2: np.ndarray, a: float, b: float, c: float, d: float) -> np.ndarray:
    """P (60, 30) mm on the coupler and theta4, by the law of cosines (scripts/closed_form.py)."""
    fb = closed_form.four_bar(theta2, 0.0, 0.0, a, b, c, d, +1)
    c3, s3 = np.cos(fb.theta3), np.sin(fb.theta3)
    return np.column_stack([a * np.cos(theta2) + 0.06 * c3 - 0.03 * s3, a * np.sin(theta2) + 0.06 * s3 + 0.03 * c3,
                            fb.theta4])


def test_spread_at_small_sigma_is_the_linear_estimate():
    """The bundled tolerance study (tolerances 0.1 mm on 40-120 mm links), 1000 variants:
    at each pose the standard deviation of each output equals the linear estimate
    sqrt(sum (dy/dp_k sigma_k)^2). The sample sigma's relative standard error is
    1/sqrt(2 (N - 1)) = 2.2% at N = 1000; the nonlinearity is of order sigma / L = 1e-3:
    tolerance 10% (4.5 standard errors, over 37 poses x 3 outputs). The worst deviation
    stays within the linear worst case plus 10%."""
    spec = load_study(STUDIES / "four_bar_tolerance.toml")
    sm = StudyMechanism(spec.__class__(**{**spec.__dict__, "samples": 1000, "steps": 37}))
    outputs, results = _run(sm)
    s = spread(sm, outputs, results)
    assert s.failures == {} and s.solved == 1000
    np.testing.assert_allclose(s.sigma, s.sigma_linear, rtol=0.10)
    assert np.all(s.worst <= 1.1 * s.worst_linear), (s.worst, s.worst_linear)


def test_every_variant_at_large_sigma_is_its_closed_form():
    """200 variants with sigma 1 mm on every length (brute force: each variant re-solved):
    each variant's P and theta4 at every pose equal the law-of-cosines four-bar of its own
    lengths, to 1e-11 m and 1e-10 rad (closure tolerance 1e-13 of the loop, times the
    condition number < 100); and their spread is no longer the linear estimate's within
    rounding, only within 25% (the nonlinearity at sigma / L = 1e-2)."""
    sm = _four_bar_study({n: {"sigma": "1 mm"} for n in NOMINAL}, samples=200)
    outputs, results = _run(sm)
    p = np.concatenate([r.p for r in results])
    y = np.concatenate([r.y for r in results])
    assert not any(c for r in results for c in r.causes)
    for lengths, yi in zip(_lengths(sm, p), y):
        expected = _closed_outputs(sm.values, *lengths)
        np.testing.assert_allclose(yi[:, :2], expected[:, :2], rtol=0, atol=1e-11)
        np.testing.assert_allclose(deviation(yi[:, 2:], expected[:, 2:], ["angle"]), 0.0, rtol=0, atol=1e-10)
    s = spread(sm, outputs, results)
    np.testing.assert_allclose(s.sigma, s.sigma_linear, rtol=0.25)


def test_non_grashof_failures_are_counted_by_the_law_of_cosines():
    """Crank a uniform in 50 +- 30 mm and rocker c uniform in 70 +- 45 mm (its nominal moved
    from the model's 80 mm by the study file; b = 120, d = 100):
    a variant assembles at the start theta0 = 60 deg iff the diagonal f = |A - O4| (law of
    cosines) satisfies |b - c| <= f <= b + c, and turns through a whole turn iff it does so
    for every theta: |b - c| <= |a - d| and a + d <= b + c. The study counts exactly those
    that cannot assemble and those that meet a fold, and drops none."""
    sm = _four_bar_study({"crank": {"tolerance": "30 mm", "distribution": "uniform"},
                          "rocker": {"nominal": "70 mm", "tolerance": "45 mm", "distribution": "uniform"}},
                         samples=300)
    outputs, results = _run(sm)
    p = np.concatenate([r.p for r in results])
    causes = np.array([c for r in results for c in r.causes])
    a, b, c, d = _lengths(sm, p).T
    theta0 = np.radians(60.0)
    f0 = np.sqrt(a**2 + d**2 - 2 * a * d * np.cos(theta0))
    assembles = (np.abs(b - c) <= f0) & (f0 <= b + c)
    turns = assembles & (np.abs(b - c) <= np.abs(a - d)) & (a + d <= b + c)
    assert len(causes) == 300
    np.testing.assert_array_equal(causes == "cannot assemble", ~assembles)
    np.testing.assert_array_equal(causes == "fold within the range", assembles & ~turns)
    np.testing.assert_array_equal(causes == "", turns)
    assert 20 < (~assembles).sum() and 20 < (assembles & ~turns).sum() and 20 < turns.sum()  # each cause occurs
    s = spread(sm, outputs, results)
    assert s.failures == {"cannot assemble": int((~assembles).sum()),
                          "fold within the range": int((assembles & ~turns).sum())}


def test_variants_outside_their_bounds_are_counted_not_solved():
    """Crank sigma 0.1 mm with bounds 39.9 .. 40.1 mm (1 sigma): about a third of the
    variants fall outside; each is counted as "outside bounds", its outputs left NaN,
    and every one inside is solved."""
    sm = _four_bar_study({"crank": {"sigma": "0.1 mm", "bounds": ["39.9 mm", "40.1 mm"]}}, samples=120)
    outputs, results = _run(sm)
    p = np.concatenate([r.p for r in results])[:, 0]
    y = np.concatenate([r.y for r in results])
    causes = np.array([c for r in results for c in r.causes])
    outside = (p < 0.0399) | (p > 0.0401)
    np.testing.assert_array_equal(causes == "outside bounds", outside)
    np.testing.assert_array_equal(causes == "", ~outside)
    assert 20 < outside.sum() < 60 and np.all(np.isnan(y[outside])) and not np.any(np.isnan(y[~outside]))


def test_rocker_omega_of_every_variant_is_the_closed_form_and_its_spread_the_linear_estimate():
    """rocker.omega at 120 rpm over 300 variants (sigma 0.5 mm on each length, 37 poses):
    each solved variant's omega4 equals Norton's closed form at its own lengths (scripts/
    closed_form.py, no pinmech) to 1e-9 rad/s (the closure tolerance 1e-13 of the loop times
    omega2 = 12.6 rad/s and the condition number, with a margin of 100); and the Monte Carlo
    sigma of omega equals the linear estimate from the exact d(omega)/dp within 20% (the
    sample sigma's standard error 1/sqrt(2 N) = 4% at N = 300, the nonlinearity sigma / L
    ~ 1% on the derivative)."""
    params = {n: {"sigma": "0.5 mm"} for n in ("crank", "coupler", "rocker", "ground")}
    where = {"crank": {"joint": "A"}, "ground": {"joint": "O4"}, "coupler": {"cut": "B", "side": "parent"},
             "rocker": {"cut": "B", "side": "child"}}
    table = {name: {**where[name], "component": "x", **spec} for name, spec in params.items()}
    raw = {"scene": "../scenes/four_bar.toml", "kind": "tolerance", "steps": 37, "samples": 300, "seed": 11,
           "batch": 50, "params": table, "outputs": {"omega": ["rocker"]}}
    sm = StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))
    outputs, results = _run(sm)
    p = np.concatenate([r.p for r in results])
    y = np.concatenate([r.y for r in results])
    assert all(not c for r in results for c in r.causes)
    omega2 = 120 * 2 * np.pi / 60
    for lengths, yi in zip(_lengths(sm, p), y):
        fb = closed_form.four_bar(sm.values, omega2, 0.0, *lengths, +1)
        np.testing.assert_allclose(yi[:, 0], fb.omega4, rtol=0, atol=1e-9)
    s = spread(sm, outputs, results)
    np.testing.assert_allclose(s.sigma, s.sigma_linear, rtol=0.20)
