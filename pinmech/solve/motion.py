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

import numpy as np
import pinocchio as pin

from pinmech.arguments import float_array
from pinmech.exceptions import ModelError
from pinmech.directions import cross as _cross
from pinmech.model.mechanism import Mechanism
from pinmech.solve.core import _core
from pinmech.solve.motion_plan import MotionPlan, motion_plan
from pinmech.solve.results import frozen


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


class _built:
    """A Motion's dict, built on first reading and kept in the instance (functools'
    cached_property takes a lock on every first read in Python 3.11: microseconds here)."""

    def __init__(self, build) -> None:
        self.build, self.name = build, build.__name__
        self.__doc__ = build.__doc__

    def __get__(self, motion, owner=None):
        if motion is None:
            return self
        value = motion.__dict__[self.name] = self.build(motion)
        return value


class Motion:
    """Everything a report shows about one solved pose: `joints`, `links`, `points` and
    `sliders`, dicts by name of JointMotion, LinkMotion, PointMotion and SliderMotion. The
    numbers are computed when the pose is evaluated; each dict is built when first read."""

    def __init__(self, mechanism: Mechanism, plan: MotionPlan, rows: np.ndarray, q: list[float], v: list[float],
                 a: list[float]) -> None:
        self._mechanism, self._plan, self._rows = mechanism, plan, rows
        self._q, self._v, self._a = q, v, a

    @_built
    def joints(self) -> dict[str, JointMotion]:
        return _joint_motions(self._mechanism, self._q, self._v, self._a)

    @_built
    def links(self) -> dict[str, LinkMotion]:
        rows, plane, out = self._rows, self._plan.plane, {}
        for name, r in self._plan.links:  # a loop: a comprehension is one more function call
            out[name] = _link_motion(rows[r], plane)
        return out

    @_built
    def points(self) -> dict[str, PointMotion]:
        rows, out = self._rows, {}
        for name, r, at, link in self._plan.points:
            out[name] = _point(rows[r], link) if at is None else _coincident(rows[at], rows[r], link)
        return out

    @_built
    def sliders(self) -> dict[str, SliderMotion]:
        rows, q, v, a = self._rows, self._q, self._v, self._a
        out = {}
        for name, kind, item in self._plan.sliders:
            if kind == "joint":
                joint, r, parent = item
                out[name] = _slider(joint, rows[r], rows[parent] if parent is not None else None,
                                    self._mechanism.coordinate(q, name), v[joint.idx_v], a[joint.idx_v])
            else:
                closure, parent, child = item
                out[name] = _cut_slider(closure, rows[parent], rows[child])
        return out

    def __repr__(self) -> str:
        return (f"Motion(joints={list(self.joints)}, links={list(self.links)}, points={list(self.points)}, "
                f"sliders={list(self.sliders)})")


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
    """Evaluate joints, links, points and sliders at (q, v, a): Pinocchio's forward
    kinematics and every asked frame in one compiled call (csrc/kinematics.cpp).

    Args:
        mechanism: the model.
        data: a `pin.Data` of the model to work in (overwritten).
        points: named points or frames to report (default: all the URDF's points).
        coincident: points of a link coinciding with a named point (e.g. B3 on link 3).
        links: links to report (default: all that move).

    Raises:
        ModelError: q, v or a not configurations or rates of the model, or data not a
            pin.Data of its model.
        FrameNotFound: a point or link the model lacks.
    """
    if isinstance(points, (str, bytes)) or isinstance(links, (str, bytes)):
        name, names = ("points", points) if isinstance(points, (str, bytes)) else ("links", links)
        raise ModelError(f"{name} must be a list of names, got the string {names!r}", path=mechanism.source)
    q = mechanism.checked_q(q)
    nv = mechanism.model.nv
    v, a = float_array(v, "v", (nv,), mechanism.source), float_array(a, "a", (nv,), mechanism.source)
    plan = motion_plan(mechanism, None if points is None else tuple(points), tuple(coincident),
                       None if links is None else tuple(links), _plane)
    if not (q.flags.c_contiguous and v.flags.c_contiguous and a.flags.c_contiguous):  # the core reads them so
        q, v, a = np.ascontiguousarray(q), np.ascontiguousarray(v), np.ascontiguousarray(a)
    rows = np.empty((plan.rows, _core.KINEMATICS_COLUMNS))
    try:
        _core.frames_at(mechanism.model, data, q, v, a, plan.frames, plan.joints, rows)
    except (TypeError, ValueError):  # no pin.Data, or one of another model (the core checks both)
        raise ModelError("data must be a pin.Data of the mechanism's model (mechanism.model.createData())",
                         path=mechanism.source) from None
    return Motion(mechanism, plan, rows, q.tolist(), v.tolist(), a.tolist())  # as evaluated: q may change after


