"""Refining a path-generation candidate: least squares on the targets with the exact
Jacobian (implicit-function theorem, fourbar.point_jacobian), then the defect
and constraint checks again (motion.causes)."""

from __future__ import annotations

import numpy as np

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.kinematics import kinematics
from pinmech.design.synthesis.motion import causes, grashof_label, progress, transmission_range
from pinmech.design.synthesis.objective import evaluate_path, extent, split
from pinmech.design.synthesis.refine import refine
from pinmech.design.synthesis.result import Linkage


def refined_path(spec: SynthesisSpec, s0: float, x: np.ndarray) -> Linkage | None:
    """The candidate x on assembly s0 refined by least squares (bounds kept), or x itself
    if the refined one has a defect; None if neither is free of them."""
    k, width = kinematics(spec.topology), len(spec.lower)
    z, theta0 = split(x[None], width)
    theta = evaluate_path(spec, s0, x[None]).theta[0]
    timed = spec.timing is not None
    v0 = np.concatenate((z[0], theta0 if timed else theta))
    S = extent(spec.targets)

    def unpack(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return v[:width], (v[width] + spec.timing if timed else v[width:])

    def residual(v: np.ndarray) -> np.ndarray:
        zz, th = unpack(v)
        r = ((k.pose(zz[None], np.array([s0]), th[None]).P[0] - spec.targets) / S).ravel()
        return np.where(np.isfinite(r), r, 1.0)  # where the dyad does not close: a step refused

    def jacobian(v: np.ndarray) -> np.ndarray:
        zz, th = unpack(v)
        _, dz, dt = k.point_jacobian(zz, s0, th)
        n = len(th)
        Jt = np.zeros((n, 2, n))
        Jt[np.arange(n), :, np.arange(n)] = dt
        Jt = Jt.sum(axis=2, keepdims=True) if timed else Jt
        return np.concatenate((dz, Jt), axis=2).reshape(2 * n, -1) / S

    lower = np.concatenate((spec.lower, np.full(len(v0) - width, -np.inf)))
    upper = np.concatenate((spec.upper, np.full(len(v0) - width, np.inf)))
    return refine(residual, jacobian, v0, lower, upper, lambda v: _linkage(spec, *unpack(v), s0))


def _linkage(spec: SynthesisSpec, z: np.ndarray, theta: np.ndarray, s: float) -> Linkage | None:
    """The Linkage z on assembly s with crank angles theta at the targets, or None if its
    motion has a defect or breaks a constraint."""
    Z, Sa, T = z[None], np.array([s]), theta[None]
    if not np.all(np.isfinite(theta)) or causes(spec, Z, Sa, T)[0]:
        return None
    way, span = progress(T, spec.direction)
    low, high = transmission_range(Z, Sa, T, way, span, spec.topology)
    errors = np.linalg.norm(kinematics(spec.topology).pose(Z, Sa, T).P[0] - spec.targets, axis=1)
    return Linkage(z.copy(), s, np.array(theta), int(way[0]), errors, (float(low[0]), float(high[0])),
                   grashof_label(z, spec.topology), topology=spec.topology)
