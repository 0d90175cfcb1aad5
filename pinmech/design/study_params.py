"""A design study's parameters: named dimensions of a mechanism, their nominal values,
bounds and distributions, and where each one sits in the user's `pin.Model`.

A parameter is one component (x, y or z) of a placement's translation [m]:

- `joint = "A"`: the origin of joint A in its parent joint's frame (the URDF `<joint>`
  `<origin xyz>`): `model.jointPlacements[A].translation[k]`;
- `cut = "B"`, `side = "parent"` or `"child"`: the origin of a loop cut's frame on that
  side (the `<constraint>`'s `parent_origin` or `child_origin`): the frame's placement.

A variant is the same mechanism with these placements written in place: the compiled
core reads them at the next solve (CHANGELOG.md, round 3), nothing is rebuilt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

AXES = {"x": 0, "y": 1, "z": 2}
DISTRIBUTIONS = ("normal", "uniform", "fixed")


@dataclass(frozen=True)
class Parameter:
    """One named dimension of a study, in SI.

    Attributes:
        name: the study file's name for it (`[params.NAME]`).
        target: "joint" (a joint origin) or "cut" (a cut frame's origin).
        element: the joint's or the cut's name.
        side: "parent" or "child" for a cut, "" for a joint.
        component: 0, 1, 2 for x, y, z of the origin, in the frame it is written in.
        nominal: the nominal value [m], or None for the model's own.
        lower, upper: bounds [m] (a sampled value outside is a failed variant).
        distribution: "normal", "uniform" or "fixed".
        spread: the standard deviation [m] (normal) or the half width [m] (uniform).
    """

    name: str
    target: str
    element: str
    side: str
    component: int
    nominal: float | None = None
    lower: float = -math.inf
    upper: float = math.inf
    distribution: str = "fixed"
    spread: float = 0.0

    @property
    def sigma(self) -> float:
        """The standard deviation of the distribution [m] (a uniform's is w / sqrt 3)."""
        if self.distribution == "uniform":
            return self.spread / math.sqrt(3.0)
        return self.spread if self.distribution == "normal" else 0.0

    def sample(self, nominal: float, rng: np.random.Generator, n: int) -> np.ndarray:
        """n values drawn about `nominal` [m] from the parameter's distribution."""
        if self.distribution == "normal":
            return nominal + self.spread * rng.standard_normal(n)
        if self.distribution == "uniform":
            return nominal + self.spread * rng.uniform(-1.0, 1.0, n)
        return np.full(n, nominal)


class Placement:
    """Where a Parameter sits in a model: read and write its value, and the world
    direction a unit change moves its frame (for the closure's parameter Jacobian).

    Attributes:
        joint: the joint whose subtree moves rigidly when a joint origin changes, or the
            joint carrying the cut frame (then only that frame moves).
        frame: the cut frame's id, or -1 for a joint origin.
    """

    def __init__(self, model: pin.Model, joint: int, frame: int, component: int) -> None:
        self.model, self.joint, self.frame, self.component = model, joint, frame, component

    def read(self) -> float:
        """The placement's component now [m]."""
        return float(self._se3().translation[self.component])

    def write(self, value: float) -> None:
        """Write the component [m] into the model in place."""
        M = self._se3().copy()
        t = M.translation.copy()
        t[self.component] = value
        M.translation = t
        if self.frame < 0:
            self.model.jointPlacements[self.joint] = M
        else:
            self.model.frames[self.frame].placement = M

    def direction(self, data: pin.Data) -> np.ndarray:
        """World direction [m/m] a unit change moves what it moves (`data.oMi` up to date):
        the axis of the frame the origin is written in (the parent joint's, or the
        cut frame's joint)."""
        written_in = self.model.parents[self.joint] if self.frame < 0 else self.joint
        return np.array(data.oMi[written_in].rotation[:, self.component])

    def moves_frame(self, frame: int, subtree: dict[int, set[int]]) -> bool:
        """Whether a unit change translates `frame` (its joint in the moved subtree, or the
        cut frame itself)."""
        if self.frame >= 0:
            return frame == self.frame
        return self.model.frames[frame].parentJoint in subtree[self.joint]

    def _se3(self) -> pin.SE3:
        if self.frame < 0:
            return self.model.jointPlacements[self.joint]
        return self.model.frames[self.frame].placement


def subtrees(model: pin.Model) -> dict[int, set[int]]:
    """Joint id -> the joints of its subtree (itself included)."""
    below: dict[int, set[int]] = {j: {j} for j in range(model.njoints)}
    for j in range(model.njoints - 1, 0, -1):
        below[model.parents[j]] |= below[j]
    return below


def placements(mechanism, params: tuple[Parameter, ...], path: str) -> list[Placement]:
    """Each parameter's Placement in the mechanism's model.

    Raises:
        FrameNotFound: a joint or cut the model does not have (naming the study file).
    """
    from pinmech.exceptions import FrameNotFound

    found = []
    for p in params:
        if p.target == "joint":
            if p.element not in mechanism.joints:
                raise FrameNotFound("joint", p.element, list(mechanism.joints), path=f"{path}, params.{p.name}")
            found.append(Placement(mechanism.model, mechanism.joint(p.element).id, -1, p.component))
            continue
        cuts = {c.name: c for c in mechanism.closures}
        if p.element not in cuts:
            raise FrameNotFound("cut", p.element, list(cuts), path=f"{path}, params.{p.name}")
        cut = cuts[p.element]
        frame = cut.parent_frame if p.side == "parent" else cut.child_frame
        found.append(Placement(mechanism.model, mechanism.model.frames[frame].parentJoint, frame, p.component))
    return found