def _cut_slider(closure, parent: np.ndarray, child: np.ndarray) -> SliderMotion:
    """The child cut frame's origin relative to the parent link (the slot), by the
    relative-motion formulas: v_rel = v_C - (v_P + w x r), a_rel = a_C - (a_P + alpha x r
    + w x (w x r)) - 2 w x v_rel, with r from the parent cut frame's origin to C's.
    `parent`, `child`: the cut frames' rows of the core's answer."""
    r = child[0:3] - parent[0:3]
    w, alpha = parent[15:18], parent[21:24]
    v_rel = child[12:15] - (parent[12:15] + _cross(w, r))
    coriolis = 2.0 * _cross(w, v_rel)
    a_rel = child[18:21] - (parent[18:21] + _cross(alpha, r) + _cross(w, _cross(w, r))) - coriolis
    axis = parent[3:12].reshape(3, 3) @ closure.axis
    return frozen(SliderMotion, {"parent": closure.parent_link, "child": closure.child_link, "relative_velocity": v_rel,
                                 "relative_acceleration": a_rel, "coriolis_acceleration": coriolis, "axis": axis,
                                 "s": float(axis @ r), "s_dot": float(axis @ v_rel), "s_ddot": float(axis @ a_rel)})


def _joint_motions(mechanism: Mechanism, q: list[float], v: list[float], a: list[float]) -> dict[str, JointMotion]:
    """Every one-dof joint's coordinate and rates; a `<mimic>` follower's from its leader's."""
    out, mimics = {}, mechanism.mimics
    for name, joint in mechanism.joints.items():
        if name in mimics:
            m = mimics[name]
            leader = mechanism.joints[m.leader]
            kind = m.kind if m.kind in ("revolute", "continuous", "prismatic") else leader.kind
            out[name] = _joint(mechanism.coordinate(q, name), m.multiplier * v[leader.idx_v],
                               m.multiplier * a[leader.idx_v], kind)
        elif joint.nv == 1:
            out[name] = _joint(joint.coordinate(q), v[joint.idx_v], a[joint.idx_v], joint.kind)
        elif joint.nv > 1:
            out[name] = _multi_dof(mechanism, joint.id, q, v, a)
    return out


_MULTI_DOF_KINDS = {"JointModelPlanar": "planar", "JointModelSpherical": "spherical",
                    "JointModelSphericalZYX": "spherical_zyx", "JointModelFreeFlyer": "floating",
                    "JointModelTranslation": "translation"}


def _multi_dof(mechanism: Mechanism, jid: int, q: list[float], v: list[float], a: list[float]) -> JointMotion:
    """A joint of several freedoms; a planar joint's (cos, sin) pair becomes its angle."""
    joint = mechanism.model.joints[jid]
    kind = _MULTI_DOF_KINDS.get(joint.shortname(), "other")
    qj = np.array(q[joint.idx_q : joint.idx_q + joint.nq])
    vj, aj = np.array(v[joint.idx_v : joint.idx_v + joint.nv]), np.array(a[joint.idx_v : joint.idx_v + joint.nv])
    if kind == "planar":
        qj = np.array([qj[0], qj[1], math.atan2(qj[3], qj[2])])
    return _joint(qj, vj, aj, kind)


def _joint(q: float | np.ndarray, v: float | np.ndarray, a: float | np.ndarray, kind: str) -> JointMotion:
    """JointMotion(q, v, a, kind), built at a fraction of the cost (`frozen`)."""
    return frozen(JointMotion, {"q": q, "v": v, "a": a, "kind": kind})


def _point(row: np.ndarray, link: str) -> PointMotion:
    """A frame's origin from its row of the core's answer (views of it, no copy)."""
    return frozen(PointMotion, {"position": row[0:3], "velocity": row[12:15], "acceleration": row[18:21], "link": link})


