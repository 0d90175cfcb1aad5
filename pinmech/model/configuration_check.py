"""A configuration checked where it enters: finite numbers of the model's size, and every
quaternion or (cos, sin) pair of unit norm (pinmech never normalises one in silence)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.arguments import all_finite, float_array
from pinmech.exceptions import ModelError

_FLOAT64 = np.dtype(np.float64)  # numpy's one instance of it (an `is` test: no conversion)

#: A configuration's quaternions and (cos, sin) pairs must have a norm within this of 1
#: (Pinocchio's own `isNormalized` precision): Pinocchio reads a quaternion of norm n as a
#: rotation scaled by n^2, so a ball joint's rates came out wrong by that factor, silently.
#: Within it the rotation is off by at most 2e-12 (relative); pinmech never normalises.
UNIT_NORM_TOL = 1e-12
#: Joint types whose coordinates hold a unit quaternion or (cos, sin) pair: its slice of
#: the joint's coordinates and what it is called in an error.
_UNIT_PARTS = {
    "JointModelSpherical": (0, 4, "quaternion"),
    "JointModelFreeFlyer": (3, 7, "quaternion"),
    "JointModelPlanar": (2, 4, "(cos, sin) pair"),
    **{f"JointModelRUB{axis}": (0, 2, "(cos, sin) pair") for axis in "XYZ"},
    "JointModelRevoluteUnboundedUnaligned": (0, 2, "(cos, sin) pair"),
}


def unit_parts(model: pin.Model) -> list[tuple[str, int, int, str]]:
    """(joint, first, stop, what) of every unit quaternion or (cos, sin) pair in q."""
    parts = []
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        part = _UNIT_PARTS.get(joint.shortname())
        if part is not None:
            parts.append((model.names[jid], joint.idx_q + part[0], joint.idx_q + part[1], part[2]))
    return parts


def checked_configuration(q: Any, nq: int, parts: list[tuple[str, int, int, str]], name: str, many: bool,
                          source: str) -> np.ndarray:
    """q as a configuration (`many`: an (N, nq) array of them) whose `parts` have unit norm.

    Raises:
        ModelError: naming the argument and what it got (a non-unit quaternion: the
            joint and its norm).
    """
    if not many and type(q) is np.ndarray and q.dtype is _FLOAT64 and q.shape == (nq,):
        values = q.tolist()  # one pose (evaluate_motion, solve) as plain floats: no numpy call
        if all_finite(values) and _unit_norms(values, parts):
            return q
    out = float_array(q, name, (None, nq) if many else (nq,), source)
    rows = out if many else out[None]
    for joint, start, stop, what in parts:
        norms = np.sqrt(np.sum(rows[:, start:stop] ** 2, axis=1))
        bad = np.flatnonzero(~(np.abs(norms - 1.0) <= UNIT_NORM_TOL))
        if bad.size:
            at = f" (row {bad[0]})" if many else ""
            raise ModelError(f"{name}{at}: joint '{joint}' has a {what} of norm {norms[bad[0]]:.17g}, not 1 "
                             f"(within {UNIT_NORM_TOL:g}): normalise it (pinocchio.normalize(model, q)); "
                             "pinmech does not guess which rotation was meant", path=source)
    return out


def _unit_norms(values: list[float], parts: list[tuple[str, int, int, str]]) -> bool:
    """Whether every quaternion and (cos, sin) pair of one pose's `values` has unit norm."""
    for _, start, stop, _ in parts:
        if not abs(math.hypot(*values[start:stop]) - 1.0) <= UNIT_NORM_TOL:  # NaN fails too
            return False
    return True

