"""URDF + `<constraint>` loop cuts -> a Pinocchio model with named points and closures.

URDF describes a tree. A closed loop is cut at one joint, and the cut is declared in the
same file with the `<constraint>` element proposed for URDF (ros/urdfdom#264):

    <constraint name="C" type="revolute|prismatic|spherical|fixed">
      <parent link="ground"/> <parent_origin xyz="0.05 0 0" rpy="0 0 0"/> <parent_axis xyz="0 0 1"/>
      <child link="link3"/>   <child_origin xyz="0 0 0" rpy="0 0 0"/>     <child_axis xyz="0 0 1"/>
    </constraint>

Pinocchio ignores the element; this module reads it, adds one frame per side of the cut,
and finds which constraint rows are independent (a planar loop loses its out-of-plane
rows). Named points are massless leaf links hung on fixed joints.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.model.closures import CUT_TYPES, Closure
from pinmech.arguments import file_path, float_array
from pinmech.directions import unit_vector
from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.model.frame_names import frame_named, frames_of_kind, reduced_model
from pinmech.model.inertia_check import model_inertia_caveats, urdf_inertia_caveats
from pinmech.model.urdf_joints import JointLimit, MimicJoint, joint_limits, mimic_joints, with_followers

#: Singular values below this fraction of the largest mark a row as structurally zero.
STRUCTURAL_RANK_TOL = 1e-9
_SAMPLES = 4
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


@dataclass(frozen=True)
class JointInfo:
    """A one-degree-of-freedom (or other) joint of the model, as a user names it.

    Attributes:
        kind: "revolute", "continuous" (stored as cos/sin), "prismatic" or "other".
        idx_q, idx_v: first index in the configuration and velocity vectors.
    """

    name: str
    id: int
    kind: str
    idx_q: int
    idx_v: int
    nq: int
    nv: int
    parent_link: str
    child_link: str
    axis: np.ndarray  # in the joint frame

    @property
    def is_angular(self) -> bool:
        return self.kind in ("revolute", "continuous")


@dataclass
class Mechanism:
    """A Pinocchio model with the user's names: joints, links, points and loop closures.

    Build one with `Mechanism.from_urdf`. It owns no solver state: solvers create their own
    `pin.Data` once and keep it across poses.

    Attributes:
        model: the (possibly reduced) Pinocchio model, with one extra frame per cut side.
        closures: the loop cuts, with their independent rows.
        joints: name -> JointInfo of every joint that moves.
        links: name -> Pinocchio BODY frame id, for every link that is not a point.
        points: name -> frame id of every named point.
        length_scale: size of the mechanism [m]: its largest loop's (each closure's own
            `length_scale` sets that loop's tolerance), or for an open chain the box of its
            joints and the frames they move; never a frame that closes no loop.
        plane_normal: unit normal of the motion plane for a planar mechanism, else None.
        locked: joints locked out of the model, with their values (SI).
        urdf_path: the URDF the model was built from, when `source` is another file (a
            linkage drawn in TOML, an MJCF file): drawings read their visuals from it.
        reference: the reference configuration (the drawn pose of a linkage), else None
            (the neutral configuration is the reference).
        motors: the actuated joints a file names (a Gepetto sidecar's name_mot): the
            default drivers.
        mimics: joints following another one (URDF `<mimic>`) and still moving.
        limits: name -> position limits of the URDF's `<limit>` [rad or m],
            for the revolute and prismatic joints that give them (locked ones included).
        force_caveats: why the file's forces are not this model's (masses its parser
            does not compute as the file's own tool, passive joint forces): kinematics do
            not need them, `ForceSolver` refuses to run on them.
        massless_links: links without mass by construction (a drawn slot's hidden block, a
            ball's gimbal links): no mass is missing there.
        mass_source: where a file gives a link's mass, for the message naming links without.
    """

    model: pin.Model
    closures: list[Closure]
    joints: dict[str, JointInfo]
    links: dict[str, int]
    points: dict[str, int]
    length_scale: float
    plane_normal: np.ndarray | None
    source: str = "<model>"
    locked: dict[str, float] = field(default_factory=dict)
    urdf_path: str | None = None
    reference: np.ndarray | None = None
    motors: list[str] = field(default_factory=list)
    _rank: object = field(default=None, repr=False, compare=False)
    mimics: dict[str, MimicJoint] = field(default_factory=dict)
    limits: dict[str, JointLimit] = field(default_factory=dict)
    force_caveats: tuple[str, ...] = ()
    massless_links: tuple[str, ...] = ()
    mass_source: str = "<inertial> mass"

    # ---------------------------------------------------------------- construction
    @classmethod
    def from_urdf(
        cls,
        path: str | Path,
        *,
        locked: dict[str, float] | None = None,
        package_dirs: list[str] | None = None,
        root_joint: str | None = None,
        reference: dict[str, float] | None = None,
    ) -> Mechanism:
        """Load a URDF with its `<constraint>` loop cuts.

        Args:
            path: the URDF file.
            locked: joints to lock out of the model, name -> value (rad or m). The others
                keep their degrees of freedom. Locked joints cost nothing at solve time.
            package_dirs: unused for kinematics (no meshes are loaded here); kept for
                symmetry with the drawing code.
            root_joint: None (the URDF's root link is fixed to the world) or "free_flyer"
                (a floating base, joint "root_joint", nq 7 / nv 6, as example-robot-data
                builds humanoids). A free flyer cannot be locked by one value: leave it
                out (None) when a scene holds the base still.
            reference: joint name -> coordinate [rad or m] of a closed reference pose (a
                linkage's drawn pose); the others stay at zero. Default: all zero.

        Raises:
            ModelError: malformed XML or URDF, or a malformed `<constraint>`.
            FrameNotFound: a locked joint that is not in the model.
        """
        path = file_path(path, "the URDF")
        source = str(path)
        root = _parse_xml(path)
        _check_urdf_spelling(root, source)
        _check_locked(locked or {}, source)
        mimics = mimic_joints(root, source)
        full = _build_model(source, root_joint, mimic=bool(mimics))
        locked = with_followers(dict(locked or {}), mimics, source)
        model = _lock_joints(full, locked, source)
        _check_size(model, source)
        if model.nv == 0:
            held = f" once {', '.join(locked)} are locked" if locked else ""
            raise ModelError(f"no joint of the model moves{held}: nothing to solve", path=source)
        links_xml = _link_names(root)
        point_names = _point_links(root)
        joint_links = {
            j.get("name"): (j.find("parent").get("link"), j.find("child").get("link"))
            for j in root.findall("joint")
            if j.find("parent") is not None and j.find("child") is not None
        }
        cuts = [_parse_constraint(c, model, links_xml, source) for c in root.findall("constraint")]
        names = [c.name for c in cuts]
        for name in names:
            if names.count(name) > 1:
                raise ModelError("two <constraint> elements share this name", path=source,
                                 element=f"<constraint name=\"{name}\">")
        mech = cls(
            model=model,
            closures=[],
            joints=_joint_infos(model, joint_links, source),
            links={n: _body_frame(model, n) for n in links_xml if n not in point_names and model.existBodyName(n)},
            points={n: _body_frame(model, n) for n in point_names if model.existBodyName(n)},
            length_scale=1.0,
            plane_normal=None,
            source=source,
            locked=dict(locked or {}),
            mimics={n: m for n, m in mimics.items() if n not in (locked or {})},
            force_caveats=tuple(urdf_inertia_caveats(root, source)),
        )
        mech.limits = {n: lu for n, lu in joint_limits(root, source).items() if n in mech.joints or n in mech.locked}
        mech.closures = [_make_closure(model, c) for c in cuts]
        mech.length_scale = _length_scale(model, mech.closures, source)
        _reduce_rows(mech)
        mech.plane_normal = _plane_normal(mech)
        if reference:
            q = pin.neutral(model)
            for name, value in reference.items():
                if name in mech.joints:
                    mech.set_coordinate(q, name, value)
            mech.reference = q
        return mech

    @classmethod
    def from_model(
        cls,
        model: pin.Model,
        constraints: Sequence[Any] = (),
        *,
        names: Sequence[str] | None = None,
        points: Sequence[str] | None = None,
        source: str = "<model>",
        reference: np.ndarray | None = None,
        urdf_path: str | None = None,
        locked: dict[str, float] | None = None,
    ) -> Mechanism:
        """A mechanism from a `pin.Model` and Pinocchio constraint models, as built in code.

        Args:
            model: the kinematic tree (copied: frames are added to the copy, not to it).
            constraints: `pin.PointAnchorConstraintModel` (a ball joint: spherical cut),
                `pin.FrameAnchorConstraintModel` (a weld: fixed cut), or the legacy
                `pin.RigidConstraintModel` of type CONTACT_3D or CONTACT_6D.
            names: the loop cuts' names (default: each constraint's name, else "loop1", ...).
            points: frames reported as named points (default: every OP_FRAME, e.g. MJCF sites).
            source: what to call the model in messages (its file).
            reference: a configuration at which the loops close (default: neutral).
            urdf_path: a URDF with the visuals, if any (for drawings).
            locked: one-freedom joints to lock out, name -> value [rad or m]; the cuts on
                them move to the nearest joint left moving.

        Raises:
            ModelError: an unknown constraint class or type, a joint id out of range, a
                locked joint with several freedoms.
            FrameNotFound: a locked joint the model lacks.
        """
        model = pin.Model(model)
        from pinmech.model.anchors import anchor_closure, anchor_cut, lock_anchored

        cuts = [anchor_cut(c, i, names, model, source) for i, c in enumerate(constraints)]
        if locked:
            model, cuts, reference = lock_anchored(model, cuts, locked, reference, source)
        listed = [c.name for c in cuts]
        for name in listed:
            if listed.count(name) > 1:
                raise ModelError(f"two constraints share the name '{name}'", path=source)
        bodies = frames_of_kind(model, pin.FrameType.BODY, source)
        joint_links = {}
        for jid in range(1, model.njoints):
            child = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == jid),
                         model.names[jid])
            parent = next((f.name for f in model.frames if f.type == pin.FrameType.BODY
                           and f.parentJoint == model.parents[jid]), "universe")
            joint_links[model.names[jid]] = (parent, child)
        mech = cls(model=model, closures=[], joints=_joint_infos(model, joint_links, source), links=bodies,
                   points=_named_points(model, points, source), length_scale=1.0, plane_normal=None,
                   source=source, urdf_path=urdf_path, locked=dict(locked or {}),
                   force_caveats=tuple(model_inertia_caveats(model)))
        mech.closures = [anchor_closure(model, cut, 1.0) for cut in cuts]  # each loop's size: below
        mech.length_scale = _length_scale(model, mech.closures, source)
        _reduce_rows(mech)
        mech.plane_normal = _plane_normal(mech)
        if reference is not None:
            mech.reference = np.array(reference, dtype=float)
            if mech.reference.shape != (model.nq,):
                raise ModelError(f"reference has {mech.reference.size} coordinates, the model nq = {model.nq}",
                                 path=source)
        return mech

    def check_independent(self) -> None:
        """Refuse loops whose equations repeat each other: the loop solver needs them independent.

        Raises:
            ModelError: naming the cuts, the row count, the rank and the true mobility.
        """
        report = self.rank_report()
        if report.rank < report.rows:
            names = ", ".join(report.redundant) or ", ".join(c.name for c in self.closures)
            raise ModelError(f"the loop cuts {names} repeat each other's equations ({report.rows} closure rows of "
                             f"rank {report.rank} on the closed poses), so the mobility is {self.model.nv - report.rank}, "
                             f"not {self.model.nv - report.rows}; pinmech's loop solver needs independent "
                             f"equations: leave out one of {names} (and a link only it held, whose motion "
                             f"repeats the others')", path=self.source)

    def add_point(self, name: str, link: str, xyz: np.ndarray) -> int:
        """Fix a named point on a link, at `xyz` [m] in the link's frame; its frame id.

        Call before creating solvers: a `pin.Data` made earlier lacks the new frame.

        Raises:
            ModelError: a name that is no text or is already a point or link's (Pinocchio
                would hand back the old point's frame), or xyz not 3 finite numbers.
            FrameNotFound: an unknown link.
        """
        if not isinstance(name, str) or not name:
            raise ModelError(f"a point's name must be a non-empty str, got {name!r:.80}", path=self.source)
        if not isinstance(link, str) or link not in self.links:
            raise FrameNotFound("link (of a point)", str(link), list(self.links), path=self.source)
        if name in self.points or name in self.links:
            raise ModelError(f"the model already has a {'point' if name in self.points else 'link'} called "
                             f"'{name}': name the point otherwise", path=self.source)
        offset = float_array(xyz, f"the coordinates of point '{name}'", (3,), self.source)
        body_id = self.links[link]
        body = self.model.frames[body_id]
        frame = pin.Frame(name, body.parentJoint, body_id, body.placement * pin.SE3(np.eye(3), offset),
                          pin.FrameType.OP_FRAME)
        self.points[name] = self.model.addFrame(frame, False)
        return self.points[name]

    # ---------------------------------------------------------------- look-ups
    def joint(self, name: str) -> JointInfo:
        """The joint called `name`; FrameNotFound lists the known ones otherwise."""
        if not isinstance(name, str):
            raise FrameNotFound("joint", f"{name!r:.40}", list(self.joints), path=self.source)
        try:
            return self.joints[name]
        except KeyError:
            raise FrameNotFound("joint", name, list(self.joints), path=self.source, cuts=self.cut_names) from None

    @property
    def cut_names(self) -> tuple[str, ...]:
        """Names of the loop cuts (`<constraint>`s, a drawn loop's closing pins)."""
        return tuple(c.name for c in self.closures)

    def driver_index(self, name: str) -> int:
        """Velocity index of a joint that can be driven (one degree of freedom).

        Raises:
            FrameNotFound: no such joint. ModelError: a joint of several freedoms.
        """
        joint = self.joint(name)
        if joint.nv != 1:
            raise ModelError(f"driver '{name}' has {joint.nv} degrees of freedom; drive one-dof joints",
                             path=self.source)
        return joint.idx_v

    def frame_id(self, name: str) -> int:
        """Frame id of a point, a link, or any other frame of the model, by name."""
        if not isinstance(name, str):
            raise FrameNotFound("point or frame", f"{name!r:.40}", list(self.points) + list(self.links),
                                path=self.source)
        if name in self.points:
            return self.points[name]
        if name in self.links:
            return self.links[name]
        fid = frame_named(self.model, name, source=self.source)
        if fid is not None:
            return fid
        known = list(self.points) + list(self.links)
        raise FrameNotFound("point or frame", name, known, path=self.source)

    def link_of_frame(self, frame: int) -> str:
        """Name of the link a frame is attached to (the body of its parent joint)."""
        joint = self.model.frames[frame].parentJoint
        for name, fid in self.links.items():
            if self.model.frames[fid].parentJoint == joint:
                return name
        return self.model.names[joint]

    @property
    def constraint_rows(self) -> int:
        """Number of independent loop-closure equations."""
        return sum(c.rows for c in self.closures)

    @property
    def mobility(self) -> int:
        """Degrees of freedom left once every loop is closed: what the drivers must number.

        The joint freedoms minus the rank of the closure rows on the closed poses near the
        reference configuration (see `pinmech.model.mobility`): loops that repeat each other
        (a double parallelogram) do not lower it twice.

        Raises:
            ModelError: the loops repeat each other's equations, which the loop solver cannot
                take (the message gives the true mobility and the cuts to remove). A mechanism
                with redundant loops still loads, for force analysis (`ForceSolver`).
        """
        self.check_independent()
        return self.model.nv - self.rank_report().rank

    def rank_report(self):
        """The closure rows' rank on closed poses (computed once, then kept)."""
        if self._rank is None:
            from pinmech.model.mobility import constraint_rank

            self._rank = constraint_rank(self)
        return self._rank

    def idle_joints(self, drivers: list[str]) -> list[str]:
        """Joints the loops leave free to move while `drivers` are held (a spinning rod)."""
        from pinmech.model.mobility import idle_joints

        return idle_joints(self, drivers, self.rank_report().q)

    def velocity_scale(self) -> np.ndarray:
        """Per degree of freedom: a length [m] for translational freedoms, 1 for the others.

        Translational freedoms are those of prismatic joints and the translations of planar
        and floating joints; each is scaled by the size of the loops its joint closes (the
        largest, `Closure.length_scale`), or the mechanism's size outside every loop.
        Multiplying Jacobian columns by it makes them dimensionless (a slide of one loop
        size weighs as a turn of one radian), so condition numbers do not depend on the
        units or the size of the mechanism, nor on frames that close no loop.
        """
        if self.__dict__.get("_slides") is None:  # the joints' kinds are fixed: found once
            self._slides = [(jid, [self.model.joints[jid].idx_v + i for i in _translational(self.model, jid)])
                            for jid in range(1, self.model.njoints)]
        scale = np.ones(self.model.nv)
        for jid, slides in self._slides:
            if slides:
                sizes = [c.length_scale for c in self.closures if jid in c.joints]
                scale[slides] = max(sizes) if sizes else self.length_scale
        return scale

    def neutral(self) -> np.ndarray:
        """The reference configuration: a linkage's drawn pose, else all joint coordinates zero."""
        if self.reference is not None:
            return self.reference.copy()
        return pin.neutral(self.model)

    def set_coordinate(self, q: np.ndarray, name: str, value: float) -> None:
        """Write a joint's coordinate (angle [rad] or length [m]) into q, in place."""
        j = self.joint(name)
        if name in self.mimics:
            leader = self.mimics[name].leader
            raise ModelError(f"joint '{name}' follows '{leader}' (URDF <mimic>): give {leader}'s value instead",
                             path=self.source)
        if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) or not np.isfinite(value):
            raise ModelError(f"joint '{name}': a coordinate must be a finite number (rad or m), got {value!r:.40}",
                             path=self.source)
        if j.kind == "continuous":
            q[j.idx_q : j.idx_q + 2] = (np.cos(value), np.sin(value))
        elif j.nq == 1:
            q[j.idx_q] = value
        else:
            raise ModelError(f"joint '{name}' has {j.nq} coordinates; give it a full configuration", path=self.source)

    def checked_q(self, q: Any, name: str = "q", *, many: bool = False) -> np.ndarray:
        """q as a configuration of the model (`many`: an (N, nq) array of them), checked
        once where it enters: finite numbers of the right shape, and every quaternion or
        (cos, sin) pair of unit norm (to UNIT_NORM_TOL).

        Raises:
            ModelError: naming the argument and what it got (a non-unit quaternion: the
                joint and its norm).
        """
        nq = self.model.nq
        out = float_array(q, name, (None, nq) if many else (nq,), self.source)
        rows = out if many else out[None]
        parts = self.__dict__.get("_unit_parts")
        if parts is None:  # the joints' types are fixed: found once
            parts = []
            for jid in range(1, self.model.njoints):
                joint = self.model.joints[jid]
                part = _UNIT_PARTS.get(joint.shortname())
                if part is not None:
                    parts.append((self.model.names[jid], joint.idx_q + part[0], joint.idx_q + part[1], part[2]))
            self.__dict__["_unit_parts"] = parts
        if not many:  # one pose (evaluate_motion, solve): plain floats, a microsecond, not numpy's 30
            values = out.tolist()
            if all(abs(math.hypot(*values[start:stop]) - 1.0) <= UNIT_NORM_TOL for _, start, stop, _ in parts):
                return out
        for joint, start, stop, what in parts:
            norms = np.sqrt(np.sum(rows[:, start:stop] ** 2, axis=1))
            bad = np.flatnonzero(~(np.abs(norms - 1.0) <= UNIT_NORM_TOL))
            if bad.size:
                at = f" (row {bad[0]})" if many else ""
                raise ModelError(f"{name}{at}: joint '{joint}' has a {what} of norm {norms[bad[0]]:.17g}, not 1 "
                                 f"(within {UNIT_NORM_TOL:g}): normalise it (pinocchio.normalize(model, q)); "
                                 "pinmech does not guess which rotation was meant", path=self.source)
        return out

    def coordinate(self, q: np.ndarray, name: str) -> float:
        """A one-dof joint's coordinate (angle in (-pi, pi] for a continuous joint)."""
        if name in self.mimics:
            m = self.mimics[name]
            return m.multiplier * self.coordinate(q, m.leader) + m.offset
        j = self.joint(name)
        if j.kind == "continuous":
            return math.atan2(q[j.idx_q + 1], q[j.idx_q])  # libm's atan2, as numpy's for one pair
        return float(q[j.idx_q])


# -------------------------------------------------------------------- XML reading
def urdf_joint_types(path: str | Path) -> dict[str, str]:
    """Joint name -> URDF joint type ("revolute", "prismatic", ...), read from the XML."""
    root = _parse_xml(Path(path))
    return {j.get("name"): j.get("type") for j in root.findall("joint")}


def urdf_mimic_leaders(path: str | Path) -> dict[str, str]:
    """Follower -> leader of the URDF's `<mimic>` joints, read from the XML."""
    return {n: m.leader for n, m in mimic_joints(_parse_xml(Path(path)), str(path)).items()}


def read_xml(path: Path, root_tag: str, kind: str) -> ET.Element:
    """The root element of a model file (`kind`: "URDF", "MJCF"), checked to be <root_tag>.

    Raises:
        ModelError: a missing file, malformed XML or another root element, naming the file.
    """
    if not path.is_file():
        raise ModelError(f"no such {kind} file", path=str(path))
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ModelError(f"malformed XML: {exc}", path=str(path)) from exc
    if root.tag != root_tag:
        raise ModelError(f"root element is <{root.tag}>, expected <{root_tag}>", path=str(path))
    return root


def _parse_xml(path: Path) -> ET.Element:
    return read_xml(path, "robot", "URDF")


def _link_names(root: ET.Element) -> list[str]:
    return [link.get("name") for link in root.findall("link")]


def _point_links(root: ET.Element) -> list[str]:
    """Massless leaf links hung on fixed joints: the URDF's named points."""
    parents = {j.find("parent").get("link") for j in root.findall("joint") if j.find("parent") is not None}
    fixed_children = {
        j.find("child").get("link")
        for j in root.findall("joint")
        if j.get("type") == "fixed" and j.find("child") is not None
    }
    empty = {
        link.get("name")
        for link in root.findall("link")
        if not any(link.find(tag) is not None for tag in ("inertial", "visual", "collision"))
    }
    return [n for n in _link_names(root) if n in fixed_children and n in empty and n not in parents]


def _vector(element: ET.Element | None, attr: str, default: str, where: str, source: str) -> np.ndarray:
    text = default if element is None else element.get(attr, default)
    try:
        values = np.array([float(x) for x in text.split()])
    except ValueError:
        raise ModelError(f"{attr}=\"{text}\" is not three numbers", path=source, element=where) from None
    if values.shape != (3,) or not np.all(np.isfinite(values)):
        raise ModelError(f"{attr}=\"{text}\" is not three finite numbers", path=source, element=where)
    return values


@dataclass(frozen=True)
class _Cut:
    name: str
    cut_type: str
    parent_link: str
    child_link: str
    parent_origin: pin.SE3
    child_origin: pin.SE3
    parent_axis: np.ndarray
    child_axis: np.ndarray
    source: str


def _parse_constraint(el: ET.Element, model: pin.Model, links: list[str], source: str) -> _Cut:
    name = el.get("name") or "<unnamed>"
    where = f"<constraint name=\"{name}\">"
    _check_known(el, where, source)
    cut_type = el.get("type")
    if cut_type not in CUT_TYPES:
        raise ModelError(f"type=\"{cut_type}\" is not one of {', '.join(CUT_TYPES)}", path=source, element=where)
    sides = {}
    for side in ("parent", "child"):
        link_el = el.find(side)
        link = None if link_el is None else link_el.get("link")
        if link is None:
            raise ModelError(f"missing <{side} link=\"...\"/>", path=source, element=where)
        if link not in links:
            raise ModelError(f"<{side} link=\"{link}\"/> names no link of the model", path=source, element=where)
        if not model.existBodyName(link):
            raise ModelError(f"<{side} link=\"{link}\"/> is not connected to the tree of joints from the root link",
                             path=source, element=where)
        origin = el.find(f"{side}_origin")
        xyz = _vector(origin, "xyz", "0 0 0", where, source)
        rpy = _vector(origin, "rpy", "0 0 0", where, source)
        axis = _vector(el.find(f"{side}_axis"), "xyz", "0 0 1", where, source)
        unit = unit_vector(axis)
        if unit is None:
            raise ModelError(f"<{side}_axis xyz=\"{el.find(f'{side}_axis').get('xyz')}\"/> is not a direction",
                             path=source, element=where)
        sides[side] = (link, pin.SE3(pin.rpy.rpyToMatrix(rpy), xyz), unit)
    return _Cut(name, cut_type, sides["parent"][0], sides["child"][0], sides["parent"][1], sides["child"][1],
                sides["parent"][2], sides["child"][2], source)


#: URDF elements whose children and attributes pinmech's kinematics and masses depend on,
#: with what they hold (urdfdom skips anything else: a misspelled <orign> leaves the joint
#: at the identity, another mechanism)
_URDF_CHILDREN = {"joint": ("origin", "parent", "child", "axis", "calibration", "dynamics", "limit", "mimic",
                            "safety_controller"),
                  "inertial": ("origin", "mass", "inertia")}
_URDF_ATTRIBUTES = {"origin": ("xyz", "rpy"), "axis": ("xyz",), "mass": ("value",),
                    "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), "parent": ("link",), "child": ("link",),
                    "joint": ("name", "type")}


def _check_urdf_spelling(root: ET.Element, source: str) -> None:
    """A child of a <joint> or <inertial>, or an attribute of the elements the kinematics
    and masses are read from, that is a near miss of a URDF name (<orgin>, xzy=) is
    refused with the likely spelling; urdfdom would skip it in silence. Names far from
    these are left alone (URDF files carry extensions)."""
    import difflib

    def near(name: str, known: tuple[str, ...]) -> str | None:
        if name in known:
            return None
        swapped = [k for k in known if sorted(k) == sorted(name)]  # xzy for xyz
        match = swapped or difflib.get_close_matches(name, known, n=1, cutoff=0.7)
        return match[0] if match else None

    elements = [(j, "joint", f"<joint name=\"{j.get('name', '')}\">") for j in root.iter("joint")]
    elements += [(i, "inertial", f"<link name=\"{link.get('name', '')}\"> <inertial>")
                 for link in root.iter("link") for i in link.findall("inertial")]
    for el, parent_tag, where in elements:
        for child in el:
            if not isinstance(child.tag, str):  # a comment
                continue
            guess = near(child.tag, _URDF_CHILDREN[parent_tag])
            if guess:
                raise ModelError(f"unknown element <{child.tag}>: did you mean <{guess}>? (the URDF parser would "
                                 "skip it)", path=source, element=where)
            for key in child.attrib:
                guess = near(key, _URDF_ATTRIBUTES.get(child.tag, ()))
                if guess:
                    raise ModelError(f"unknown attribute {key}=\"{child.get(key)}\" of <{child.tag}>: did you "
                                     f"mean {guess}?", path=source, element=where)


#: what a <constraint> holds: its attributes, and each child element with its attributes
_CONSTRAINT_ATTRIBUTES = {"name", "type"}
_CONSTRAINT_CHILDREN = {"parent": {"link"}, "child": {"link"}, "parent_origin": {"xyz", "rpy"},
                        "child_origin": {"xyz", "rpy"}, "parent_axis": {"xyz"}, "child_axis": {"xyz"}}


def _check_known(el: ET.Element, where: str, source: str) -> None:
    """Every attribute and child of a <constraint> is one pinmech reads: a misspelled
    <parent_orgin> was skipped, its origin taken as 0 0 0, and another mechanism solved."""
    for key in el.attrib:
        if key not in _CONSTRAINT_ATTRIBUTES:
            raise ModelError(f"unknown attribute {key}=\"{el.get(key)}\" (a <constraint> has "
                             f"{', '.join(sorted(_CONSTRAINT_ATTRIBUTES))})", path=source, element=where)
    seen = set()
    for child in el:
        if not isinstance(child.tag, str):  # a comment
            continue
        if child.tag not in _CONSTRAINT_CHILDREN:
            raise ModelError(f"unknown element <{child.tag}> (a <constraint> holds "
                             f"{', '.join(f'<{t}>' for t in _CONSTRAINT_CHILDREN)})", path=source, element=where)
        if child.tag in seen:
            raise ModelError(f"<{child.tag}> is given twice", path=source, element=where)
        seen.add(child.tag)
        for key in child.attrib:
            if key not in _CONSTRAINT_CHILDREN[child.tag]:
                raise ModelError(f"unknown attribute {key}=\"{child.get(key)}\" of <{child.tag}> (it has "
                                 f"{', '.join(sorted(_CONSTRAINT_CHILDREN[child.tag]))})", path=source, element=where)


# -------------------------------------------------------------------- model building
_ROOT_JOINTS = {"free_flyer": pin.JointModelFreeFlyer}


def _build_model(source: str, root_joint: str | None = None, *, mimic: bool = False) -> pin.Model:
    """pin.buildModelFromUrdf (honouring `<mimic>` when asked), with urdfdom's own stderr
    chatter folded into the error."""
    if root_joint is not None and root_joint not in _ROOT_JOINTS:
        raise ModelError(f"root_joint must be None or one of {', '.join(_ROOT_JOINTS)}, got {root_joint!r}",
                         path=source)
    args = (_ROOT_JOINTS[root_joint](),) if root_joint else ()
    return pinocchio_build(lambda: pin.buildModelFromUrdf(source, *args, mimic=mimic), source)


def pinocchio_build(build, source: str):
    """Call one of Pinocchio's model builders with the C++ parsers' stderr chatter caught,
    and fold that chatter into a one-line ModelError when the builder fails."""
    with tempfile.TemporaryFile(mode="w+b") as sink:
        saved = os.dup(2)
        try:
            sys.stderr.flush()
            os.dup2(sink.fileno(), 2)
            try:
                return build()
            except (ValueError, RuntimeError) as exc:
                error = exc
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        sink.seek(0)
        said = " ".join(sink.read().decode(errors="replace").split())
    detail = f" ({said})" if said else ""
    message = " ".join(f"{error}{detail}".split())  # Pinocchio's messages run over several lines
    raise ModelError(f"Pinocchio cannot build the model: {message}", path=source) from error


def _check_locked(locked: dict[str, float], source: str) -> None:
    """Every locked value is a finite number (SI), else a ModelError naming the joint."""
    if not isinstance(locked, dict):
        raise ModelError(f"locked must be a dict of joint name -> value (rad or m), got {locked!r:.60}", path=source)
    for name, value in locked.items():
        if not isinstance(name, str):
            raise ModelError(f"locked must name joints (str), got the key {name!r:.40}", path=source)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(_as_float(value)):
            raise ModelError(f"locked joint '{name}' must be held at a finite number (rad or m), got {value!r:.40}",
                             path=source)


def _as_float(value: int | float) -> float:
    """value as a float; an int beyond float64 as infinity (refused as not finite)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def _lock_joints(model: pin.Model, locked: dict[str, float], source: str) -> pin.Model:
    if not locked:
        return model
    q_ref = pin.neutral(model)
    ids = []
    for name, value in locked.items():
        if not model.existJointName(name):
            raise FrameNotFound("joint to lock", name, [n for n in model.names[1:]], path=source)
        jid = model.getJointId(name)
        joint = model.joints[jid]
        if joint.nq == 0 and "Mimic" in joint.shortname():
            pass  # a follower: its leader, locked with it, sets where it is held
        elif joint.nq == 2 and joint.nv == 1:
            q_ref[joint.idx_q : joint.idx_q + 2] = (np.cos(value), np.sin(value))
        elif joint.nq == 1:
            q_ref[joint.idx_q] = value
        else:
            raise ModelError(f"joint '{name}' has {joint.nq} coordinates and cannot be locked by one value", path=source)
        ids.append(jid)
    return reduced_model(model, ids, q_ref)


#: Most degrees of freedom a model may keep. Pinocchio's `Data` allocates, whatever it is
#: used for, four nv x nv x nv tensors (second derivatives of the inverse dynamics:
#: d2tau_dqdq, d2tau_dvdv, d2tau_dqdv, d2tau_dadq; data.hxx) and a 6 x nv x nv one, so its
#: size grows as nv^3: measured with Pinocchio 4.1, 69 MB at nv = 100, 0.5 GB at 200, 4 GB at
#: 400 (62.5 bytes per nv^3, chains and stars alike). pinmech makes several Data; past this
#: a model would exhaust memory (a 1,000-link chain: 62 GB) before anything is solved.
MAX_DOF = 256
_DATA_BYTES_PER_DOF_CUBED = 62.5


def _check_size(model: pin.Model, source: str) -> None:
    """Raises ModelError (one line, with the memory it would take) for a model with more
    degrees of freedom than `MAX_DOF`, before Pinocchio tries to allocate its Data."""
    if model.nv > MAX_DOF:
        gigabytes = _DATA_BYTES_PER_DOF_CUBED * model.nv**3 / 1e9
        raise ModelError(f"the model keeps {model.nv} degrees of freedom ({model.njoints - 1} joints); Pinocchio's "
                         f"working data for it would take about {gigabytes:.3g} GB (it holds nv x nv x nv tensors of "
                         f"second derivatives), so pinmech takes at most {MAX_DOF}: lock the joints the scene holds "
                         "still ([lock], or move = [...])", path=source)


def _joint_kind(joint: pin.JointModel) -> str:
    short = joint.shortname()
    if joint.nv != 1:
        return "other"
    if joint.nq == 2:
        return "continuous"
    if "Prismatic" in short or short.startswith("JointModelP"):
        return "prismatic"
    if "Revolute" in short or short.startswith("JointModelR"):
        return "revolute"
    return "other"


def _written_axis(source: str, name: str) -> str | None:
    """The axis a URDF (`<axis xyz>`) or MJCF (`axis`) file writes for joint `name`, as written
    (`xyz="0 0 1e-200"`), or None (no such file or joint, or not three numbers)."""
    try:
        root = ET.parse(source).getroot()
    except (OSError, ET.ParseError):
        return None
    for joint in root.iter("joint"):
        if joint.get("name") == name:
            axis = joint.find("axis")
            key, text = ("xyz", axis.get("xyz")) if axis is not None else ("axis", joint.get("axis"))
            try:
                return f'{key}="{text}"' if text is not None and len([float(v) for v in text.split()]) == 3 else None
            except ValueError:
                return None
    return None


def _joint_axis(joint: pin.JointModel, name: str, source: str) -> np.ndarray:
    """Unit axis of a one-dof joint in its own frame (motion subspace).

    Raises:
        ModelError: an axis of zero length (or not finite): the joint would move nothing.
    """
    if joint.nv != 1:
        return np.zeros(3)
    data = joint.createData()
    q = np.zeros(joint.nq)
    if joint.nq == 2:
        q[0] = 1.0
    joint.calc(data, q)
    S = np.array(data.S).reshape(6, 1)[:, 0]
    part = S[3:] if np.linalg.norm(S[3:]) > 0 else S[:3]
    norm = float(np.linalg.norm(part))
    if not (norm > 0 and np.isfinite(norm)):
        text = _written_axis(source, name)
        if text is not None and unit_vector([float(v) for v in text.split("\"")[1].split()]) is not None:
            raise ModelError(f"{text} is a direction Pinocchio's reader cannot normalise (its length "
                             "under- or overflows in double precision, the axis read as [0, 0, 0]): write it as a "
                             "unit vector", path=source, element=f"<joint name=\"{name}\"> <axis>")
        raise ModelError(f"the axis of joint {name} is {np.round(part, 6).tolist()}: not a direction, the joint "
                         "would move nothing", path=source, element=f"<joint name=\"{name}\"> <axis>")
    return part / norm


def _joint_infos(model: pin.Model, joint_links: dict[str, tuple[str, str]], source: str) -> dict[str, JointInfo]:
    infos = {}
    for jid in range(1, model.njoints):
        joint, name = model.joints[jid], model.names[jid]
        parent, child = joint_links.get(name, (model.names[model.parents[jid]], name))
        infos[name] = JointInfo(name, jid, _joint_kind(joint), joint.idx_q, joint.idx_v, joint.nq, joint.nv,
                                parent, child, _joint_axis(joint, name, source))
    return infos


def _named_points(model: pin.Model, names: Sequence[str] | None, source: str) -> dict[str, int]:
    """Name -> frame id of the named points: the frames called so (a site before a body or
    a joint of the same name), by default every OP_FRAME (MJCF sites).

    Raises:
        FrameNotFound: a name no frame has.
    """
    if names is None:
        return frames_of_kind(model, pin.FrameType.OP_FRAME, source)
    out = {}
    for name in names:
        fid = frame_named(model, name, source=source)
        if fid is None:
            raise FrameNotFound("point", name, sorted({f.name for f in model.frames}), path=source)
        out[name] = fid
    return out


def _body_frame(model: pin.Model, link: str) -> int:
    return frame_named(model, link, (pin.FrameType.BODY,))


#: Mechanism sizes pinmech accepts [m]: squares of lengths and speeds must stay finite.
SIZE_RANGE = (1e-50, 1e50)


def _translational(model: pin.Model, jid: int) -> list[int]:
    """Velocity components of a joint that translate (motion subspace without rotation, at
    the neutral configuration): a prismatic joint's one, a planar joint's two, a floating
    joint's three."""
    joint = model.joints[jid]
    if joint.nv == 0:  # a mimic follower: no freedom of its own
        return []
    data = joint.createData()
    joint.calc(data, pin.neutral(model))
    S = np.array(data.S).reshape(6, joint.nv)
    return [i for i in range(joint.nv) if not np.any(S[3:, i]) and np.any(S[:3, i])]


def _box(points: np.ndarray) -> float:
    """Diagonal of the box around points (rows) [m]."""
    with np.errstate(over="ignore", invalid="ignore"):
        return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if len(points) else 0.0


def _check_range(size: float, source: str) -> None:
    if not SIZE_RANGE[0] <= size <= SIZE_RANGE[1]:
        raise ModelError(f"the mechanism's size is {size:.3g} m, outside the {SIZE_RANGE[0]:g} to "
                         f"{SIZE_RANGE[1]:g} m pinmech can compute with (check the <origin> numbers)", path=source)


def _length_scale(model: pin.Model, closures: list[Closure], source: str) -> float:
    """The mechanism's size [m]: the largest of its loops' sizes; without loops (an arm),
    the box around its joints and the frames they move, at the neutral configuration
    (frames fixed to the ground, however far, do not count).

    Each loop's size (its `length_scale`, the scale of its closure tolerance) is the box
    around what closes it: the origins of the joints on its path through the tree and the
    two cut frames. A named point or a frame that closes no loop does not change it.

    Raises:
        ModelError: a size outside `SIZE_RANGE` (numbers that overflow, as 1e308 in an origin).
    """
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    every = _box(np.array([f.translation for f in data.oMf]))
    if every != 0:
        _check_range(every, source)
    for closure in closures:
        closure.joints = _loop_joints(model, closure)
        points = [data.oMi[j].translation for j in closure.joints]
        points += [data.oMf[closure.parent_frame].translation, data.oMf[closure.child_frame].translation]
        size = _box(np.array(points))
        closure.length_scale = size if size > 0 else (every or 1.0)
        _check_range(closure.length_scale, source)
    if closures:
        return max(c.length_scale for c in closures)
    moving = [data.oMi[j].translation for j in range(1, model.njoints)]
    moving += [data.oMf[i].translation for i in range(model.nframes) if model.frames[i].parentJoint != 0]
    size = _box(np.array(moving))
    return size if size > 0 else (every or 1.0)


def _loop_joints(model: pin.Model, closure: Closure) -> tuple[int, ...]:
    """Ids of the joints on the loop of a cut: the tree paths from both cut frames' joints
    up to (not including) their common ancestor."""
    def ancestors(j: int) -> list[int]:
        out = [j]
        while j != 0:
            j = model.parents[j]
            out.append(j)
        return out

    a = ancestors(model.frames[closure.parent_frame].parentJoint)
    b = ancestors(model.frames[closure.child_frame].parentJoint)
    common = set(a) & set(b)
    return tuple(j for j in a + b if j not in common and j != 0)


def _make_closure(model: pin.Model, cut: _Cut) -> Closure:
    """The closure of a cut, with one frame added per side; its size is set by `_length_scale`."""
    frame_ids = []
    for side, link, origin in (("parent", cut.parent_link, cut.parent_origin), ("child", cut.child_link, cut.child_origin)):
        body_id = _body_frame(model, link)
        body = model.frames[body_id]
        frame = pin.Frame(f"{cut.name}__{side}", body.parentJoint, body_id, body.placement * origin,
                          pin.FrameType.OP_FRAME)
        frame_ids.append(model.addFrame(frame, False))
    return Closure(cut.name, cut.cut_type, frame_ids[0], frame_ids[1], cut.parent_axis, cut.child_axis,
                   parent_link=cut.parent_link, child_link=cut.child_link)


def _sample_configurations(model: pin.Model, count: int, scale: np.ndarray | float = 1.0) -> list[np.ndarray]:
    """Seeded random configurations: about a radian, or `scale` metres for a slide, from neutral."""
    rng = np.random.default_rng(20261122)
    q0 = pin.neutral(model)
    return [pin.integrate(model, q0, scale * rng.normal(size=model.nv)) for _ in range(count)]


def _reduce_rows(mech: Mechanism) -> None:
    """Give each closure a constant basis of the rows that do not vanish identically."""
    if not mech.closures:
        return
    model = mech.model
    data = model.createData()
    columns = mech.velocity_scale()  # rows and columns dimensionless: the rank is the same at any size
    samples = _sample_configurations(model, _SAMPLES, columns)
    stacks: list[list[np.ndarray]] = [[] for _ in mech.closures]
    for q in samples:
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for stack, closure in zip(stacks, mech.closures):
            rows = closure.selected * closure._scale()
            stack.append(rows @ closure.relative_jacobian6(model, data) * columns)
    for stack, closure in zip(stacks, mech.closures):
        U, s, _ = np.linalg.svd(np.hstack(stack), full_matrices=False)
        rank = int(np.sum(s > STRUCTURAL_RANK_TOL * max(s[0], 1e-300))) if s.size else 0
        closure.basis = _readable_basis(U[:, :rank])


def _readable_basis(U: np.ndarray) -> np.ndarray:
    """Rows of the identity when they span the same space as U's columns, else U^T.

    A planar revolute cut then keeps "x" and "y" rather than two mixed combinations,
    so its residual reads in the cut frame's own axes.
    """
    inside = np.linalg.norm(U.T, axis=0) > 1 - 1e-12  # identity rows lying in span(U)
    if int(inside.sum()) == U.shape[1]:
        return np.eye(U.shape[0])[inside]
    return U.T.copy()


def _plane_normal(mech: Mechanism) -> np.ndarray | None:
    """The common normal of a planar mechanism: every link turns about it, none moves along it."""
    model = mech.model
    if model.nv == 0:
        return None
    data = model.createData()
    angular, linear = [], []
    columns = mech.velocity_scale()  # dimensionless columns and rows, as in _reduce_rows
    for q in _sample_configurations(model, 3, columns):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for fid in range(model.nframes):
            J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            J = J.reshape(6, model.nv) * columns  # Pinocchio gives a 6 x 1 Jacobian as a vector
            angular.append(J[3:])
            linear.append(J[:3] / mech.length_scale)
    # A = hstack(angular) is 3 x (frames * nv). A = R^T Q^T, so A's U and s are those of the
    # 3 x 3 R^T: same accuracy, and LAPACK's SVD of the wide A took 30 ms on a floating Talos.
    R = np.linalg.qr(np.hstack(angular).T, mode="r")
    U, s, _ = np.linalg.svd(R.T)
    if s[0] == 0 or (len(s) > 1 and s[1] > STRUCTURAL_RANK_TOL * s[0]):
        return None
    normal = U[:, 0] * np.sign(U[np.argmax(np.abs(U[:, 0])), 0])
    lin = np.hstack(linear)
    if np.linalg.norm(normal @ lin) > STRUCTURAL_RANK_TOL * max(np.linalg.norm(lin), 1e-300):
        return None
    return normal
