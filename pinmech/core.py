"""The bridge to pinmech's compiled core (pinmech/csrc/core.cpp): a `LoopSolver`'s model,
closure rows and assembly blocks handed over as arrays, once per solver.

The core follows a sweep pose by pose with the rules of continuation.py; where a step
needs more than a regular predictor-corrector step (a change point, a fold, a singular
or too ill-conditioned pose), it stops and the Python path takes that pose (solve_cycle.py).
Models with joints the core does not rebuild (mimic, composite, helical, universal,
ellipsoid joints) are solved by the Python path throughout: `core_for` returns None.
"""

from __future__ import annotations

import os

import numpy as np
import pinocchio as pin

try:
    from pinmech import _core
except ImportError as error:  # e.g. `python -m pinmech` in a checkout installed with `pip install .`
    raise ImportError(f"pinmech's compiled core is missing from {os.path.dirname(__file__)}, a source tree "
                      "without its build: run pinmech from outside the checkout, or install the checkout "
                      f"with `pip install -e .` ({error})") from error

#: Pinocchio joint types the core rebuilds, by shortname -> its code in core.cpp.
JOINT_CODES = {
    "JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2, "JointModelRevoluteUnaligned": 3,
    "JointModelRUBX": 4, "JointModelRUBY": 5, "JointModelRUBZ": 6, "JointModelRevoluteUnboundedUnaligned": 7,
    "JointModelPX": 8, "JointModelPY": 9, "JointModelPZ": 10, "JointModelPrismaticUnaligned": 11,
    "JointModelSpherical": 12, "JointModelPlanar": 13, "JointModelFreeFlyer": 14, "JointModelTranslation": 15,
}
_AXIS_CODES = {3, 7, 11}
CUT_CODES = {"revolute": 0, "prismatic": 1, "spherical": 2, "fixed": 3}
DEFAULT_TOL = _core.DEFAULT_TOL
#: PINMECH_CORE=0 in the environment solves everything by the Python path (tests compare
#: the two; a user can rule the core out when in doubt).
ENABLED = os.environ.get("PINMECH_CORE", "1") != "0"


def placement_rows(placements: list[pin.SE3]) -> np.ndarray:
    """(n, 12): each placement's rotation row by row, then its translation."""
    out = np.zeros((len(placements), 12))
    for i, M in enumerate(placements):
        out[i, :9] = M.rotation.reshape(9)
        out[i, 9:] = M.translation
    return out


class ModelCopy:
    """What a core copied from a `pin.Model` that a user may still change in place: every
    joint's placement and the placements of the frames it took. A core is rebuilt when
    they no longer match (the Python path reads them afresh at every pose)."""

    def __init__(self, model: pin.Model, frame_ids) -> None:
        self.joints = [model.jointPlacements[j].copy() for j in range(1, model.njoints)]
        self.frame_ids = tuple(int(f) for f in frame_ids)
        self.frames = [model.frames[f].placement.copy() for f in self.frame_ids]

    def matches(self, model: pin.Model) -> bool:
        return (model.njoints - 1 == len(self.joints)
                and all(model.jointPlacements[j + 1] == M for j, M in enumerate(self.joints))
                and all(model.frames[f].placement == M for f, M in zip(self.frame_ids, self.frames)))


class CompiledModel:
    """A `pin.Model`'s joints and some of its frames, rebuilt in the core.

    Attributes:
        frames: Pinocchio frame id -> its index among the core's frames.
    """

    def __init__(self, model: pin.Model, frame_ids: list[int]) -> None:
        self.types, self.parents, placements, axes = [], [], [], np.zeros((model.njoints - 1, 3))
        for jid in range(1, model.njoints):
            joint = model.joints[jid]
            code = JOINT_CODES[joint.shortname()]  # KeyError: not rebuilt (core_for says None)
            if code in _AXIS_CODES:  # the axis from the motion subspace (not every binding has .axis)
                jdata = joint.createData()
                joint.calc(jdata, pin.neutral(model)[joint.idx_q:joint.idx_q + joint.nq])
                S = np.asarray(jdata.S).reshape(6)
                axes[jid - 1] = S[:3] if code == 11 else S[3:]
            self.types.append(code)
            self.parents.append(int(model.parents[jid]))
            placements.append(model.jointPlacements[jid])
        self.placements, self.axes = placement_rows(placements), axes
        self.frames = {fid: i for i, fid in enumerate(dict.fromkeys(frame_ids))}
        self.frame_parents = [int(model.frames[fid].parentJoint) for fid in self.frames]
        self.frame_placements = placement_rows([model.frames[fid].placement for fid in self.frames])
        self.nv = model.nv

    def kinematics(self, model: pin.Model) -> _core.Core | None:
        """A core with these frames and no loops (for `Core.frame_motion`), or None where it
        disagrees with `model` (`agrees`)."""
        none = np.zeros((0, 3))
        core = _core.Core(self.types, self.parents, self.placements, self.axes, self.frame_parents,
                          self.frame_placements, [], [], [], none, none, [], [], [], [], [], [], np.ones(self.nv),
                          [], [], DEFAULT_TOL)
        return core if agrees(core, self, model, []) else None


