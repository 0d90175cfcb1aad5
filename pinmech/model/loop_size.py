"""A mechanism's size [m]: each loop's (the scale of its closure tolerance) and the whole's."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError
from pinmech.model.closures import Closure


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
