"""A design study's parameters: named dimensions of a mechanism, their nominal values,
bounds and distributions, and where each one sits in the user's `pin.Model`.

A parameter is one component (x, y or z) of a placement's translation [m]:

- `joint = "A"`: the origin of joint A in its parent joint's frame (the URDF `<joint>`
  `<origin xyz>`, a robot.yaml model's URDF joints): `model.jointPlacements[A].translation[k]`;
- `body = "coupler"`: an MJCF body's `pos`, the origin of the one joint that moves it;
- `cut = "B"`, `side = "parent"` or `"child"`: the origin of a loop cut's frame on that
  side (the `<constraint>`'s `parent_origin` or `child_origin`, an MJCF `<connect>`'s
  anchor, a robot.yaml loop's frame): the frame's placement;
- `point = "P"`: a named point (a scene's, a URDF fixed link's, an MJCF site's) in its
  link: its frame, with the frames built at the same place (a fixed joint's, a robot.yaml
  loop's cut frame) and those hung below it.

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
        target: "joint" (a joint origin), "cut" (a cut frame's origin), "point" (a named
            point's place in its link) or "body" (an MJCF body's pos).
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
    direction a unit change moves its frames (for the closure's parameter Jacobian).

    Attributes:
        joint: the joint whose subtree moves rigidly when a joint origin changes, or the
            joint carrying the frames (then only those frames move).
        frames: the frames moved together (a cut frame; a named point with the frames
            built at it: a fixed link's, a sidecar cut's, those hung below it), or () for
            a joint origin.
    """

    drawn = False  # a translation component (drawn_params.DrawnPlacement: a drawn length)

    def __init__(self, model: pin.Model, joint: int, frames: tuple[int, ...], component: int) -> None:
        self.model, self.joint, self.frames, self.component = model, joint, tuple(frames), component
        # the model's own vectors (Boost.Python views, indexed afresh at each write: a frame
        # added to the model later moves their elements, not them)
        self._joint_placements, self._model_frames = model.jointPlacements, model.frames
        self.written_in = model.parents[joint] if not self.frames else joint  # whose axes the component is in

    def read(self) -> float:
        """The placement's component now [m] (the first frame's, for frames)."""
        return float(self._se3(self.frames[0] if self.frames else -1).translation[self.component])

    def write(self, value: float) -> None:
        """Write the component [m] into the model in place (frames: each moved by the same
        amount). Pinocchio 4's bindings hand `translation` as a view of the model's own SE3,
        so one component is written with no SE3 copied (tests/test_study_variant_writes.py)."""
        if not self.frames:
            self._joint_placements[self.joint].translation[self.component] = value
            return
        k = self.component
        views = [self._model_frames[f].placement.translation for f in self.frames]
        shift = value - float(views[0][k])
        for t in views:
            t[k] = float(t[k]) + shift

    def direction(self, data: pin.Data) -> np.ndarray:
        """World direction [m/m] a unit change moves what it moves (`data.oMi` up to date):
        the axis of the frame the origin is written in (the parent joint's, or the
        frames' joint)."""
        return np.array(data.oMi[self.written_in].rotation[:, self.component])

    def moves_frame(self, frame: int, subtree: dict[int, set[int]]) -> bool:
        """Whether a unit change translates `frame` (its joint in the moved subtree, or one
        of the moved frames)."""
        if self.frames:
            return frame in self.frames
        return self.model.frames[frame].parentJoint in subtree[self.joint]

    def _se3(self, frame: int) -> pin.SE3:
        return self.model.jointPlacements[self.joint] if frame < 0 else self.model.frames[frame].placement


def subtrees(model: pin.Model) -> dict[int, set[int]]:
    """Joint id -> the joints of its subtree (itself included)."""
    below: dict[int, set[int]] = {j: {j} for j in range(model.njoints)}
    for j in range(model.njoints - 1, 0, -1):
        below[model.parents[j]] |= below[j]
    return below


def placements(mechanism, params: tuple[Parameter, ...], path: str, scene=None) -> list:
    """Each parameter's Placement in the mechanism's model (a DrawnPlacement for a drawn
    linkage's param, drawn_params.py, which needs the scene).

    Raises:
        FrameNotFound: a joint, cut, point, body or param the model does not have (naming
            the study file and the parameter).
        SceneError: a param on a scene whose model is not a drawn linkage.
    """
    out, drawing = [], None
    for p in params:
        where = f"{path}, params.{p.name}"
        if p.target == "param":
            from pinmech.design.study.drawn_params import Drawing, DrawnPlacement

            drawing = drawing or Drawing(scene, mechanism, where)
            out.append(DrawnPlacement(drawing, p.element, where))
        else:
            out.append(_placement(mechanism, p, where))
    return out


def _placement(mechanism, p: Parameter, where: str) -> Placement:
    from pinmech.exceptions import FrameNotFound

    model = mechanism.model
    if p.target == "body":  # an MJCF body's pos: the origin of the one joint that moves it
        joints = [j for j in mechanism.joints.values() if j.child_link == p.element and j.kind != "other"]
        if len(joints) != 1:
            bodies = sorted({j.child_link for j in mechanism.joints.values() if j.kind != "other"})
            raise FrameNotFound("body with one joint", p.element, bodies, path=where)
        return Placement(model, joints[0].id, (), p.component)
    if p.target == "joint":
        if p.element not in mechanism.joints:
            raise FrameNotFound("joint", p.element, list(mechanism.joints), path=where)
        return Placement(model, mechanism.joint(p.element).id, (), p.component)
    if p.target == "point":
        if p.element not in mechanism.points:
            raise FrameNotFound("point", p.element, list(mechanism.points), path=where)
        frame = mechanism.points[p.element]
        return Placement(model, model.frames[frame].parentJoint, _frames_at(mechanism, frame), p.component)
    cuts = {c.name: c for c in mechanism.closures}
    if p.element not in cuts:
        raise FrameNotFound("cut", p.element, list(cuts), path=where)
    cut = cuts[p.element]
    frame = cut.parent_frame if p.side == "parent" else cut.child_frame
    return Placement(model, model.frames[frame].parentJoint, (frame,), p.component)


def _frames_at(mechanism, frame: int) -> tuple[int, ...]:
    """The frames that move with a named point: itself, the fixed-joint frames it was built
    from at the same place, the loop cut frames made there (a robot.yaml loop's), and every
    frame hung below them."""
    model, same = mechanism.model, {frame}
    joint, place = model.frames[frame].parentJoint, model.frames[frame].placement

    def at_point(f: int) -> bool:
        g = model.frames[f]
        return g.parentJoint == joint and g.type != pin.FrameType.JOINT and g.placement.isApprox(place, 1e-12)

    f = model.frames[frame].parentFrame
    while f not in same and at_point(f) and model.frames[f].type == pin.FrameType.FIXED_JOINT:
        same.add(f)
        f = model.frames[f].parentFrame
    same |= {i for c in mechanism.closures for i in (c.parent_frame, c.child_frame) if at_point(i)}
    grown = True
    while grown:
        below = {i for i in range(model.nframes) if model.frames[i].parentFrame in same and i not in same
                 and model.frames[i].type != pin.FrameType.JOINT}
        same |= below
        grown = bool(below)
    return tuple(sorted(same))
