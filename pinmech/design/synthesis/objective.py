"""The path-generation objective of a batch of four-bar (or slider-crank) candidates, for
the global search.

A search row x = (z (9)[, theta0]): the four-bar z (fourbar.NAMES) and with
timing the crank's angle theta0 [rad] at the first target; each search is on one assembly
s (B left (+1) or right (-1) of A -> O4). Without timing, each target's crank angle is where
the coupler curve passes nearest it: the nearest of `SAMPLES` crank angles over a turn,
then the vertex of the parabola through the squared distances there and at the two
neighbours. The objective is sum_i |P(theta_i) - T_i|^2 / S^2 (S: the targets' extent),
or `REJECTED` with the cause where the motion has a defect or breaks a constraint
(motion.causes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.design.synthesis.file import SAMPLES, SynthesisSpec
from pinmech.design.synthesis.kinematics import kinematics
from pinmech.design.synthesis.motion import causes

REJECTED = 1e3  # the objective of a rejected candidate: above any accepted one's


@dataclass(frozen=True)
class BatchValues:
    """A batch's objective values (n,), each rejected candidate's cause ("" if accepted) and
    the crank angles at the targets (n, N) [rad]."""

    values: np.ndarray
    causes: list[str]
    theta: np.ndarray


def batch_values(found: list[str], err2: np.ndarray, theta: np.ndarray) -> BatchValues:
    """The BatchValues of rows with causes found (n,), squared relative errors err2 (n, N)
    and crank angles theta (n, N) [rad]: "does not close" added where an error is not
    finite, the sum of err2 where accepted, else REJECTED."""
    found = [c or ("does not close" if not np.all(np.isfinite(err2[i])) else "") for i, c in enumerate(found)]
    values = np.array([REJECTED if c else float(err2[i].sum()) for i, c in enumerate(found)])
    return BatchValues(values, found, theta)


def extent(targets: np.ndarray) -> float:
    """S: the diagonal of the targets' bounding box [m], the scale of relative errors."""
    return float(np.linalg.norm(targets.max(axis=0) - targets.min(axis=0)))


def split(x: np.ndarray, width: int = 9) -> tuple[np.ndarray, np.ndarray]:
    """Search rows x (n, width [+ 1]) -> z (n, width), theta0 (n,) [rad] (0 without
    timing); width: the topology's parameters (9 for a four-bar, 8 for a slider-crank)."""
    theta0 = x[:, width] if x.shape[1] > width else np.zeros(len(x))
    return x[:, :width], theta0


def path_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The bounds of a search row: the file's, and with timing theta0."""
    timed = [(-math.pi, math.pi)] if spec.timing is not None else []
    return [*zip(spec.lower.tolist(), spec.upper.tolist()), *timed]


def carried_angle(topology: str, p, z: np.ndarray, s: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """The angle [rad] (n, m) of the link a motion carries, at the pose p of candidates z on
    assemblies s at crank angles theta (n, m): the bar A -> B (the four-bar's coupler, the
    slider-crank's rod), or the block's slot direction u (the inverted slider-crank's
    block, which turns with its guide)."""
    if topology == "inverted-slider-crank":
        return kinematics(topology).guide_angle(z, s, theta)
    return np.arctan2(p.B[..., 1] - p.A[..., 1], p.B[..., 0] - p.A[..., 0])


def nearest_angles(z: np.ndarray, s: np.ndarray, targets: np.ndarray, angles: np.ndarray | None = None,
                   gamma: np.ndarray | None = None, topology: str = "four-bar") -> np.ndarray:
    """Each target's crank angle (n, N) [rad] where the coupler curve on assembly s passes
    nearest it (NaN if the dyad closes nowhere). With the poses' angles (N,) [rad] and the
    candidates' offsets gamma (n,) [rad], nearest in pose: |P - T|^2 + S^2 |e(phi3 + gamma)
    - e(angle)|^2 (phi3 the carried link's angle, carried_angle; S the targets' extent)."""
    step = 2 * math.pi / SAMPLES
    grid = np.arange(SAMPLES) * step
    thetas = np.broadcast_to(grid, (len(z), SAMPLES))
    p = kinematics(topology).pose(z, s, thetas)
    px, py = p.P[..., 0], p.P[..., 1]  # (n, M)
    if angles is not None:
        lead = carried_angle(topology, p, z, s, thetas) + gamma[:, None]  # (n, M)
        weight = 2 * extent(targets) ** 2
    # One target at a time: (n, M) arrays, where (n, N, M) ones were allocated and faulted
    # in afresh at every call (the same arithmetic, element by element).
    theta = np.empty((len(z), len(targets)))
    for j, (tx, ty) in enumerate(targets):
        dx, dy = px - tx, py - ty
        d2 = dx * dx + dy * dy  # (n, M)
        if angles is not None:
            d2 += weight * (1 - np.cos(lead - angles[j]))
        d2[np.isnan(d2)] = np.inf
        theta[:, j] = _nearest_sample(d2) * step
    return theta


def _nearest_sample(d2: np.ndarray) -> np.ndarray:
    """Each row's least entry of squared distances d2 (n, M) over a closed turn of M samples,
    as a fractional sample index (n,): the parabola through it and its two neighbours (where
    all three are finite and curve upwards, the shift clipped to half a sample), NaN for a
    row with none finite."""
    k, rows, m = np.argmin(d2, axis=1), np.arange(len(d2)), d2.shape[1]
    f0, fm, fp = d2[rows, k], d2[rows, (k - 1) % m], d2[rows, (k + 1) % m]
    found = np.isfinite(f0)
    ok = np.isfinite(fm) & np.isfinite(fp) & found
    fm, f0, fp = (np.where(ok, f, 0.0) for f in (fm, f0, fp))
    curve = fm - 2 * f0 + fp
    ok &= curve > 0
    shift = np.where(ok, 0.5 * (fm - fp) / np.where(ok, curve, 1.0), 0.0)
    return np.where(found, k + np.clip(shift, -0.5, 0.5), np.nan)


def evaluate_path(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The objective of search rows x (n, width or width + 1) on one assembly (+1 or -1), row by row
    (the same numbers however the rows are split into batches)."""
    z, theta0 = split(np.atleast_2d(np.asarray(x, dtype=float)), len(spec.lower))
    s = np.full(len(z), float(assembly))
    if spec.timing is not None:
        theta = theta0[:, None] + spec.timing[None, :]
    else:
        theta = nearest_angles(z, s, spec.targets, topology=spec.topology)
    P = kinematics(spec.topology).pose(z, s, np.nan_to_num(theta)).P
    d2 = ((P - spec.targets[None]) ** 2).sum(-1) / extent(spec.targets) ** 2
    found = causes(spec, z, s, np.nan_to_num(theta))
    return batch_values(found, d2, theta)
