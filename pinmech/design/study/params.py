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
        kind: "length", or "angle" for a drawn linkage's param written in deg (then every
            value above is in rad).
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
    kind: str = "length"  # or "angle": a drawn linkage's angle param (values in rad)

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

    Pinocchio stores a placement in its carrying joint's frame, composed with the frames
    it hangs from (a URDF fixed link turned on another, an MJCF jointless body with its
    quat, a joint's `pos`); the value is read and written in the frame the file writes
    it in: `value = axes^T (t - origin)`, t the stored translation.

    Attributes:
        joint: the joint whose subtree moves rigidly when a joint origin changes, or the
            joint carrying the frames (then only those frames move).
        frames: the frames moved together (a cut frame; a named point with the frames
            built at it: a fixed link's, a sidecar cut's, those hung below it), or () for
            a joint origin.
        written_in: the joint whose body carries what moves (rate_sensitivity.py).
        axes, origin: the writing frame's axes (3, 3) and origin (3,) [m] in written_in's frame.
    """

    drawn = False  # a translation component (drawn_params.DrawnPlacement: a drawn length)
    kind = "length"

    def __init__(self, model: pin.Model, joint: int, frames: tuple[int, ...], component: int,
                 writing: pin.SE3 | None = None) -> None:
        self.model, self.joint, self.frames, self.component = model, joint, tuple(frames), component
        # the model's own vectors (Boost.Python views, indexed afresh at each write: a frame
        # added to the model later moves their elements, not them)
        self._joint_placements, self._model_frames = model.jointPlacements, model.frames
        self.written_in = model.parents[joint] if not self.frames else joint  # whose axes the component is in
        writing = pin.SE3.Identity() if writing is None else writing
        self.axes, self.origin = np.array(writing.rotation), np.array(writing.translation)

    def read(self) -> float:
        """The placement's component now [m], in the frame it is written in (the first
        frame's, for frames)."""
        t = self._se3(self.frames[0] if self.frames else -1).translation
        return float(self.axes[:, self.component] @ (np.asarray(t) - self.origin))

    def write(self, value: float) -> None:
        """Write the component [m] into the model in place (frames: each moved by the same
        amount, along the writing frame's axis). Pinocchio 4's bindings hand `translation`
        as a view of the model's own SE3, so it is written with no SE3 copied
        (tests/test_study_variant_writes.py)."""
        k, axis = self.component, self.axes[:, self.component]
        if not self.frames:
            views = [self._joint_placements[self.joint].translation]
        else:
            views = [self._model_frames[f].placement.translation for f in self.frames]
        if axis[k] == 1.0:  # written in axes parallel to the stored ones: the component itself, exactly
            shift = float(self.origin[k]) + value - float(views[0][k])
            for t in views:
                t[k] = float(t[k]) + shift
            views[0][k] = float(self.origin[k]) + value
            return
        shift = (value - self.read()) * axis
        for t in views:
            for i in np.flatnonzero(shift):
                t[i] = float(t[i]) + float(shift[i])

    def direction(self, data: pin.Data) -> np.ndarray:
        """World direction [m/m] a unit change moves what it moves (`data.oMi` up to date):
        the writing frame's axis, carried by the joint whose body holds it."""
        return np.array(data.oMi[self.written_in].rotation @ self.axes[:, self.component])

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
            out.append(DrawnPlacement(drawing, p, where))
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
        return _joint_origin(model, joints[0].id, p.component, body=p.element)
    if p.target == "joint":
        if p.element not in mechanism.joints:
            raise FrameNotFound("joint", p.element, list(mechanism.joints), path=where)
        return _joint_origin(model, mechanism.joint(p.element).id, p.component)
    if p.target == "point":
        if p.element not in mechanism.points:
            raise FrameNotFound("point", p.element, list(mechanism.points), path=where)
        frame = mechanism.points[p.element]
        frames = _frames_at(mechanism, frame)
        writing = mechanism.written_frames.get(("point", p.element)) or _writing_frame(model, _top_of(model, frame, frames))
        return Placement(model, model.frames[frame].parentJoint, frames, p.component, writing)
    cuts = {c.name: c for c in mechanism.closures}
    if p.element not in cuts:
        raise FrameNotFound("cut", p.element, list(cuts), path=where)
    cut = cuts[p.element]
    frame = cut.parent_frame if p.side == "parent" else cut.child_frame
    writing = mechanism.written_frames.get(("cut", p.element, p.side)) or _writing_frame(model, frame)
    return Placement(model, model.frames[frame].parentJoint, (frame,), p.component, writing)


def _joint_origin(model: pin.Model, joint: int, component: int, body: str = "") -> Placement:
    """A joint origin's Placement, written in its parent link's frame (the link the joint
    hangs from, which Pinocchio may have merged into the parent joint with a turn: a URDF
    fixed link, an MJCF jointless body or a joint's `pos`). For an MJCF `body`, the value
    is the body's pos: its frame's origin, which a joint `pos` sets off from the joint's."""
    frame = model.getFrameId(model.names[joint], pin.FrameType.JOINT)
    writing = _writing_frame(model, frame) if frame < model.nframes else pin.SE3.Identity()
    if body:
        own = next((f for f in model.frames if f.name == body and f.type == pin.FrameType.BODY
                    and f.parentJoint == joint), None)
        if own is not None:  # origin shifted by the body frame's offset on its joint [m]
            offset = model.jointPlacements[joint].rotation @ own.placement.translation
            writing = pin.SE3(writing.rotation, writing.translation - offset)
    return Placement(model, joint, (), component, writing)


def _writing_frame(model: pin.Model, frame: int) -> pin.SE3:
    """The placement [m] in `frame`'s joint of the frame it is written in: its parent frame,
    when that is on the same joint (a link's frame, a fixed link's turned one), else the
    joint's own (identity)."""
    parent = model.frames[frame].parentFrame
    if parent == frame or model.frames[parent].parentJoint != _carrier(model, frame):
        return pin.SE3.Identity()
    return pin.SE3(model.frames[parent].placement)


def _carrier(model: pin.Model, frame: int) -> int:
    """The joint a frame's placement is stored in: a JOINT frame's is its parent joint's."""
    f = model.frames[frame]
    return model.parents[f.parentJoint] if f.type == pin.FrameType.JOINT else f.parentJoint


def _top_of(model: pin.Model, frame: int, same: tuple[int, ...]) -> int:
    """The highest of a point's frames built at the same place (the fixed joint that made
    it): the one whose parent frame is not among them."""
    while model.frames[frame].parentFrame in same and model.frames[frame].parentFrame != frame:
        frame = model.frames[frame].parentFrame
    return frame


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
