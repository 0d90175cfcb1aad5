"""Whether a four-bar candidate's motion through the targets is free of defects, and meets
the synthesis file's constraints: the cause of its rejection, or "".

The crank turns from the first target's angle to the last's, one way, on one assembly s:

- **branch** defects cannot occur: every pose of a candidate is on its one s;
- **circuit** ("fold within the motion"): a fold of the dyad (fourbar.folds)
  between the first and the last target: the crank cannot carry the linkage through it;
- **order** ("targets out of order"): the crank angles of the targets do not progress
  one way (each step within one turn, all of them within one turn);
- "does not close" at a target, "transmission angle" below the least asked (never below
  MIN_TRANSMISSION: a dead point), "Grashof
  class" other than the one asked, "link ratio" above the one asked.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.kinematics import kinematics

#: Rejection causes, in the order they are checked.
CAUSES = ("does not close", "targets out of order", "fold within the motion", "Grashof class", "link ratio",
          "transmission angle")
_TWO_PI = 2 * math.pi
#: The least transmission angle ever accepted [rad], whatever the file asks: at 0 the
#: linkage is at a dead point (a fold), where the crank cannot drive it nor the engine solve it.
MIN_TRANSMISSION = math.radians(1.0)


def progress(theta: np.ndarray, direction: str) -> tuple[np.ndarray, np.ndarray]:
    """The way the crank turns (+1 ccw, -1 cw, 0 neither works) and the motion's span
    [rad] for crank angles theta (n, N) at the targets, in order."""
    steps = np.mod(np.diff(theta, axis=1), _TWO_PI)
    ccw_span = steps.sum(axis=1)
    ccw = np.all(steps > 0, axis=1) & (ccw_span < _TWO_PI)
    back = np.mod(-np.diff(theta, axis=1), _TWO_PI)
    cw_span = back.sum(axis=1)
    cw = np.all(back > 0, axis=1) & (cw_span < _TWO_PI)
    if direction == "ccw":
        cw = np.zeros_like(cw)
    elif direction == "cw":
        ccw = np.zeros_like(ccw)
    way = np.where(ccw, 1, np.where(cw, -1, 0))
    return way, np.where(way > 0, ccw_span, np.where(way < 0, cw_span, np.nan))


def within(angle: np.ndarray, start: np.ndarray, way: np.ndarray, span: np.ndarray) -> np.ndarray:
    """Whether angles (n, k) lie strictly inside the arcs from start (n,) turning `way`
    over `span` [rad] (NaN angles never do)."""
    off = np.mod(way[:, None] * (angle - start[:, None]), _TWO_PI)
    return (off > 0) & (off < span[:, None])


def transmission_range(z: np.ndarray, s: np.ndarray, theta: np.ndarray, way: np.ndarray,
                       span: np.ndarray, topology: str = "four-bar") -> tuple[np.ndarray, np.ndarray]:
    """The least and the greatest transmission angle mu [rad] over each motion. A four-bar's
    mu follows D = |A O4| alone, which is monotonic in cos(theta - g) between theta = g and
    g + pi (a slider-crank's, the distance of A from the slide, in sin(theta - slide)):
    its extremes are at the motion's ends or at g, g + pi when the crank passes them."""
    k = kinematics(topology)
    g = k.ground_angle(z)
    extra = np.stack((g, g + math.pi), -1)
    inside = within(extra, theta[:, 0], way, span)
    at = np.concatenate((theta[:, :1], theta[:, -1:], np.where(inside, extra, theta[:, :1])), axis=1)
    mu = k.pose(z, s, at).mu
    return mu.min(axis=1), mu.max(axis=1)


def causes(spec: SynthesisSpec, z: np.ndarray, s: np.ndarray, theta: np.ndarray) -> list[str]:
    """Each candidate's rejection cause ("" if none): z (n, 9), s (n,), the crank angles
    at the targets theta (n, N) [rad]."""
    k = kinematics(spec.topology)
    closes = k.pose(z, s, theta).closes.all(axis=1)
    way, span = progress(theta, spec.direction)
    fold_angles, _ = k.folds(z)
    crosses = within(fold_angles, theta[:, 0], way, np.nan_to_num(span)).any(axis=1)
    mu_low, mu_high = transmission_range(z, s, theta, np.where(way == 0, 1, way), np.nan_to_num(span),
                                         spec.topology)
    quality = np.minimum(mu_low, math.pi - mu_high)
    out = []
    for i in range(len(z)):
        out.append("does not close" if not closes[i] else "targets out of order" if way[i] == 0
                   else "fold within the motion" if crosses[i] else _shape(spec, z[i])
                   or ("transmission angle" if quality[i] < max(spec.transmission, MIN_TRANSMISSION) else ""))
    return out


def grashof_label(z: np.ndarray, topology: str = "four-bar") -> str:
    """The Grashof class of one candidate (a slider-crank's: "crank" or "rocker")."""
    return kinematics(topology).label(z)


def _shape(spec: SynthesisSpec, z: np.ndarray) -> str:
    """"Grashof class" or "link ratio" where the candidate's lengths break them, else ""."""
    if spec.grashof != "any":
        label = grashof_label(z, spec.topology)
        grashof = label not in ("triple rocker",)
        if not (label == spec.grashof or (spec.grashof == "grashof" and grashof)):
            return "Grashof class"
    if math.isfinite(spec.ratio):
        lengths = kinematics(spec.topology).lengths(z)
        if max(lengths) > spec.ratio * min(lengths):
            return "link ratio"
    return ""