def _link_motion(row: np.ndarray, plane: tuple[list[float], list[float]] | None) -> LinkMotion:
    """A link's frame from its row of the core's answer (views of it, no copy)."""
    rotation = row[3:12]
    angle, axis = _plane_angle(rotation.tolist(), plane)
    return frozen(LinkMotion, {"rotation": rotation.reshape(3, 3), "angular_velocity": row[15:18],
                               "angular_acceleration": row[21:24], "angle": angle, "angle_axis": axis})


def _plane(normal: np.ndarray | None) -> tuple[list[float], list[float]] | None:
    """A planar mechanism's plane normal and the world x axis projected on the plane
    (`_plane_reference`), as floats; None for a spatial mechanism."""
    return None if normal is None else (normal.tolist(), _plane_reference(*normal.tolist()).tolist())


#: A link axis is measured in the plane when its projection on the plane is at least this
#: long (it is within 60 deg of the plane): its in-plane direction is then exact to
#: rounding. Of x, y and z one always qualifies (their squared projections add up to 2).
_IN_PLANE = 0.5


def _plane_angle(rotation: list[float], plane: tuple[list[float], list[float]] | None) -> tuple[float | None, str]:
    """Angle about the plane normal of the link's x axis (else y, else z: the first that
    lies within 60 deg of the plane), from the world x axis projected on the plane; and
    which axis was measured. `rotation`: the link's rotation, 9 floats row by row; `plane`:
    the normal and the reference direction (`_plane`), None for a spatial mechanism. Plain
    floats: a pose's few products cost less than numpy's calls."""
    if plane is None:
        return None, "x"
    (n0, n1, n2), (r0, r1, r2) = plane
    for k, name in _AXES:
        a0, a1, a2 = rotation[k], rotation[k + 3], rotation[k + 6]  # column k
        along = n0 * a0 + n1 * a1 + n2 * a2
        p0, p1, p2 = a0 - n0 * along, a1 - n1 * along, a2 - n2 * along
        if math.hypot(p0, p1, p2) >= _IN_PLANE or k == 2:
            c0, c1, c2 = r1 * p2 - r2 * p1, r2 * p0 - r0 * p2, r0 * p1 - r1 * p0
            return math.atan2(n0 * c0 + n1 * c1 + n2 * c2, r0 * p0 + r1 * p1 + r2 * p2), name
    raise AssertionError("unreachable")  # pragma: no cover


_AXES = ((0, "x"), (1, "y"), (2, "z"))


@functools.lru_cache(maxsize=8)
def _plane_reference(nx: float, ny: float, nz: float) -> np.ndarray:
    """The world x axis projected on the plane (the y axis when the normal is near x)."""
    normal = np.array((nx, ny, nz))
    ref = np.array([1.0, 0.0, 0.0]) if abs(nx) < 0.9 else np.array([0.0, 1.0, 0.0])
    ref = ref - normal * (normal @ ref)
    return ref / np.linalg.norm(ref)


def _coincident(link: np.ndarray, at: np.ndarray, name: str) -> PointMotion:
    """Motion of the material point of a link that sits at a point now (rigid-body formulas):
    `link` and `at` are the link frame's and the point's rows of the core's answer."""
    r = at[0:3] - link[0:3]
    w, alpha = link[15:18], link[21:24]
    return frozen(PointMotion, {
        "position": at[0:3],
        "velocity": link[12:15] + _cross(w, r),
        "acceleration": link[18:21] + _cross(alpha, r) + _cross(w, _cross(w, r)),
        "link": name,
    })


def _slider(joint, row: np.ndarray, parent: np.ndarray | None, q: float, rate: float, accel: float) -> SliderMotion:
    """A tree slider from its joint's row (and its parent joint's, None for the ground) of
    the core's answer, its coordinate q [m], rate [m/s] and acceleration [m/s^2]."""
    axis_world = row[3:12].reshape(3, 3) @ joint.axis
    omega_parent = parent[15:18] if parent is not None else np.zeros(3)
    v_rel = rate * axis_world
    return frozen(SliderMotion, {
        "parent": joint.parent_link,
        "child": joint.child_link,
        "relative_velocity": v_rel,
        "relative_acceleration": accel * axis_world,
        "coriolis_acceleration": 2.0 * _cross(omega_parent, v_rel),
        "axis": axis_world,
        "s": q,
        "s_dot": rate,
        "s_ddot": accel,
    })
