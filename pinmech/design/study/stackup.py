"""A tolerance study's stack-up at every pose of the cycle, as a designer reads it.

For output y and parameters p_i with tolerances t_i (the +- half width: a uniform's, or
3 sigma_i of a normal) and standard deviations sigma_i, from the exact sensitivities
S_i = dy/dp_i at the pose:

    worst case   sum |S_i| t_i
    RSS          sqrt(sum (S_i t_i)^2)
    sigma linear sqrt(sum (S_i sigma_i)^2)
    contribution (S_i sigma_i)^2 / sigma_linear^2   (of the variance; they add up to 1)

beside the Monte Carlo sigma of the deviation over the variants that solved. A point
output's spread in the plane at a pose is its covariance: S Sigma_p S^T (linear) and the
variants' sample covariance (Monte Carlo); its 3-sigma ellipse is that covariance's
ellipse at 3 standard deviations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.design.study.tolerance import deviation, half_widths


@dataclass(frozen=True)
class Stackup:
    """Per pose (steps) and output (n_out), in SI.

    Attributes:
        tolerance: (n_par,) t_i; sigma_p: (n_par,) sigma_i.
        worst, rss, sigma_linear: (steps, n_out) the linear stack-ups above.
        sigma, mean: (steps, n_out) the Monte Carlo deviation's standard deviation and mean
            over the `solved` variants of `samples` (NaN without survivors).
        contribution: (steps, n_out, n_par) each parameter's share of the linear variance.
    """

    tolerance: np.ndarray
    sigma_p: np.ndarray
    worst: np.ndarray
    rss: np.ndarray
    sigma_linear: np.ndarray
    sigma: np.ndarray
    mean: np.ndarray
    contribution: np.ndarray
    solved: int
    samples: int


def stackup(result) -> Stackup:
    """The stack-up of a tolerance study's result (run.StudyResult)."""
    params = result.spec.params
    sigma_p = np.array([p.sigma for p in params])
    t = half_widths(params)
    S = result.sensitivity
    var = (S * sigma_p) ** 2
    sigma_linear = np.sqrt(var.sum(axis=-1))
    with np.errstate(divide="ignore", invalid="ignore"):
        contribution = np.where(sigma_linear[..., None] > 0, var / sigma_linear[..., None] ** 2, 0.0)
    dev = survivors(result)
    nan = np.full(sigma_linear.shape, math.nan)
    sigma = dev.std(axis=0, ddof=1) if dev.shape[0] > 1 else nan
    mean = dev.mean(axis=0) if dev.shape[0] else nan
    return Stackup(t, sigma_p, np.abs(S) @ t, np.sqrt(((S * t) ** 2).sum(axis=-1)), sigma_linear, sigma, mean,
                   contribution, dev.shape[0], len(result.variants[2]))


def survivors(result) -> np.ndarray:
    """The deviations from the nominal (solved, steps, n_out) [SI] of the variants that solved."""
    _, y, causes = result.variants
    ok = np.array([not c for c in causes], dtype=bool)
    return deviation(y[ok], result.nominal, result.kinds)


def point_pairs(outputs: list[str]) -> list[tuple[str, int, int]]:
    """(point, index of its .x, index of its .y) for each point output with both."""
    return [(n[:-2], outputs.index(n), outputs.index(n[:-2] + ".y")) for n in outputs
            if n.endswith(".x") and n[:-2] + ".y" in outputs]


def covariances(result, ix: int, iy: int) -> tuple[np.ndarray, np.ndarray]:
    """A point's (x, y) covariance at each pose (steps, 2, 2) [m^2]: linear S Sigma_p S^T,
    and the survivors' sample covariance (NaN with fewer than two)."""
    sigma_p = np.array([p.sigma for p in result.spec.params])
    S = result.sensitivity[:, [ix, iy], :]
    linear = np.einsum("sak,k,sbk->sab", S, sigma_p**2, S)
    dev = survivors(result)[:, :, [ix, iy]]
    if dev.shape[0] < 2:
        return linear, np.full(linear.shape, math.nan)
    centred = dev - dev.mean(axis=0)
    return linear, np.einsum("nsa,nsb->sab", centred, centred) / (dev.shape[0] - 1)


def ellipse(cov: np.ndarray, k: float = 3.0, points: int = 73) -> np.ndarray:
    """The k-sigma ellipse of a 2 x 2 covariance [m^2], (points, 2) [m] about the origin."""
    w, v = np.linalg.eigh(0.5 * (cov + cov.T))
    a = np.linspace(0.0, 2 * math.pi, points)
    circle = np.stack([np.cos(a), np.sin(a)], axis=-1)
    return k * (circle * np.sqrt(np.clip(w, 0.0, None))) @ v.T
