"""What a hand calculation reports, read off Pinocchio at a solved (q, v, a).

Positions, velocities and classical accelerations of named points; angular velocities
and accelerations of links; joint coordinates and rates; and for every prismatic joint
the relative (slider) velocity, acceleration and the Coriolis term 2 w_parent x v_rel.
All vectors are in the world frame, SI units.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.model.closures import _cross
from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.arguments import float_array
from pinmech.model.mechanism import Mechanism

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class PointMotion:
    """Position [m], velocity [m/s] and classical acceleration [m/s^2] of a point, world frame."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    link: str


@dataclass(frozen=True)
class LinkMotion:
    """Orientation, angular velocity [rad/s] and angular acceleration [rad/s^2] of a link.

    `angle` is the rotation about the mechanism's plane normal [rad] (planar mechanisms
    only, else None): the angle of the link's x axis, as a textbook's phi, measured in the
    plane. A link whose x axis is (nearly) normal to the plane has no such angle: its y
    axis is measured instead (its z axis if y is too), and `angle_axis` says which.
    """

    rotation: np.ndarray
    angular_velocity: np.ndarray
    angular_acceleration: np.ndarray
    angle: float | None
    angle_axis: str = "x"


@dataclass(frozen=True)
class JointMotion:
    """Coordinate [rad or m], rate and acceleration of a one-dof joint; arrays for a joint of
    several freedoms: a planar joint's (x [m], y [m], theta [rad]) and their rates, else
    Pinocchio's configuration (a quaternion for a spherical or floating joint) and its
    tangent rates (linear then angular, in the joint's frame)."""

    q: float | np.ndarray
    v: float | np.ndarray
    a: float | np.ndarray
    kind: str


@dataclass(frozen=True)
class SliderMotion:
    """Motion of a prismatic joint's (or prismatic cut's) child relative to its parent,
    world frame.

    Attributes:
        relative_velocity: velocity of the child's point relative to the parent [m/s].
        relative_acceleration: its acceleration seen from the parent [m/s^2].
        coriolis_acceleration: 2 w_parent x v_rel [m/s^2].
        axis: the slide's unit direction, world frame (the parent's axis for a cut).
        s: the child's position along `axis` [m]: a tree slider's coordinate, a cut's
            offset of the child's cut frame from the parent's.
        s_dot, s_ddot: its rate [m/s] and acceleration [m/s^2] seen from the parent
            (`relative_velocity` and `relative_acceleration` along `axis`).
    """

    parent: str
    child: str
    relative_velocity: np.ndarray
    relative_acceleration: np.ndarray
    coriolis_acceleration: np.ndarray
    axis: np.ndarray
    s: float
    s_dot: float
    s_ddot: float


@dataclass(frozen=True)
class CoincidentPoint:
    """A point of `link` that coincides with the named point `at` at this instant (e.g. B3)."""

    name: str
    at: str
    link: str


@dataclass(frozen=True)
class Motion:
    """Everything a report shows about one solved pose."""

    joints: dict[str, JointMotion]
    links: dict[str, LinkMotion]
    points: dict[str, PointMotion]
    sliders: dict[str, SliderMotion]


def evaluate_motion(
    mechanism: Mechanism,
    data: pin.Data,
    q: np.ndarray,
    v: np.ndarray,
    a: np.ndarray,
    *,
    points: Iterable[str] | None = None,
    coincident: Iterable[CoincidentPoint] = (),
    links: Iterable[str] | None = None,
) -> Motion:
    """Evaluate joints, links, points and sliders at (q, v, a).

    Args:
        mechanism: the model.
        data: a `pin.Data` of the model to work in (overwritten).
        points: named points or frames to report (default: all the URDF's points).
        coincident: points of a link coinciding with a named point (e.g. B3 on link 3).
        links: links to report (default: all that move).
    """
    model = mechanism.model
    for name, names in (("points", points), ("links", links)):
        if isinstance(names, (str, bytes)):
            raise ModelError(f"{name} must be a list of names, got the string {names!r}", path=mechanism.source)
    q = mechanism.checked_q(q)
    v, a = (_vector(x, model.nv, name, mechanism) for x, name in ((v, "v"), (a, "a")))
    if not isinstance(data, pin.Data) or len(data.oMi) != model.njoints or len(data.oMf) != model.nframes:
        raise ModelError("data must be a pin.Data of the mechanism's model (mechanism.model.createData())",
                         path=mechanism.source)
    pin.forwardKinematics(model, data, q, v, a)
    pin.updateFramePlacements(model, data)
    link_names = list(links) if links is not None else _moving_links(mechanism)
    link_motion = {n: _link_motion(mechanism, data, n) for n in link_names}
    point_names = list(points) if points is not None else list(mechanism.points)
    coincident = list(coincident)
    point_motion = {}
    for name in point_names:
        match = [c for c in coincident if c.name == name]
        point_motion[name] = _coincident(mechanism, data, match[0]) if match else _point(mechanism, data, name)
    for c in coincident:
        point_motion.setdefault(c.name, _coincident(mechanism, data, c))
    return Motion(
        joints=_joint_motions(mechanism, q, v, a),
        links=link_motion,
        points=point_motion,
        sliders=_sliders(mechanism, data, q, v, a),
    )


