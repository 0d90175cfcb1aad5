"""Slider-crank function generation: the block's travel along the slide a prescribed
function of the crank's turn, at N pairs (crank turn, slider travel) from the first pair.

A search row x = (crank r, rod l, offset e, theta0) [m, m, m, rad]: the crank's pivot O2 =
(0, 0), the slide along x at y = e (slider's row (0, 0, 0, e, r, l, 0, 0)); the
crank at theta0 + dtheta_i must move the block by dx_i from where it is at theta0. The
objective is the sum of the squared travel errors over the travel's range squared;
defects and constraints as for paths (motion.causes: the pairs' crank turns fix
the order). Refinement: least squares with the exact Jacobian of the block's place
(slider.loop_jacobian).
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.motion import causes, grashof_label, progress, transmission_range
from pinmech.design.synthesis.objective import BatchValues, batch_values
from pinmech.design.synthesis.refine import refine
from pinmech.design.synthesis.result import Linkage
from pinmech.design.synthesis.slider import loop_jacobian, pose, slide_position

_TOPOLOGY = "slider-crank"


def slider_function_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The file's bounds of crank, rod and offset, and the start angle over a turn."""
    return [*zip(spec.lower.tolist(), spec.upper.tolist()), (-math.pi, math.pi)]


def _linkages(spec: SynthesisSpec, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows x (n, 4) -> z (n, 8) and the crank angles at the pairs (n, N) [rad]."""
    z = np.zeros((len(x), 8))
    z[:, 4], z[:, 5], z[:, 3] = x[:, 0], x[:, 1], x[:, 2]
    return z, x[:, 3:4] + spec.targets[None, :, 0]


def _span(spec: SynthesisSpec) -> float:
    return float(max(np.ptp(spec.targets[:, 1]), 1e-12))


def _travel_errors(spec: SynthesisSpec, z: np.ndarray, s: np.ndarray,
                   theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The block's travel from the first pair minus the travel asked (n, N) [m], and its
    place along the slide at the first pair (n,) [m]."""
    x = slide_position(z, pose(z, s, theta).B)
    return (x - x[:, :1]) - spec.targets[None, :, 1], x[:, 0]


def evaluate_slider_function(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The objective of rows x (n, 4) on one assembly, row by row."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    z, theta = _linkages(spec, x)
    s = np.full(len(x), float(assembly))
    err, _ = _travel_errors(spec, z, s, theta)
    err2 = (err / _span(spec)) ** 2
    found = causes(spec, z, s, theta)
    return batch_values(found, err2, theta)


def refined_slider_function(spec: SynthesisSpec, s0: float, x: np.ndarray) -> Linkage | None:
    """The row x on assembly s0 refined by least squares (bounds kept), or x itself if the
    refined one has a defect; None if neither is free of them."""
    span = _span(spec)

    def residual(v: np.ndarray) -> np.ndarray:
        z, theta = _linkages(spec, v[None])
        r = _travel_errors(spec, z, np.array([s0]), theta)[0][0] / span
        return np.where(np.isfinite(r), r, 1.0)

    def jacobian(v: np.ndarray) -> np.ndarray:
        z, theta = _linkages(spec, v[None])
        _, dq_z, dq_t = loop_jacobian(z[0], s0, theta[0])
        dx = np.column_stack((dq_z[:, 1, 4], dq_z[:, 1, 5], dq_z[:, 1, 3], dq_t[:, 1]))  # d x_i / d(r, l, e, theta0)
        return (dx - dx[:1]) / span

    lower = np.concatenate((spec.lower, [-np.inf]))
    upper = np.concatenate((spec.upper, [np.inf]))
    return refine(residual, jacobian, x, lower, upper, lambda v: _linkage(spec, v, s0))


def _linkage(spec: SynthesisSpec, v: np.ndarray, s: float) -> Linkage | None:
    z, theta = _linkages(spec, v[None])
    S = np.array([s])
    err, x0 = _travel_errors(spec, z, S, theta)
    if not np.all(np.isfinite(err)) or causes(spec, z, S, theta)[0]:
        return None
    way, span = progress(theta, spec.direction)
    low, high = transmission_range(z, S, theta, way, span, _TOPOLOGY)
    return Linkage(z[0].copy(), s, theta[0].copy(), int(way[0]), np.abs(err[0]), (float(low[0]), float(high[0])),
                   grashof_label(z[0], _TOPOLOGY), task="function", phi0=float(x0[0]), topology=_TOPOLOGY)