def core_for(solver) -> _core.Core | None:
    """The compiled core of a `LoopSolver` (built once, again when the model's placements
    or the tolerance changed), or None where the core cannot rebuild the model, or its
    rebuilt model disagrees with the Python one (then the Python path solves it all)."""
    if not ENABLED:
        return None
    cached = solver.__dict__.get("_compiled")
    if cached is not None and cached[0] == solver.tol and cached[1].matches(solver.model):
        return cached[2]
    copy = ModelCopy(solver.model, [f for c in solver.mechanism.closures for f in (c.parent_frame, c.child_frame)])
    core = _build(solver)
    solver.__dict__["_compiled"] = (solver.tol, copy, core)
    return core


def _build(solver) -> _core.Core | None:
    closures = solver.mechanism.closures
    if not closures or solver.model.nv == 0:
        return None
    built = compile_loops(solver.model, closures, solver.mechanism.velocity_scale(), tol=solver.tol,
                          drv_v=solver._drv_v, dep_v=solver._dep_v, drv_q=solver._drv_q,
                          blocks=solver.structure.blocks)
    return None if built is None else built[0]


def compile_loops(model: pin.Model, closures: list, v_scale: np.ndarray, *, extra_frames: list[int] = (),
                  tol: float = DEFAULT_TOL, drv_v=(), dep_v=(), drv_q=(), blocks=()):
    """A core of the model with its loop closures (rows as the Closure objects state them)
    and the frames asked, with the drivers' and dependent joints' indices for sweeps:
    (core, its CompiledModel), or None where the core cannot rebuild the model."""
    frames = [f for c in closures for f in (c.parent_frame, c.child_frame)] + list(extra_frames)
    try:
        compiled = CompiledModel(model, frames)
    except KeyError:
        return None
    for c in closures:  # what the core copies stays as it is (as CutEvaluator does)
        c.__dict__["_in_use"] = True
    rows6 = [np.ascontiguousarray(c._rows6, dtype=float) for c in closures]
    full = [np.ascontiguousarray(c.selected * c._scale(), dtype=float) for c in closures]
    axes = np.array([c.axis for c in closures], dtype=float).reshape(-1, 3)
    child_axes = np.array([c.child_axis for c in closures], dtype=float).reshape(-1, 3)
    core = _core.Core(
        compiled.types, compiled.parents, compiled.placements, compiled.axes,
        compiled.frame_parents, compiled.frame_placements,
        [CUT_CODES[c.cut_type] for c in closures],
        [compiled.frames[c.parent_frame] for c in closures], [compiled.frames[c.child_frame] for c in closures],
        axes, child_axes, rows6, full, [int(v) for v in drv_v], [int(v) for v in dep_v],
        [int(i) for i, _ in drv_q], [int(c) for _, c in drv_q], np.asarray(v_scale, dtype=float),
        [list(map(int, b.rows)) for b in blocks], [list(map(int, b.cols)) for b in blocks], float(tol),
    )
    return (core, compiled) if agrees(core, compiled, model, closures) else None


def agrees(core: _core.Core, compiled: CompiledModel, model: pin.Model, closures: list) -> bool:
    """Whether the rebuilt model is the Python one: the same coordinates, and at a seeded
    random configuration the same frame placements and closure rows and Jacobians (to
    1e-12 of their size; the same formulas in another order agree to 1e-15). A rebuild
    that differs (a joint type read wrongly, an axis) leaves the model to the Python path
    instead of giving other numbers."""
    same = (core.nq == model.nq and core.nv == model.nv
            and core.idx_q == [model.joints[j].idx_q for j in range(1, model.njoints)]
            and core.idx_v == [model.joints[j].idx_v for j in range(1, model.njoints)])
    if not same:
        return False
    rng = np.random.default_rng(20261122)
    q = pin.integrate(model, pin.neutral(model), rng.uniform(-1.0, 1.0, model.nv))
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    fids = list(compiled.frames)
    zeros = np.zeros((1, model.nv))
    P, R = core.frame_motion(q[None], zeros, zeros, list(range(len(fids))))[:2]
    want_P = np.array([data.oMf[f].translation for f in fids]).reshape(1, -1)
    want_R = np.array([data.oMf[f].rotation.reshape(9) for f in fids]).reshape(1, -1)
    size = 1.0 + float(np.abs(want_P).max(initial=0.0))
    if not (np.abs(P - want_P).max(initial=0.0) <= 1e-12 * size and np.abs(R - want_R).max(initial=0.0) <= 1e-12):
        return False
    if not closures:
        return True
    r = np.concatenate([c.residual(data) for c in closures])
    J = np.vstack([c.jacobian(model, data) for c in closures])
    scale = 1.0 + max(float(np.abs(r).max()), float(np.abs(J).max()))
    return bool(np.abs(core.residual(q) - r).max() <= 1e-12 * scale
                and np.abs(core.jacobian(False) - J).max() <= 1e-12 * scale)
