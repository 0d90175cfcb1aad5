"""Four-bar function generation: the rocker's turn a prescribed function of the crank's,
at N pairs (crank turn, rocker turn) from the first pair.

A search row x = (crank a, coupler b, rocker c, theta0, phi0) [m, m, m, rad, rad]: the
ground O2 = (0, 0), O4 = (d, 0) with d the file's `ground`; the crank at theta0 + dtheta_i
must put the rocker (direction O4 -> B) at phi0 + dphi_i. The objective is the sum of the
squared angle errors over the output range squared; defects and constraints as for paths
(motion.causes: the pairs' crank turns fix the order). Refinement: least
squares with the exact Jacobian of phi (fourbar.rocker_jacobian). Freudenstein's
equation (freudenstein.py) over a grid of start angles gives more starting points.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.freudenstein import freudenstein_k, link_lengths
from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.fourbar import pose, rocker_jacobian
from pinmech.design.synthesis.motion import causes, grashof_label, progress, transmission_range
from pinmech.design.synthesis.objective import BatchValues, batch_values
from pinmech.design.synthesis.refine import refine
from pinmech.design.synthesis.result import Linkage

_GRID = 24  # Freudenstein starts: theta0 and phi0 every 15 deg


def function_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The file's bounds of crank, coupler, rocker, and the start angles over a turn (given
    absolute pairs: the file's start, which rows do not change)."""
    if spec.start is not None:
        return [*zip(spec.lower.tolist(), spec.upper.tolist()), *((a, a + 1e-9) for a in spec.start)]
    return [*zip(spec.lower.tolist(), spec.upper.tolist()), (-math.pi, math.pi), (-math.pi, math.pi)]


def _starts(spec: SynthesisSpec, x: np.ndarray) -> np.ndarray:
    """The crank's and the rocker's angles at the first pair (n, 2) [rad]: the rows' own,
    or the file's absolute ones."""
    return x[:, 3:5] if spec.start is None else np.broadcast_to(np.asarray(spec.start), (len(x), 2))


def _linkages(spec: SynthesisSpec, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows x (n, 5) -> z (n, 9), the crank angles (n, N) and the rocker angles asked (n, N)."""
    n = len(x)
    z = np.zeros((n, 9))
    z[:, 2] = spec.ground
    z[:, 4:7] = x[:, :3]
    start = _starts(spec, x)
    return z, start[:, 0:1] + spec.targets[None, :, 0], start[:, 1:2] + spec.targets[None, :, 1]


def _wrapped(angle: np.ndarray) -> np.ndarray:
    return np.mod(angle + math.pi, 2 * math.pi) - math.pi


def _span(spec: SynthesisSpec) -> float:
    return float(max(np.ptp(spec.targets[:, 1]), 1e-9))


def evaluate_function(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The objective of rows x (n, 5) on one assembly, row by row."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    z, theta, wanted = _linkages(spec, x)
    s = np.full(len(x), float(assembly))
    B = pose(z, s, theta).B
    phi = np.arctan2(B[..., 1], B[..., 0] - spec.ground)
    err2 = (_wrapped(phi - wanted) / _span(spec)) ** 2
    found = causes(spec, z, s, theta)
    return batch_values(found, err2, theta)


def freudenstein_rows(spec: SynthesisSpec) -> np.ndarray:
    """Rows from Freudenstein's equation (least squares over the pairs) at start angles on
    a grid, within the bounds, best first."""
    rows = []
    grid = np.arange(_GRID) * 2 * math.pi / _GRID - math.pi
    for theta0, phi0 in ([spec.start] if spec.start is not None else ((t, p) for t in grid for p in grid)):
        lengths = link_lengths(freudenstein_k(theta0 + spec.targets[:, 0], phi0 + spec.targets[:, 1]), spec.ground)
        if lengths is not None and np.all((spec.lower <= lengths) & (np.array(lengths) <= spec.upper)):
            rows.append([*lengths, theta0, phi0])
    return np.array(rows).reshape(-1, 5)


def refined_function(spec: SynthesisSpec, s0: float, x: np.ndarray) -> Linkage | None:
    """The row x on assembly s0 refined by least squares (bounds kept), or x itself if the
    refined one has a defect; None if neither is free of them."""
    span = _span(spec)

    def residual(v: np.ndarray) -> np.ndarray:
        z, theta, wanted = _linkages(spec, v[None])
        B = pose(z, np.array([s0]), theta).B[0]
        r = _wrapped(np.arctan2(B[:, 1], B[:, 0] - spec.ground) - wanted[0]) / span
        return np.where(np.isfinite(r), r, 1.0)

    def jacobian(v: np.ndarray) -> np.ndarray:
        z, theta, _ = _linkages(spec, v[None])
        _, dz, dt = rocker_jacobian(z[0], s0, theta[0])
        if spec.start is not None:  # the start angles are the file's: the rows' do not count
            dt, minus = np.zeros_like(dt), np.zeros(len(dt))
        else:
            minus = -np.ones(len(dt))
        return np.column_stack((dz[:, 4:7], dt, minus)) / span

    lower = np.concatenate((spec.lower, [-np.inf, -np.inf]))
    upper = np.concatenate((spec.upper, [np.inf, np.inf]))
    return refine(residual, jacobian, x, lower, upper, lambda v: _linkage(spec, v, s0, np.abs(residual(v)) * span))


def _linkage(spec: SynthesisSpec, v: np.ndarray, s: float, errors: np.ndarray) -> Linkage | None:
    z, theta, _ = _linkages(spec, v[None])
    S = np.array([s])
    if not np.all(np.isfinite(errors)) or causes(spec, z, S, theta)[0]:
        return None
    way, span = progress(theta, spec.direction)
    low, high = transmission_range(z, S, theta, way, span)
    return Linkage(z[0].copy(), s, theta[0].copy(), int(way[0]), errors, (float(low[0]), float(high[0])),
                   grashof_label(z[0]), task="function", phi0=float(_starts(spec, v[None])[0, 1]))
