"""Process capability of a tolerance study's outputs against a stated spec.

A study file's `[spec]` table gives, for an output, the limits on its deviation from the
nominal at every pose (the nominal's own motion is the design; the spec bounds what the
tolerances add to it):

    [spec]
    "P.y" = "0.3 mm"                                  # +-0.3 mm
    "rocker.angle" = { lower = "-0.4 deg", upper = "0.5 deg" }

At each pose, over the variants that solved (mean mu and standard deviation sigma of the
deviation): Cp = (USL - LSL) / (6 sigma), Cpk = min(USL - mu, mu - LSL) / (3 sigma), and
the parts per million outside the limits of the normal with that mu and sigma,
1e6 (Phi((LSL - mu) / sigma) + Phi((mu - USL) / sigma)). The pose that matters is the
one with the least Cpk; beside it, the parts per million counted: the variants whose
deviation leaves the limits at any pose of the cycle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.exceptions import SceneError
from pinmech.units import to_si

#: An output's kind (outputs.py) -> the quantity its limits are written as (units.SI_UNITS).
_QUANTITY = {"length": "length", "angle": "angle", "speed": "velocity", "angular speed": "angular_velocity",
             "angular acceleration": "angular_acceleration", "torque": "torque", "force": "force"}


@dataclass(frozen=True)
class Capability:
    """One output against its limits [SI, on the deviation from the nominal].

    Attributes:
        lower, upper: the limits; mean, sigma: (steps,) of the deviation over the survivors.
        cp, cpk: (steps,) the indices at each pose (inf where sigma is 0).
        ppm: (steps,) parts per million outside, of the normal with that mean and sigma.
        ppm_observed: variants outside at some pose of the cycle, per million survivors.
        worst: the pose index with the least Cpk.
    """

    lower: float
    upper: float
    mean: np.ndarray
    sigma: np.ndarray
    cp: np.ndarray
    cpk: np.ndarray
    ppm: np.ndarray
    ppm_observed: float
    worst: int


def normal_cdf(x: np.ndarray | float) -> np.ndarray:
    """Phi(x), the standard normal's cumulative distribution (through erfc: exact in the tails)."""
    return 0.5 * np.vectorize(math.erfc)(-np.asarray(x, dtype=float) / math.sqrt(2.0))


def indices(mean: np.ndarray, sigma: np.ndarray, lower: float, upper: float) -> tuple[np.ndarray, np.ndarray]:
    """Cp = (U - L) / (6 sigma) and Cpk = min(U - mean, mean - L) / (3 sigma) (inf at sigma = 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        cp = np.where(sigma > 0, (upper - lower) / (6.0 * sigma), math.inf)
        cpk = np.where(sigma > 0, np.minimum(upper - mean, mean - lower) / (3.0 * sigma), math.inf)
    return cp, cpk


def ppm_normal(mean: np.ndarray, sigma: np.ndarray, lower: float, upper: float) -> np.ndarray:
    """Parts per million of N(mean, sigma) outside [lower, upper] (0 or 1e6 at sigma = 0)."""
    mean, sigma = np.asarray(mean, dtype=float), np.asarray(sigma, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        below = normal_cdf(np.where(sigma > 0, (lower - mean) / sigma, np.where(mean < lower, math.inf, -math.inf)))
        above = normal_cdf(np.where(sigma > 0, (mean - upper) / sigma, np.where(mean > upper, math.inf, -math.inf)))
    return 1e6 * (below + above)


def capability(dev: np.ndarray, lower: float, upper: float) -> Capability:
    """The capability of deviations dev (survivors, steps) against [lower, upper]."""
    mean = dev.mean(axis=0)
    sigma = dev.std(axis=0, ddof=1) if dev.shape[0] > 1 else np.zeros(dev.shape[1])
    cp, cpk = indices(mean, sigma, lower, upper)
    outside = np.any((dev < lower) | (dev > upper), axis=1)
    return Capability(lower, upper, mean, sigma, cp, cpk, ppm_normal(mean, sigma, lower, upper),
                      1e6 * float(outside.mean()) if dev.shape[0] else math.nan, int(np.argmin(cpk)))


def limits(raw: tuple, names: list[str], kinds: list[str], path: str) -> dict[str, tuple[float, float]]:
    """The `[spec]` table as output name -> (lower, upper) [SI], each written in the output's
    own quantity ("0.3 mm" for a length: +-0.3 mm; or {lower, upper}).

    Raises:
        SceneError: an output the study does not have, a value of another quantity, or
            lower not below upper (naming the file and the key).
    """
    out = {}
    for name, value in raw:  # (StudySpec.limits: pairs, a table's as pairs too)
        value = dict(value) if isinstance(value, tuple) else value
        key = f"spec.{name}"
        if name not in names:
            raise SceneError(f"'{name}' is not an output of this study (outputs: {', '.join(names)})", path=path,
                             key=key)
        quantity = _QUANTITY[kinds[names.index(name)]]
        if isinstance(value, dict):
            unknown = sorted(set(value) - {"lower", "upper"})
            if unknown or len(value) != 2:
                raise SceneError(f"give lower and upper (unknown: {', '.join(unknown) or 'none'})", path=path, key=key)
            lo, hi = (to_si(value[k], quantity, where=f"{path}, {key}.{k}") for k in ("lower", "upper"))
        else:
            half = to_si(value, quantity, where=f"{path}, {key}")
            lo, hi = -half, half
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise SceneError(f"the limits {value!r} must be finite with lower below upper (a +- value positive)",
                             path=path, key=key)
        out[name] = (lo, hi)
    return out
