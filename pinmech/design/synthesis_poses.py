"""Four-bar motion generation: the coupler through N poses, its point P at each target
place and its angle at each target angle, in order.

A search row x = (z (9), gamma): the four-bar (synthesis_fourbar.NAMES) and the angle
gamma [rad] from the bar A -> B to the line the poses' angles are measured on. Each pose's
crank angle is where the coupler comes nearest the pose (synthesis_objective.nearest_angles
with the angles); the objective is sum_i |P - T_i|^2 / S^2 + (1 - cos(phi3 + gamma -
angle_i)) * 2; defects and constraints as for paths. Refinement: least squares on the
places / S and the angles, with the exact Jacobians of P and phi3 (implicit-function theorem).
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis_file import SynthesisSpec
from pinmech.design.synthesis_fourbar import link_angle_jacobian, point_jacobian, pose
from pinmech.design.synthesis_motion import causes, grashof_label, progress, transmission_range
from pinmech.design.synthesis_objective import BatchValues, batch_values, extent, nearest_angles
from pinmech.design.synthesis_refine import refine
from pinmech.design.synthesis_result import Linkage


def poses_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The file's bounds of the four-bar, and gamma over a turn."""
    return [*zip(spec.lower.tolist(), spec.upper.tolist()), (-math.pi, math.pi)]


def _turn(angle: np.ndarray) -> np.ndarray:
    return np.mod(angle + math.pi, 2 * math.pi) - math.pi


def _coupler_angle(p) -> np.ndarray:
    return np.arctan2(p.B[..., 1] - p.A[..., 1], p.B[..., 0] - p.A[..., 0])


def evaluate_poses(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The objective of rows x (n, 10) on one assembly, row by row."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    z, gamma = x[:, :9], x[:, 9]
    s = np.full(len(z), float(assembly))
    theta = nearest_angles(z, s, spec.targets, spec.angles, gamma)
    p = pose(z, s, np.nan_to_num(theta))
    d2 = ((p.P - spec.targets[None]) ** 2).sum(-1) / extent(spec.targets) ** 2
    d2 = d2 + 2 * (1 - np.cos(_coupler_angle(p) + gamma[:, None] - spec.angles[None]))
    found = causes(spec, z, s, np.nan_to_num(theta))
    return batch_values(found, d2, theta)


def refined_poses(spec: SynthesisSpec, s0: float, x: np.ndarray) -> Linkage | None:
    """The row x on assembly s0 refined by least squares (bounds kept), or x itself if the
    refined one has a defect; None if neither is free of them."""
    theta = evaluate_poses(spec, s0, x[None]).theta[0]
    n, S = len(spec.targets), extent(spec.targets)
    v0 = np.concatenate((x, theta))

    def residual(v: np.ndarray) -> np.ndarray:
        p = pose(v[None, :9], np.array([s0]), v[None, 10:])
        r = np.concatenate((((p.P[0] - spec.targets) / S).ravel(), _turn(_coupler_angle(p)[0] + v[9] - spec.angles)))
        return np.where(np.isfinite(r), r, 1.0)

    def jacobian(v: np.ndarray) -> np.ndarray:
        _, dPz, dPt = point_jacobian(v[:9], s0, v[10:])
        _, dphz, dpht = link_angle_jacobian(v[:9], s0, v[10:], 0)
        J = np.zeros((3 * n, 10 + n))
        J[:2 * n, :9] = dPz.reshape(2 * n, 9) / S
        J[:2 * n, 10:] = (dPt[:, :, None] * np.eye(n)[:, None, :]).reshape(2 * n, n) / S
        J[2 * n:, :9], J[2 * n:, 9], J[2 * n:, 10:] = dphz, 1.0, np.diag(dpht)
        return J

    lower = np.concatenate((spec.lower, np.full(1 + n, -np.inf)))
    upper = np.concatenate((spec.upper, np.full(1 + n, np.inf)))
    if not np.all(np.isfinite(theta)):  # a pose the coupler never comes near: nothing to refine
        return None
    return refine(residual, jacobian, v0, lower, upper, lambda v: _linkage(spec, v, s0))


def _linkage(spec: SynthesisSpec, v: np.ndarray, s: float) -> Linkage | None:
    z, gamma, theta = v[:9], float(v[9]), v[10:]
    Z, S, T = z[None], np.array([s]), theta[None]
    if not np.all(np.isfinite(theta)) or causes(spec, Z, S, T)[0]:
        return None
    p = pose(Z, S, T)
    errors = np.linalg.norm(p.P[0] - spec.targets, axis=1)
    turns = np.abs(_turn(_coupler_angle(p)[0] + gamma - spec.angles))
    if not (np.all(np.isfinite(errors)) and np.all(np.isfinite(turns))):
        return None
    way, span = progress(T, spec.direction)
    low, high = transmission_range(Z, S, T, way, span)
    return Linkage(z.copy(), s, theta.copy(), int(way[0]), errors, (float(low[0]), float(high[0])),
                   grashof_label(z), task="motion", phi0=gamma, angle_errors=turns)
