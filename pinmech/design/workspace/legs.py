"""The legs of a parallel mechanism, for a workspace study: which joints and closure rows
each motor's leg owns, and its working mode (the sign of its "elbow").

A leg is a motor joint hanging from the base and every joint below it; its one loop cut
joins its tip to the platform (or to the leg that carries the end point). With its cut's
rows (dimensionless, as the compiled core's Jacobian) over its own joints' columns the leg has a square
block B; the tip's motion B = [m | P] splits into the motor's column m and the passive
joints' columns P. The leg is serially singular (type I) where m falls into the span of P:
with n the normal of that span, oriented along the leg's last bar (from its first passive
joint to its tip), the working mode sign is sign(m . n). For a planar RR leg this is the
sign of sin(elbow angle); for a Delta's arm and forearm, which side of the forearm the arm
swings. Oriented by the bar, not by the joint coordinates, the sign does not change with a
universal joint's two parametrisations of one bar direction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.exceptions import SceneError
from pinmech.model.mechanism import Mechanism

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class Leg:
    """One motor's leg.

    Attributes:
        motor: the motor joint's name; joints: its Pinocchio joint ids (motor first).
        cols: their velocity indices (motor first); rows: its cut's rows among the stacked
            closure rows; closure: that cut's index; frame, partner: the cut's frame on the
            leg and the one it meets; elbow: the first passive joint's id.
    """

    motor: str
    joints: tuple[int, ...]
    cols: np.ndarray
    rows: np.ndarray
    closure: int
    frame: int
    partner: int
    elbow: int


def _refused(message: str, path: str) -> SceneError:
    """The study file's scene is not a parallel mechanism a workspace study can map."""
    return SceneError(message, path=path, key="scene")


def find_legs(mechanism: Mechanism, motors: tuple[str, ...], where: str) -> tuple[Leg, ...]:
    """The legs of `motors`, or a SceneError (key "scene") saying why the mechanism is not parallel."""
    model = mechanism.model
    if len(motors) < 2:
        raise _refused(f"a workspace study needs a parallel mechanism of 2 or 3 motors, one a leg; "
                             f"{mechanism.source} is driven by {len(motors)} ({', '.join(motors) or 'none'})",
                             path=where)
    offsets = np.cumsum([0] + [c.rows for c in mechanism.closures])
    legs = tuple(_leg(mechanism, name, offsets, where) for name in motors)
    owned = [j for leg in legs for j in leg.joints]
    if len(owned) != len(set(owned)):
        raise _refused("the motors' legs share joints: not a parallel mechanism of one motor a leg", path=where)
    if any(model.joints[j].nv != 1 for j in owned):
        raise _refused("a leg has a joint of several freedoms: give one-freedom joints", path=where)
    return legs


def _leg(mechanism: Mechanism, motor: str, offsets: np.ndarray, where: str) -> Leg:
    model = mechanism.model
    jid = model.getJointId(motor)
    if model.parents[jid] != 0:
        raise _refused(f"motor '{motor}' does not hang from the base (its parent joint is "
                             f"'{model.names[model.parents[jid]]}'): not a leg of a parallel mechanism", path=where)
    joints = [jid] + [j for j in range(jid + 1, model.njoints) if _below(model, j, jid)]
    cuts = []
    for k, c in enumerate(mechanism.closures):
        for frame, partner in ((c.child_frame, c.parent_frame), (c.parent_frame, c.child_frame)):
            if model.frames[frame].parentJoint in joints:
                cuts.append((k, frame, partner))
    rows = np.concatenate([np.arange(offsets[k], offsets[k + 1]) for k, *_ in cuts]) if cuts else np.zeros(0, int)
    if len(cuts) != 1 or len(rows) != len(joints):
        raise _refused(f"motor '{motor}''s leg ({len(joints)} joints) meets {len(cuts)} loop cuts with "
                             f"{len(rows)} rows: a workspace study needs one cut a leg, as many rows as joints",
                             path=where)
    k, frame, partner = cuts[0]
    cols = np.array([model.joints[j].idx_v for j in joints])
    return Leg(motor, tuple(joints), cols, rows, k, frame, partner, joints[1])


def _below(model: pin.Model, j: int, ancestor: int) -> bool:
    while j > 0:
        if j == ancestor:
            return True
        j = model.parents[j]
    return False


def mode_sign(mechanism: Mechanism, data: pin.Data, leg: Leg) -> float:
    """m . n of the leg at the pose in `data` (joint Jacobians and frames placed): its sign
    is the working mode, 0 a type I singularity of the leg. The leg's block is its tip's own
    motion (not the cut's relative motion, which mixes in the other side's while the loop is
    open) seen through the cut's rows; scaled by |m|, it is the cosine of the angle between
    the motor's tip motion and the normal of what the passive joints can do."""
    block = _tip_rows(mechanism, data, leg)
    m, passive = block[:, 0], block[:, 1:]
    u, _, _ = np.linalg.svd(passive, full_matrices=True)
    n = u[:, -1]
    if n @ _bar_rows(mechanism, data, leg) < 0:
        n = -n
    norm = float(np.linalg.norm(m))
    return float(m @ n) / norm if norm > 0 else 0.0


def passive_conditioning(mechanism: Mechanism, data: pin.Data, leg: Leg) -> float:
    """sigma_min / sigma_max of the leg's passive columns (1 for a single column): near 0 the
    passive joints' coordinates are singular themselves (a universal joint's bar along its
    second hinge), where the mode sign means nothing."""
    sigma = np.linalg.svd(_tip_rows(mechanism, data, leg)[:, 1:], compute_uv=False)
    return float(sigma[-1] / sigma[0]) if sigma[0] > 0 else 0.0


def _tip_rows(mechanism: Mechanism, data: pin.Data, leg: Leg) -> np.ndarray:
    """(rows, leg joints): the leg's tip motion (linear / loop size, angular) in the cut's rows."""
    c = mechanism.closures[leg.closure]
    jac = pin.getFrameJacobian(mechanism.model, data, leg.frame, _LWA)[:, leg.cols]
    R_T = data.oMf[c.parent_frame].rotation.T
    return c.rows6 @ np.vstack([R_T @ jac[:3], R_T @ jac[3:]])


def _bar_rows(mechanism: Mechanism, data: pin.Data, leg: Leg) -> np.ndarray:
    """The leg's last bar (first passive joint -> tip) as the cut's rows see a tip motion."""
    c = mechanism.closures[leg.closure]
    bar = data.oMf[leg.frame].translation - data.oMi[leg.elbow].translation
    return c.rows6 @ np.concatenate((data.oMf[c.parent_frame].rotation.T @ bar, np.zeros(3)))


def set_angles(model: pin.Model, q: np.ndarray, joints: tuple[int, ...], theta: np.ndarray) -> None:
    """Write one-freedom joints' coordinates theta [rad or m] into q in place."""
    for j, t in zip(joints, theta):
        joint = model.joints[j]
        if joint.nq == 2:  # unbounded revolute: (cos, sin)
            q[joint.idx_q : joint.idx_q + 2] = (np.cos(t), np.sin(t))
        else:
            q[joint.idx_q] = t


def angles(model: pin.Model, q: np.ndarray, joints: tuple[int, ...]) -> np.ndarray:
    """One-freedom joints' coordinates [rad (in (-pi, pi] if unbounded) or m] in q."""
    out = []
    for j in joints:
        joint = model.joints[j]
        i = joint.idx_q
        out.append(np.arctan2(q[i + 1], q[i]) if joint.nq == 2 else q[i])
    return np.array(out)