def _sliders(mechanism: Mechanism, data: pin.Data, q: np.ndarray, v: np.ndarray,
             a: np.ndarray) -> dict[str, SliderMotion]:
    """Every prismatic joint of the tree, and every prismatic loop cut (a drawn pin-in-slot
    is cut at its slide), by name."""
    out = {n: _slider(mechanism, data, n, mechanism.coordinate(q, n), float(v[j.idx_v]), float(a[j.idx_v]))
           for n, j in mechanism.joints.items() if j.kind == "prismatic"}
    for closure in mechanism.closures:
        if closure.cut_type == "prismatic" and closure.name not in out:
            out[closure.name] = _cut_slider(mechanism, data, closure)
    return out


def _cut_slider(mechanism: Mechanism, data: pin.Data, closure) -> SliderMotion:
    """The child cut frame's origin relative to the parent link (the slot), by the
    relative-motion formulas: v_rel = v_C - (v_P + w x r), a_rel = a_C - (a_P + alpha x r
    + w x (w x r)) - 2 w x v_rel, with r from the parent cut frame's origin to C's."""
    model = mechanism.model
    parent, child = closure.parent_frame, closure.child_frame
    r = data.oMf[child].translation - data.oMf[parent].translation
    vel_p = pin.getFrameVelocity(model, data, parent, _LWA)
    acc_p = pin.getFrameClassicalAcceleration(model, data, parent, _LWA)
    alpha = pin.getFrameAcceleration(model, data, parent, _LWA).angular
    w = vel_p.angular
    v_c = pin.getFrameVelocity(model, data, child, _LWA).linear
    a_c = pin.getFrameClassicalAcceleration(model, data, child, _LWA).linear
    v_rel = v_c - (vel_p.linear + _cross(w, r))
    coriolis = 2.0 * _cross(w, v_rel)
    a_rel = a_c - (acc_p.linear + _cross(alpha, r) + _cross(w, _cross(w, r))) - coriolis
    axis = data.oMf[parent].rotation @ closure.axis
    return SliderMotion(parent=closure.parent_link, child=closure.child_link, relative_velocity=v_rel,
                        relative_acceleration=a_rel, coriolis_acceleration=coriolis, axis=axis,
                        s=float(axis @ r), s_dot=float(axis @ v_rel), s_ddot=float(axis @ a_rel))


def _vector(x: Any, size: int, name: str, mechanism: Mechanism) -> np.ndarray:
    """x as `size` finite floats, else a ModelError naming the argument and what it got."""
    return float_array(x, name, (size,), mechanism.source)


