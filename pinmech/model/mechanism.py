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

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.arguments import float_array
from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.model.closure_rows import STRUCTURAL_RANK_TOL, close_loops
from pinmech.model.closures import Closure
from pinmech.model.configuration_check import UNIT_NORM_TOL, checked_configuration, unit_parts
from pinmech.model.frame_names import frame_named, frames_of_kind
from pinmech.model.inertia_check import model_inertia_caveats
from pinmech.model.joint_info import JointInfo, _joint_infos, _named_points, _tree_joint_links
from pinmech.model.loop_size import SIZE_RANGE, _translational
from pinmech.model.pinocchio_build import MAX_DOF, pinocchio_build
from pinmech.model.urdf_joints import JointLimit, MimicJoint
from pinmech.model.urdf_xml import read_xml, urdf_joint_types, urdf_mimic_leaders

#: names kept importable from here (they lived in this module)
__all__ = ["MAX_DOF", "SIZE_RANGE", "STRUCTURAL_RANK_TOL", "UNIT_NORM_TOL", "JointInfo", "Mechanism",
           "pinocchio_build", "read_xml", "urdf_joint_types", "urdf_mimic_leaders"]

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
        written_frames: ("point", name) or ("cut", name, side) -> the placement in its joint
            of the frame a file wrote it in, where the model's own frames lost it (an MJCF
            site or anchor on a jointless body, moved onto the moving body).
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
    written_frames: dict = field(default_factory=dict)

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
        from pinmech.model.urdf_load import mechanism_from_urdf

        return mechanism_from_urdf(cls, path, locked=locked, root_joint=root_joint, reference=reference)

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
        joint_links = _tree_joint_links(model)
        mech = cls(model=model, closures=[], joints=_joint_infos(model, joint_links, source), links=bodies,
                   points=_named_points(model, points, source), length_scale=1.0, plane_normal=None,
                   source=source, urdf_path=urdf_path, locked=dict(locked or {}),
                   force_caveats=tuple(model_inertia_caveats(model)))
        close_loops(mech, [anchor_closure(model, cut, 1.0) for cut in cuts])  # each loop's size: there
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
            raise FrameNotFound("point or frame", f"{name!r:.40}", self.place_names, path=self.source)
        if name in self.points:
            return self.points[name]
        if name in self.links:
            return self.links[name]
        fid = frame_named(self.model, name, source=self.source)
        if fid is not None:
            return fid
        raise FrameNotFound("point or frame", name, self.place_names, path=self.source)

    @property
    def place_names(self) -> list[str]:
        """Every name `frame_id` finds: the points, the links, then the pins and joints (a
        drawn linkage's pins, a URDF's joints and fixed joints), without pinmech's own
        frames (a loop cut's sides) and the world."""
        own = {f"{c.name}__{side}" for c in self.closures for side in ("parent", "child")} | {"universe"}
        names = list(dict.fromkeys([*self.points, *self.links]))
        kinds = (pin.FrameType.OP_FRAME, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT)
        return names + sorted({f.name for f in self.model.frames if f.type in kinds} - set(names) - own)

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
        known = self.__dict__.get("_unit_parts")
        if known is None or known[0] is not self.model:  # a model's joint types are fixed: found once
            known = self.__dict__["_unit_parts"] = (self.model, self.model.nq, unit_parts(self.model))
        return checked_configuration(q, known[1], known[2], name, many, self.source)

    def coordinate(self, q: np.ndarray, name: str) -> float:
        """A one-dof joint's coordinate (angle in (-pi, pi] for a continuous joint)."""
        if name in self.mimics:
            m = self.mimics[name]
            return m.multiplier * self.coordinate(q, m.leader) + m.offset
        return self.joint(name).coordinate(q)

