"""Watt and Stephenson six-bar synthesis on the engine (engine.py): path
generation (a coupler point of the last dyad through the targets, with or without timing),
function generation (the output link's turns against the crank's) and motion generation
(a link through poses: its point's place and its angle, with or without timing).

A search row is x = (p[, theta0][, gamma]): the free params p [m] (spec.free), with timing
(or for a function) the crank's value theta0 at the first target [rad], and for a motion
the angle gamma from the link's x axis to the poses' line [rad]. A motion's objective is
the four-bar motion's (poses.py): sum |P - T_i|^2 / S^2 + 2 (1 - cos(phi + gamma
- angle_i)), S the targets' extent, so an angle error e counts as a place error S e. Each candidate is
drawn, written into the model and followed by the compiled core over the crank's range (a
whole turn unless the template scene's [sweep] gives from .. to), on that one assembly (a fold, a change point or another assembly
at the start is its cause of rejection). Then, along that one continuation:

- without timing, each target's crank value is where the coupler curve passes nearest it
  (the nearest of the range's poses, then the vertex of the parabola through it and its
  neighbours); **order** ("targets out of order"): those values must progress one way,
  within one turn (motion.progress), as the four-bar's;
- with timing (a function's pairs), the crank values theta0 + turns are followed exactly;
- "transmission angle": the least transmission angle of the dyads spec.pins over the
  motion (the poses of the turn between the first and the last target, and the targets').

The refinement (least squares, bounds kept, refine.refine) moves p and the crank
values with the exact Jacobian: d(output)/dp by the implicit-function theorem on the loop
equations (sensitivity.output_sensitivity; the drawing's own change by its central
differences, drawn_params.py), d(output)/dtheta from the follow's tangent dq/dtheta.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.engine import EngineTemplate, template
from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.motion import MIN_TRANSMISSION, progress, within
from pinmech.design.synthesis.objective import REJECTED, BatchValues, extent
from pinmech.design.synthesis.refine import refine
from pinmech.design.synthesis.result import Linkage
from pinmech.exceptions import PinmechError

_TWO_PI = 2 * math.pi
FULL_TURN = "crank turns fully"  # a six-bar's class: the follow has taken the crank round a whole turn


def _timed(spec: SynthesisSpec) -> bool:
    return spec.timing is not None or spec.task == "function"


def _turns(spec: SynthesisSpec) -> np.ndarray:
    """The crank's turns from the first target [rad]: the timing, or the pairs' first column."""
    return spec.targets[:, 0] if spec.task == "function" else spec.timing


def sixbar_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The bounds of a search row: the free params', theta0's when timed, gamma's for a motion."""
    turn = [(-math.pi, math.pi)]
    return [*zip(spec.lower.tolist(), spec.upper.tolist()), *(turn if _timed(spec) else []),
            *(turn if spec.task == "motion" else [])]


def _gamma(spec: SynthesisSpec, x: np.ndarray) -> float:
    """A motion row's gamma (its last column) [rad]; 0 for the other tasks."""
    return float(x[-1]) if spec.task == "motion" else 0.0