def _joint_motions(mechanism: Mechanism, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> dict[str, JointMotion]:
    """Every one-dof joint's coordinate and rates; a `<mimic>` follower's from its leader's."""
    out = {}
    for name, joint in mechanism.joints.items():
        if name in mechanism.mimics:
            m = mechanism.mimics[name]
            leader = mechanism.joints[m.leader]
            kind = m.kind if m.kind in ("revolute", "continuous", "prismatic") else leader.kind
            out[name] = JointMotion(mechanism.coordinate(q, name), m.multiplier * float(v[leader.idx_v]),
                                    m.multiplier * float(a[leader.idx_v]), kind)
        elif joint.nv == 1:
            out[name] = JointMotion(mechanism.coordinate(q, name), float(v[joint.idx_v]), float(a[joint.idx_v]),
                                    joint.kind)
        elif joint.nv > 1:
            out[name] = _multi_dof(mechanism, joint.id, q, v, a)
    return out


_MULTI_DOF_KINDS = {"JointModelPlanar": "planar", "JointModelSpherical": "spherical",
                    "JointModelSphericalZYX": "spherical_zyx", "JointModelFreeFlyer": "floating",
                    "JointModelTranslation": "translation"}


def _multi_dof(mechanism: Mechanism, jid: int, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> JointMotion:
    """A joint of several freedoms; a planar joint's (cos, sin) pair becomes its angle."""
    joint = mechanism.model.joints[jid]
    kind = _MULTI_DOF_KINDS.get(joint.shortname(), "other")
    qj = q[joint.idx_q : joint.idx_q + joint.nq].copy()
    vj, aj = v[joint.idx_v : joint.idx_v + joint.nv].copy(), a[joint.idx_v : joint.idx_v + joint.nv].copy()
    if kind == "planar":
        qj = np.array([qj[0], qj[1], math.atan2(qj[3], qj[2])])
    return JointMotion(qj, vj, aj, kind)


def _moving_links(mechanism: Mechanism) -> list[str]:
    model = mechanism.model
    return [n for n, fid in mechanism.links.items() if model.frames[fid].parentJoint != 0]


def _point(mechanism: Mechanism, data: pin.Data, name: str) -> PointMotion:
    fid = mechanism.frame_id(name)
    model = mechanism.model
    return PointMotion(
        position=data.oMf[fid].translation.copy(),
        velocity=pin.getFrameVelocity(model, data, fid, _LWA).linear.copy(),
        acceleration=pin.getFrameClassicalAcceleration(model, data, fid, _LWA).linear.copy(),
        link=mechanism.link_of_frame(fid),
    )


def _link_motion(mechanism: Mechanism, data: pin.Data, name: str) -> LinkMotion:
    if name not in mechanism.links:
        raise FrameNotFound("link", name, list(mechanism.links), path=mechanism.source)
    fid = mechanism.links[name]
    model = mechanism.model
    rotation = data.oMf[fid].rotation.copy()
    angle, axis = _plane_angle(rotation, mechanism.plane_normal)
    return LinkMotion(
        rotation=rotation,
        angular_velocity=pin.getFrameVelocity(model, data, fid, _LWA).angular.copy(),
        angular_acceleration=pin.getFrameAcceleration(model, data, fid, _LWA).angular.copy(),
        angle=angle,
        angle_axis=axis,
    )


#: A link axis is measured in the plane when its projection on the plane is at least this
#: long (it is within 60 deg of the plane): its in-plane direction is then exact to
#: rounding. Of x, y and z one always qualifies (their squared projections add up to 2).
_IN_PLANE = 0.5


def _plane_angle(rotation: np.ndarray, normal: np.ndarray | None) -> tuple[float | None, str]:
    """Angle about the plane normal of the link's x axis (else y, else z: the first that
    lies within 60 deg of the plane), from the world x axis projected on the plane; and
    which axis was measured."""
    if normal is None:
        return None, "x"
    ref = _plane_reference(*normal.tolist())
    for k, name in enumerate("xyz"):
        axis = rotation[:, k]
        in_plane = axis - normal * float(normal @ axis)
        if math.hypot(*in_plane.tolist()) >= _IN_PLANE or name == "z":
            return math.atan2(float(normal @ _cross(ref, in_plane)), float(ref @ in_plane)), name
    raise AssertionError("unreachable")  # pragma: no cover


@functools.lru_cache(maxsize=8)
def _plane_reference(nx: float, ny: float, nz: float) -> np.ndarray:
    """The world x axis projected on the plane (the y axis when the normal is near x)."""
    normal = np.array((nx, ny, nz))
    ref = np.array([1.0, 0.0, 0.0]) if abs(nx) < 0.9 else np.array([0.0, 1.0, 0.0])
    ref = ref - normal * (normal @ ref)
    return ref / np.linalg.norm(ref)


def _coincident(mechanism: Mechanism, data: pin.Data, c: CoincidentPoint) -> PointMotion:
    """Motion of the material point of `c.link` that sits at point `c.at` now (rigid-body formulas)."""
    if c.link not in mechanism.links:
        raise FrameNotFound("link", c.link, list(mechanism.links), path=mechanism.source)
    model = mechanism.model
    fid = mechanism.links[c.link]
    at = data.oMf[mechanism.frame_id(c.at)].translation.copy()
    origin = data.oMf[fid].translation
    vel = pin.getFrameVelocity(model, data, fid, _LWA)
    acc = pin.getFrameClassicalAcceleration(model, data, fid, _LWA)
    spatial_acc = pin.getFrameAcceleration(model, data, fid, _LWA)
    r = at - origin
    w, alpha = vel.angular, spatial_acc.angular
    return PointMotion(
        position=at,
        velocity=vel.linear + _cross(w, r),
        acceleration=acc.linear + _cross(alpha, r) + _cross(w, _cross(w, r)),
        link=c.link,
    )


def _slider(mechanism: Mechanism, data: pin.Data, name: str, q: float, rate: float, accel: float) -> SliderMotion:
    """A tree slider from its coordinate q [m], rate [m/s] and acceleration [m/s^2]."""
    joint = mechanism.joint(name)
    model = mechanism.model
    axis_world = data.oMi[joint.id].rotation @ joint.axis
    parent_joint = model.parents[joint.id]
    omega_parent = data.oMi[parent_joint].rotation @ data.v[parent_joint].angular
    v_rel = rate * axis_world
    return SliderMotion(
        parent=joint.parent_link,
        child=joint.child_link,
        relative_velocity=v_rel,
        relative_acceleration=accel * axis_world,
        coriolis_acceleration=2.0 * _cross(omega_parent, v_rel),
        axis=axis_world,
        s=q,
        s_dot=rate,
        s_ddot=accel,
    )
