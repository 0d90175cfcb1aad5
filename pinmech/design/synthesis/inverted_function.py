"""Inverted slider-crank function generation: the guide's (the rocker's) turn a prescribed
function of the crank's, at N pairs (crank turn, guide turn) from the first pair.

A search row x = (crank r, offset e, theta0, phi0) [m, m, rad, rad]: the crank's pivot O2 =
(0, 0), the guide's O4 = (d, 0) with d the file's `ground` (inverted's row (0, 0,
d, 0, r, e, 0, 0)); the crank at theta0 + dtheta_i must put the guide (the slot's
direction) at phi0 + dphi_i. Four unknowns: four pairs are met exactly in general, more
in least squares. The objective is the sum of the squared angle errors over the output's
range squared; defects and constraints as for paths (motion.causes: the pairs'
crank turns fix the order). Refinement: least squares with the exact Jacobian of the
guide's angle (inverted.guide_jacobian).
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.inverted import guide_angle, guide_jacobian
from pinmech.design.synthesis.motion import causes, grashof_label, progress, transmission_range
from pinmech.design.synthesis.objective import BatchValues, batch_values
from pinmech.design.synthesis.refine import refine
from pinmech.design.synthesis.result import Linkage

_TOPOLOGY = "inverted-slider-crank"


def inverted_function_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The file's bounds of crank and offset, and the start angles over a turn."""
    return [*zip(spec.lower.tolist(), spec.upper.tolist()), (-math.pi, math.pi), (-math.pi, math.pi)]


def _linkages(spec: SynthesisSpec, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows x (n, 4) -> z (n, 8), the crank angles (n, N) and the guide angles asked (n, N)."""
    z = np.zeros((len(x), 8))
    z[:, 2] = spec.ground
    z[:, 4:6] = x[:, :2]
    return z, x[:, 2:3] + spec.targets[None, :, 0], x[:, 3:4] + spec.targets[None, :, 1]


def _wrapped(angle: np.ndarray) -> np.ndarray:
    return np.mod(angle + math.pi, 2 * math.pi) - math.pi


def _span(spec: SynthesisSpec) -> float:
    return float(max(np.ptp(spec.targets[:, 1]), 1e-9))


def _errors(spec: SynthesisSpec, z: np.ndarray, s: np.ndarray, theta: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """The guide's angle minus the angle asked, wrapped to a half turn (n, N) [rad]."""
    return _wrapped(guide_angle(z, s, theta) - wanted)


def evaluate_inverted_function(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The objective of rows x (n, 4) on one assembly, row by row."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    z, theta, wanted = _linkages(spec, x)
    s = np.full(len(x), float(assembly))
    err2 = (_errors(spec, z, s, theta, wanted) / _span(spec)) ** 2
    return batch_values(causes(spec, z, s, theta), err2, theta)


def refined_inverted_function(spec: SynthesisSpec, s0: float, x: np.ndarray) -> Linkage | None:
    """The row x on assembly s0 refined by least squares (bounds kept), or x itself if the
    refined one has a defect; None if neither is free of them."""
    span = _span(spec)
    S = np.array([s0])

    def residual(v: np.ndarray) -> np.ndarray:
        z, theta, wanted = _linkages(spec, v[None])
        r = _errors(spec, z, S, theta, wanted)[0] / span
        return np.where(np.isfinite(r), r, 1.0)

    def jacobian(v: np.ndarray) -> np.ndarray:
        z, theta, _ = _linkages(spec, v[None])
        _, dz, dt = guide_jacobian(z[0], s0, theta[0])
        return np.column_stack((dz[:, 4:6], dt, -np.ones(len(dt)))) / span

    lower = np.concatenate((spec.lower, [-np.inf, -np.inf]))
    upper = np.concatenate((spec.upper, [np.inf, np.inf]))
    return refine(residual, jacobian, x, lower, upper, lambda v: _linkage(spec, v, s0))


def _linkage(spec: SynthesisSpec, v: np.ndarray, s: float) -> Linkage | None:
    z, theta, wanted = _linkages(spec, v[None])
    S = np.array([s])
    errors = np.abs(_errors(spec, z, S, theta, wanted)[0])
    if not np.all(np.isfinite(errors)) or causes(spec, z, S, theta)[0]:
        return None
    way, span = progress(theta, spec.direction)
    low, high = transmission_range(z, S, theta, way, span, _TOPOLOGY)
    return Linkage(z[0].copy(), s, theta[0].copy(), int(way[0]), errors, (float(low[0]), float(high[0])),
                   grashof_label(z[0], _TOPOLOGY), task="function", phi0=float(v[3]), topology=_TOPOLOGY)
