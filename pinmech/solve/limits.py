"""Joint limits (URDF `<limit lower upper>`, MJCF `range`): which joints a solved pose puts beyond them.

pinmech solves the kinematics the drivers ask for; a pose that puts a joint beyond the
range its URDF gives is reported (text: a "Joint limits" section, JSON: "limit_violations"),
as a warning by default, or as a `LimitError` when asked (`--limits error`,
`[report] limits = "error"`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.exceptions import LimitError
from pinmech.model.mechanism import Mechanism
from pinmech.solve.motion import Motion

#: What to do about a joint beyond its limits.
LIMIT_MODES = ("warn", "error")


@dataclass(frozen=True)
class LimitViolation:
    """A joint at `value`, outside [lower, upper] (SI: rad or m)."""

    joint: str
    value: float
    lower: float
    upper: float
    angular: bool
    element: str = "URDF <limit>"

    def describe(self) -> str:
        """One phrase in the user's units, naming the element that states the limit:
        "B_slider = 0.183 m is above its upper limit 0.1 m (URDF <limit>)"."""
        side, bound = ("above its upper", self.upper) if self.value > self.upper else ("below its lower", self.lower)
        return (f"{self.joint} = {_format(self.value, self.angular)} is {side} limit "
                f"{_format(bound, self.angular)} ({self.element})")

    def as_dict(self) -> dict[str, float | str]:
        return {"joint": self.joint, "value": self.value, "lower": self.lower, "upper": self.upper}


def limit_violations(mechanism: Mechanism, motion: Motion) -> list[LimitViolation]:
    """The joints of a solved pose beyond their URDF limits, locked ones included (a margin
    of 1e-9, relative to the bound or absolute below 1, for the rounding of a closed loop)."""
    values = {n: j.q for n, j in motion.joints.items() if isinstance(j.q, float)}
    values |= {n: ball_angle(j.q) for n, j in motion.joints.items() if n in mechanism.limits and np.size(j.q) == 4}
    return _beyond(mechanism, values)


def limits_at(mechanism: Mechanism, q: np.ndarray) -> list[LimitViolation]:
    """The joints beyond their URDF limits at configuration q (an arm path's point)."""
    values = {n: mechanism.coordinate(q, n) for n in mechanism.limits
              if n in mechanism.mimics or (n in mechanism.joints and mechanism.joints[n].nv == 1)}
    for name in mechanism.limits:
        joint = mechanism.joints.get(name)
        if joint is not None and joint.nq == 4 and joint.nv == 3:
            values[name] = ball_angle(q[joint.idx_q: joint.idx_q + 4])
    return _beyond(mechanism, values)


def ball_angle(quaternion: np.ndarray) -> float:
    """The angle a ball joint has turned from its reference [rad, in 0..pi]: MuJoCo's
    limited ball joint keeps it below its range's upper bound. Pinocchio's order x y z w."""
    quaternion = np.asarray(quaternion, dtype=float)
    return float(2 * np.arctan2(np.linalg.norm(quaternion[:3]), abs(quaternion[3])))


def _beyond(mechanism: Mechanism, values: dict[str, float]) -> list[LimitViolation]:
    """The joints of `values` (and the locked ones) outside their limits."""
    out = []
    for name, limit in mechanism.limits.items():
        if name in mechanism.locked:  # held where the scene locks it
            value = mechanism.locked[name]
        elif name in values:
            value = values[name]
        else:
            continue
        margin = 1e-9 * max(1.0, abs(limit.lower), abs(limit.upper))
        if value < limit.lower - margin or value > limit.upper + margin:
            out.append(LimitViolation(name, value, limit.lower, limit.upper, limit.angular, limit.element))
    return out


def enforce(violations: list[LimitViolation], mode: str, where: str = "") -> None:
    """In mode "error", raise LimitError naming every violation; in "warn", nothing."""
    if mode not in LIMIT_MODES:
        raise LimitError(f"limits must be one of {', '.join(LIMIT_MODES)}, got {mode!r}", violations=[])
    if violations and mode == "error":
        said = "; ".join(v.describe() for v in violations)
        raise LimitError(f"{where}{': ' if where else ''}{said}", violations=violations)


def _format(x: float, angular: bool) -> str:
    return f"{math.degrees(x):.6g} deg" if angular else f"{x:.6g} m"