def evaluate_sixbar(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The objective of search rows x (n, width) on the drawn assembly (`assembly` unused:
    the drawing's sides fix it), row by row: the same numbers however rows are batched."""
    t = template(spec)
    rows = [_row(spec, t, r) for r in np.atleast_2d(np.asarray(x, dtype=float))]
    return BatchValues(np.array([r[0] for r in rows]), [r[1] for r in rows], np.array([r[2] for r in rows]))


def _row(spec: SynthesisSpec, t: EngineTemplate, x: np.ndarray) -> tuple[float, str, np.ndarray]:
    """One row's objective, cause ("" if accepted) and crank values at the targets [rad]."""
    n = len(spec.free)
    none = np.full(len(spec.targets), np.nan)
    cause = t.write(x[:n])
    if cause:
        return REJECTED, cause, none
    if not _timed(spec):
        Q, _, cause = t.follow(t.grid)
        if cause:
            return REJECTED, cause, none
        Y = t.values(Q)
        theta, err2 = _nearest(t.grid[:t.poses], _distances2(spec, Y[:t.poses], _gamma(spec, x)), t.full)
        return _judged(spec, t, theta, err2, t.grid[:t.poses], Y[:t.poses])
    theta = x[n] + _turns(spec)
    motion = check_motion(spec, t, theta, _gamma(spec, x))
    if isinstance(motion, str):
        return REJECTED, motion, none
    err2, grid_y = motion
    return _judged(spec, t, theta, err2, t.grid[:t.poses], grid_y)


def check_motion(spec: SynthesisSpec, t: EngineTemplate, theta: np.ndarray,
                 gamma: float = 0.0) -> str | tuple[np.ndarray, np.ndarray]:
    """The linkage now written followed over its range and through the crank values theta
    (N,) [rad]: the cause where it fails, else each target's squared error (relative to
    the targets' extent for a path, with a motion's angle term at gamma [rad]; [rad^2] for
    a function's turns) and the outputs at the range's grid poses."""
    mapped = t.mapped(theta)
    if np.any(np.isnan(mapped)):
        return "target outside the crank's range"
    values, at, grid_at = _merged(t, mapped)
    Q, _, cause = t.follow(values)
    if cause:
        return cause
    Y = t.values(Q)
    return _errors2(spec, Y[at, :t.width], gamma), Y[grid_at[:t.poses]]


def _merged(t: EngineTemplate, mapped: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The follow's values: the range's grid and the crank values `mapped` into it
    (EngineTemplate.mapped), increasing [rad]; where theirs and the grid's are among them."""
    both = np.concatenate((t.grid, mapped))
    order = np.argsort(both, kind="stable")
    where = np.empty(len(both), dtype=int)
    where[order] = np.arange(len(both))
    return both[order], where[len(t.grid):], where[:len(t.grid)]


def _errors2(spec: SynthesisSpec, y: np.ndarray, gamma: float = 0.0) -> np.ndarray:
    """Squared errors at the targets of outputs y (N, width): the point's distance over the
    targets' extent (a motion's: with its angle term at gamma [rad]), or the output's turn
    from the first pair against the pair's [rad]."""
    if spec.task == "function":
        return _wrapped(y[:, 0] - y[0, 0] - spec.targets[:, 1]) ** 2
    return np.diag(_distances2(spec, y, gamma))


def _distances2(spec: SynthesisSpec, Y: np.ndarray, gamma: float) -> np.ndarray:
    """(N, M): each target's squared distance from the outputs Y (M, width) at M poses:
    |P - T|^2 / S^2, and for a motion + 2 (1 - cos(phi + gamma - angle)) (poses)."""
    d2 = ((Y[None, :, :2] - spec.targets[:, None, :]) ** 2).sum(-1) / extent(spec.targets) ** 2
    if spec.task == "motion":
        d2 = d2 + 2 * (1 - np.cos(Y[None, :, 2] + gamma - spec.angles[:, None]))
    return d2


def _wrapped(a: np.ndarray) -> np.ndarray:
    return np.mod(a + math.pi, _TWO_PI) - math.pi


def _nearest(grid: np.ndarray, d2: np.ndarray, wrap: bool) -> tuple[np.ndarray, np.ndarray]:
    """Each target's crank value where the curve over the range's grid (M,) passes nearest
    it [rad], and the squared distance there (d2 (N, M): _distances2; the parabola's vertex
    through the nearest pose's and its neighbours'; wrap: the grid is a whole turn, its
    first pose the last's neighbour)."""
    M, step = len(grid), grid[1] - grid[0]
    k = np.argmin(d2, axis=1)
    rows = np.arange(len(d2))
    fm, f0, fp = d2[rows, (k - 1) % M], d2[rows, k], d2[rows, (k + 1) % M]
    curve = fm - 2 * f0 + fp
    ok = (curve > 0) & (wrap | ((k > 0) & (k < M - 1)))
    shift = np.where(ok, np.clip(0.5 * (fm - fp) / np.where(ok, curve, 1.0), -0.5, 0.5), 0.0)
    vertex = np.where(ok, f0 - 0.5 * shift * (fm - fp) / 2, f0)
    return grid[k] + shift * step, np.maximum(vertex, 0.0)


def _judged(spec: SynthesisSpec, t: EngineTemplate, theta: np.ndarray, err2: np.ndarray, grid: np.ndarray,
            grid_y: np.ndarray) -> tuple[float, str, np.ndarray]:
    """The objective, the order and transmission causes, and theta."""
    way, span = progress(theta[None], spec.direction)
    if way[0] == 0:
        return REJECTED, "targets out of order", theta
    low, _ = transmission(spec, t, theta, way, span, grid, grid_y)
    if low < max(spec.transmission, MIN_TRANSMISSION if spec.pins else 0.0):
        return REJECTED, "transmission angle", theta
    return float(err2.sum()), "", theta


def transmission(spec: SynthesisSpec, t: EngineTemplate, theta: np.ndarray, way: np.ndarray, span: np.ndarray,
                 grid: np.ndarray, grid_y: np.ndarray) -> tuple[float, float]:
    """The least and greatest transmission angle (its distance from 0 and 180 deg) of the
    dyads spec.pins over the turn's poses within the motion [rad]; (90, 90) deg without pins."""
    if not spec.pins:
        return math.pi / 2, math.pi / 2
    inside = within(grid[None], theta[:1], way, span)[0]
    mu = grid_y[inside, t.width:]
    quality = np.minimum(mu, math.pi - mu)
    return (float(quality.min()), float(quality.max())) if len(mu) else (math.pi / 2, math.pi / 2)


def refined_sixbar(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> Linkage | None:
    """Row x refined by least squares with the exact Jacobian (bounds kept), or x itself if
    the refined one has a defect; None if neither is free of them (checked again by
    `sixbar_linkage` over the whole turn)."""
    t, n = template(spec), len(spec.free)
    theta = _row(spec, t, x)[2]
    if not np.all(np.isfinite(theta)):
        return None
    timed, motion = _timed(spec), spec.task == "motion"
    v0 = np.concatenate((x[:n], x[n:n + 1] if timed else theta, x[-1:] if motion else []))
    S = extent(spec.targets) if spec.task != "function" else 1.0
    scale = np.array([S, S, 1.0]) if motion else np.full(t.width, S)  # a motion's angle row in rad
    end = len(v0) - 1 if motion else len(v0)  # the crank's columns end before gamma

    def unpack(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        return v[:n], (v[n] + _turns(spec)) if timed else v[n:end], float(v[-1]) if motion else 0.0

    def poses(v: np.ndarray):
        p, th, _ = unpack(v)
        if t.write(p):
            return None
        mapped = t.mapped(th)
        if np.any(np.isnan(mapped)):
            return None
        order = np.argsort(mapped, kind="stable")
        Q, D1, cause = t.follow(mapped[order])
        if cause:
            return None
        back = np.empty_like(order)
        back[order] = np.arange(len(order))
        return Q[back], D1[back]

    def residual(v: np.ndarray) -> np.ndarray:
        at = poses(v)
        if at is None:  # a fold or an open loop on the way: a step refused
            return np.ones(len(spec.targets) * t.width)
        y = t.values(at[0])[:, :t.width]
        if spec.task == "path":
            return ((y - spec.targets) / S).ravel()
        if motion:
            turn = _wrapped(y[:, 2] + unpack(v)[2] - spec.angles)
            return np.column_stack(((y[:, :2] - spec.targets) / S, turn)).ravel()
        return _wrapped(y[:, 0] - y[0, 0] - spec.targets[:, 1])

    def jacobian(v: np.ndarray) -> np.ndarray:
        at = poses(v)
        if at is None:
            raise np.linalg.LinAlgError("the candidate does not follow its motion")
        try:
            parts = [t.jacobians(q, d1) for q, d1 in zip(*at)]
        except PinmechError as exc:  # a pose too ill-conditioned, a drawing at p +- h that does not close
            raise np.linalg.LinAlgError(str(exc)) from exc
        N = len(parts)
        J = np.zeros((N, t.width, len(v)))
        for i, (dp, dth) in enumerate(parts):
            J[i, :, :n] = dp
            J[i, :, n if timed else n + i] = dth
        if spec.task == "function":
            J = J - J[:1]
        J = J / scale[None, :, None]
        if motion:
            J[:, 2, -1] = 1.0  # d(phi + gamma - angle)/d gamma
        return J.reshape(N * t.width, -1)

    lower = np.concatenate((spec.lower, np.full(len(v0) - n, -np.inf)))  # theta0 or thetas, gamma: free
    upper = np.concatenate((spec.upper, np.full(len(v0) - n, np.inf)))
    return refine(residual, jacobian, v0, lower, upper, lambda v: sixbar_linkage(spec, *unpack(v)))


def sixbar_linkage(spec: SynthesisSpec, p: np.ndarray, theta: np.ndarray, gamma: float = 0.0) -> Linkage | None:
    """The Linkage of free params p [m] with crank values theta at the targets [rad] (and a
    motion's gamma [rad]), or None where its turn has a defect or its motion breaks a
    constraint."""
    t = template(spec)
    if not np.all(np.isfinite(theta)) or t.write(p):
        return None
    motion = check_motion(spec, t, theta, gamma)
    if isinstance(motion, str):
        return None
    err2, grid_y = motion
    way, span = progress(theta[None], spec.direction)
    if way[0] == 0:
        return None
    low, high = transmission(spec, t, theta, way, span, t.grid[:t.poses], grid_y)
    if low < max(spec.transmission, MIN_TRANSMISSION if spec.pins else 0.0):
        return None
    scale = extent(spec.targets) if spec.task == "path" else 1.0
    values, at, _ = _merged(t, t.mapped(theta))
    phi0, errors, turns = gamma, np.sqrt(err2) * scale, None
    if spec.task != "path":
        Q, _, _ = t.follow(values)
        y = t.values(Q[at])
        if spec.task == "function":
            phi0 = float(y[0, 0])
        else:  # a motion: the place's error [m] and the angle's [rad] apart
            errors = np.linalg.norm(y[:, :2] - spec.targets, axis=1)
            turns = np.abs(_wrapped(y[:, 2] + gamma - spec.angles))
    params = {**t.template, **{k: float(v) for k, v in zip(spec.free, p)}}
    return Linkage(np.array(p, dtype=float), 1.0, np.array(theta, dtype=float), int(way[0]), errors,
                   (low, high), FULL_TURN, task=spec.task, phi0=phi0, angle_errors=turns, topology=spec.topology,
                   params=params)
