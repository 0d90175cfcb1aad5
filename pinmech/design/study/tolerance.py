"""Tolerance studies: seeded Monte Carlo over the parameters' distributions, each variant
solved over the cycle, beside the linear estimate from the exact sensitivities.

Variants are drawn in batches of `spec.batch`: batch i draws from
`SeedSequence(spec.seed, spawn_key=(i,))`, so a variant's values depend on the study's
seed and its index only, never on how many processes share the work (cluster.py).
Every variant that fails is kept with its cause (variant.CAUSES).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.variant import StudyMechanism

PERCENTILES = (0.5, 50.0, 99.5)


@dataclass(frozen=True)
class Batch:
    """Variants start .. start + count - 1 of a study, drawn from batch `index`'s stream."""

    index: int
    start: int
    count: int


@dataclass(frozen=True)
class BatchResult:
    """The variants of a batch: parameters p (count, n_par) [m], outputs y (count, steps,
    n_out) [m, rad] (NaN rows where a variant failed), and each failure's cause ("" if none);
    extra: one more number a variant (a grid study's least transmission angle [rad]) or None."""

    batch: Batch
    p: np.ndarray
    y: np.ndarray
    causes: tuple[str, ...]
    extra: np.ndarray | None = None


def batches(samples: int, size: int) -> list[Batch]:
    """The study's batches: `samples` variants, `size` a batch (the last one shorter)."""
    return [Batch(i, s, min(size, samples - s)) for i, s in enumerate(range(0, samples, size))]


def draw(sm: StudyMechanism, batch: Batch) -> np.ndarray:
    """The batch's parameter values (count, n_par) [m], from its own seeded stream."""
    rng = np.random.default_rng(np.random.SeedSequence(sm.spec.seed, spawn_key=(batch.index,)))
    return np.column_stack([param.sample(nominal, rng, batch.count)
                            for param, nominal in zip(sm.spec.params, sm.nominal)]).reshape(batch.count, -1)


def run_batch(sm: StudyMechanism, outputs: StudyOutputs, batch: Batch) -> BatchResult:
    """Solve the batch's drawn variants over the cycle (the model is left at the nominal)."""
    return solve_variants(sm, outputs, batch, draw(sm, batch))


def solve_variants(sm: StudyMechanism, outputs: StudyOutputs, batch: Batch, p: np.ndarray,
                   at_variant: Callable[[np.ndarray], float] | None = None) -> BatchResult:
    """Solve the variants p (count, n_par) [m] over the cycle (the model is left at the
    nominal). `at_variant(q)`, if given, is called on each solved variant's poses while its
    values are still written in the model; its numbers are the result's `extra` (NaN: failed)."""
    y = np.full((batch.count, len(sm.values), len(outputs.names)), np.nan)
    extra = np.full(batch.count, np.nan) if at_variant else None
    causes = []
    try:
        for i, (pi, outside) in enumerate(zip(p, sm.outside(p).tolist())):
            cycle = sm.rejected(pi) if outside else sm.within(pi)
            causes.append(cycle.cause)
            if not cycle.cause:
                outputs.cycle(cycle.q, cycle.v, cycle.a, out=y[i])
                if at_variant:
                    extra[i] = at_variant(cycle.q)
    finally:
        sm.write(sm.nominal)
    return BatchResult(batch, p, y, tuple(causes), extra)


@dataclass(frozen=True)
class Spread:
    """The outputs' spread over the cycle, from the Monte Carlo and from the linear estimate.

    Attributes:
        names: output names; nominal: (steps, n_out) nominal outputs; sensitivity:
            (steps, n_out, n_par) dy/dp.
        sigma: (steps, n_out) standard deviation of the deviation y - y_nominal over the
            variants that solved; sigma_linear: sqrt(sum (dy/dp_k sigma_k)^2).
        worst: (n_out,) largest |y - y_nominal| over variants and poses; worst_linear:
            (n_out,) max over poses of sum |dy/dp_k| t_k (t: the uniform half width, or 3 sigma).
        percentiles: (len(PERCENTILES), steps, n_out) of the deviation.
        failures: cause -> how many variants failed so; solved: variants that solved.
    """

    names: list[str]
    nominal: np.ndarray
    sensitivity: np.ndarray
    sigma: np.ndarray
    sigma_linear: np.ndarray
    worst: np.ndarray
    worst_linear: np.ndarray
    percentiles: np.ndarray
    failures: dict[str, int]
    solved: int


def spread(sm: StudyMechanism, outputs: StudyOutputs, results: list[BatchResult]) -> Spread:
    """Gather the batches (in order) into a Spread against the nominal's linear estimate."""
    nominal_cycle = sm.cycle(sm.nominal)
    y0, dy = cycle_sensitivity(sm, outputs, nominal_cycle)
    y = np.concatenate([r.y for r in results])
    causes = [c for r in results for c in r.causes]
    ok = np.array([not c for c in causes], dtype=bool)
    dev = deviation(y[ok], y0, outputs.kinds)
    sig = np.array([param.sigma for param in sm.spec.params])
    half = half_widths(sm.spec.params)
    failures: dict[str, int] = {}
    for c in causes:
        if c:
            failures[c] = failures.get(c, 0) + 1
    empty = not dev.shape[0]
    return Spread(
        outputs.names, y0, dy,
        np.full(y0.shape, math.nan) if empty else dev.std(axis=0, ddof=1) if dev.shape[0] > 1 else np.zeros(y0.shape),
        np.sqrt(((dy * sig) ** 2).sum(axis=-1)),
        np.full(y0.shape[1], math.nan) if empty else np.abs(dev).max(axis=(0, 1)),
        (np.abs(dy) @ half).max(axis=0),
        np.full((len(PERCENTILES), *y0.shape), math.nan) if empty else np.percentile(dev, PERCENTILES, axis=0),
        failures, int(ok.sum()))


def half_widths(params) -> np.ndarray:
    """Each parameter's tolerance t [m or rad]: a uniform's half width, else 3 sigma."""
    return np.array([p.spread if p.distribution == "uniform" else 3.0 * p.sigma for p in params])


def deviation(y: np.ndarray, y0: np.ndarray, kinds: list[str]) -> np.ndarray:
    """y - y0, angles wrapped into [-pi, pi) [m, rad]."""
    dev = y - y0
    angles = np.array([k == "angle" for k in kinds])
    dev[..., angles] = (dev[..., angles] + math.pi) % (2 * math.pi) - math.pi
    return dev
