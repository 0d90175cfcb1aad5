"""Motion generation of a four-bar, a slider-crank or an inverted slider-crank: the
coupler (the rod; the block) through N poses, its point P at each target place and its
angle at each target angle, in order.

A search row x = (z, gamma): the linkage (fourbar.NAMES, 9; slider.NAMES,
8; inverted.NAMES, 8) and the angle gamma [rad] from the carried link's angle (the
bar A -> B; the block's slot direction u, objective.carried_angle) to the line the
poses' angles are measured on. Each pose's
crank angle is where the coupler comes nearest the pose (objective.nearest_angles
with the angles); the objective is sum_i |P - T_i|^2 / S^2 + (1 - cos(phi3 + gamma -
angle_i)) * 2; defects and constraints as for paths. Refinement: least squares on the
places / S and the angles, with the exact Jacobians of P and phi3 (implicit-function theorem).
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.fourbar import link_angle_jacobian
from pinmech.design.synthesis.kinematics import kinematics
from pinmech.design.synthesis.motion import causes, grashof_label, progress, transmission_range
from pinmech.design.synthesis.objective import BatchValues, batch_values, carried_angle, extent, nearest_angles
from pinmech.design.synthesis.refine import refine
from pinmech.design.synthesis.result import Linkage


def poses_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The file's bounds of the linkage, and gamma over a turn."""
    return [*zip(spec.lower.tolist(), spec.upper.tolist()), (-math.pi, math.pi)]


def _turn(angle: np.ndarray) -> np.ndarray:
    return np.mod(angle + math.pi, 2 * math.pi) - math.pi


def evaluate_poses(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The objective of rows x (n, width + 1) on one assembly, row by row."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    w = len(spec.lower)
    z, gamma = x[:, :w], x[:, w]
    s = np.full(len(z), float(assembly))
    theta = nearest_angles(z, s, spec.targets, spec.angles, gamma, spec.topology)
    at = np.nan_to_num(theta)
    p = kinematics(spec.topology).pose(z, s, at)
    d2 = ((p.P - spec.targets[None]) ** 2).sum(-1) / extent(spec.targets) ** 2
    d2 = d2 + 2 * (1 - np.cos(carried_angle(spec.topology, p, z, s, at) + gamma[:, None] - spec.angles[None]))
    found = causes(spec, z, s, np.nan_to_num(theta))
    return batch_values(found, d2, theta)


def refined_poses(spec: SynthesisSpec, s0: float, x: np.ndarray) -> Linkage | None:
    """The row x on assembly s0 refined by least squares (bounds kept), or x itself if the
    refined one has a defect; None if neither is free of them."""
    theta = evaluate_poses(spec, s0, x[None]).theta[0]
    n, S, w, k = len(spec.targets), extent(spec.targets), len(spec.lower), kinematics(spec.topology)
    v0 = np.concatenate((x, theta))

    def residual(v: np.ndarray) -> np.ndarray:
        z, s, th = v[None, :w], np.array([s0]), v[None, w + 1:]
        p = k.pose(z, s, th)
        phi = carried_angle(spec.topology, p, z, s, th)[0]
        r = np.concatenate((((p.P[0] - spec.targets) / S).ravel(), _turn(phi + v[w] - spec.angles)))
        return np.where(np.isfinite(r), r, 1.0)

    def jacobian(v: np.ndarray) -> np.ndarray:
        _, dPz, dPt = k.point_jacobian(v[:w], s0, v[w + 1:])
        dphz, dpht = _coupler_jacobian(spec.topology, v[:w], s0, v[w + 1:])
        J = np.zeros((3 * n, w + 1 + n))
        J[:2 * n, :w] = dPz.reshape(2 * n, w) / S
        J[:2 * n, w + 1:] = (dPt[:, :, None] * np.eye(n)[:, None, :]).reshape(2 * n, n) / S
        J[2 * n:, :w], J[2 * n:, w], J[2 * n:, w + 1:] = dphz, 1.0, np.diag(dpht)
        return J

    lower = np.concatenate((spec.lower, np.full(1 + n, -np.inf)))
    upper = np.concatenate((spec.upper, np.full(1 + n, np.inf)))
    if not np.all(np.isfinite(theta)):  # a pose the coupler never comes near: nothing to refine
        return None
    return refine(residual, jacobian, v0, lower, upper, lambda v: _linkage(spec, v, s0))


def _coupler_jacobian(topology: str, z: np.ndarray, s: float, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """d(the carried link's angle)/dz (m, width) [rad/m] and /dtheta (m,): the four-bar's
    coupler (fourbar.link_angle_jacobian), the slider-crank's rod
    (slider.loop_jacobian's first row) or the inverted slider-crank's block, which
    turns with its guide (inverted.guide_jacobian)."""
    if topology == "inverted-slider-crank":
        from pinmech.design.synthesis.inverted import guide_jacobian

        return guide_jacobian(z, s, theta)[1:]
    if topology == "slider-crank":
        from pinmech.design.synthesis.slider import loop_jacobian

        _, dq_z, dq_t = loop_jacobian(z, s, theta)
        return dq_z[:, 0, :], dq_t[:, 0]
    return link_angle_jacobian(z, s, theta, 0)[1:]


def _linkage(spec: SynthesisSpec, v: np.ndarray, s: float) -> Linkage | None:
    w = len(spec.lower)
    z, gamma, theta = v[:w], float(v[w]), v[w + 1:]
    Z, S, T = z[None], np.array([s]), theta[None]
    if not np.all(np.isfinite(theta)) or causes(spec, Z, S, T)[0]:
        return None
    p = kinematics(spec.topology).pose(Z, S, T)
    errors = np.linalg.norm(p.P[0] - spec.targets, axis=1)
    turns = np.abs(_turn(carried_angle(spec.topology, p, Z, S, T)[0] + gamma - spec.angles))
    if not (np.all(np.isfinite(errors)) and np.all(np.isfinite(turns))):
        return None
    way, span = progress(T, spec.direction)
    low, high = transmission_range(Z, S, T, way, span, spec.topology)
    return Linkage(z.copy(), s, theta.copy(), int(way[0]), errors, (float(low[0]), float(high[0])),
                   grashof_label(z, spec.topology), task="motion", phi0=gamma, angle_errors=turns,
                   topology=spec.topology)
