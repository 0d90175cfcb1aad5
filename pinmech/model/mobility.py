"""Mobility from the rank of the loop constraint Jacobian on the closed configurations.

Counting rows (joint freedoms minus closure equations) is wrong when loops repeat each
other: a double parallelogram has 4 freedoms and 4 closure rows, yet it moves (mobility
1), because on its closed poses the rows have rank 3. Rank is a property of the closed
configurations, not of arbitrary ones, so this module first closes the loops (least
squares from the reference configuration), then takes the largest rank of the scaled
constraint Jacobian over a few closed poses around it (an isolated singular pose has a
lower rank than its neighbours; a structural redundancy has it everywhere).

It also finds idle freedoms: motions the closures allow with every driver held, such as a
rod with ball joints at both ends spinning about its own axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.model.closure_core import closure_rows
from pinmech.seeded import Seeded

#: Singular values below this fraction of the largest count as zero (dimensionless rows).
RANK_TOL = 1e-8
_CLOSE_TOL = 1e-12
_NEIGHBOURS = 3
_STEP = 0.05  # [rad, or sizes of the mechanism]: how far the neighbouring poses lie


@dataclass(frozen=True)
class RankReport:
    """The constraint Jacobian's rank on the closed configurations.

    Attributes:
        rank: largest rank over the closed poses sampled (the generic rank).
        rows: number of closure rows (after each cut's own reduction).
        q: a closed configuration (None when none could be found: then rank = rows).
        redundant: names of the cuts whose rows repeat the others' (some row of theirs
            adds nothing to the rank).
    """

    rank: int
    rows: int
    q: np.ndarray | None
    redundant: tuple[str, ...] = ()


def stacked_jacobian(mech, q: np.ndarray, scale: np.ndarray | None = None) -> np.ndarray:
    """Every closure's rows, stacked, with dimensionless columns (prismatic x size) at q;
    `scale`: the mechanism's `velocity_scale()`, when the caller has it already."""
    return closure_rows(mech).jacobian(q) * (mech.velocity_scale() if scale is None else scale)


def close_least_squares(mech, q: np.ndarray, iterations: int = 60,
                        scale: np.ndarray | None = None) -> np.ndarray | None:
    """Gauss-Newton with minimum-norm steps: a closed configuration near q, or None."""
    scale = mech.velocity_scale() if scale is None else scale
    rows = closure_rows(mech)
    for _ in range(iterations):
        r = rows.residual(q)
        if np.max(np.abs(r), initial=0.0) < _CLOSE_TOL:
            return q
        J = rows.jacobian(q) * scale
        step = np.linalg.lstsq(J, -r, rcond=1e-10)[0]
        size = np.max(np.abs(step), initial=0.0)
        if size > 0.5:
            step *= 0.5 / size
        q = pin.integrate(mech.model, q, step * scale)
    return None


def _rank(J: np.ndarray) -> int:
    if J.size == 0:
        return 0
    s = np.linalg.svd(J, compute_uv=False)
    return int(np.sum(s > RANK_TOL * max(s[0], 1e-300)))


def constraint_rank(mech) -> RankReport:
    """The generic rank of the closure rows on the closed poses near the reference (full
    rank on the first closed pose settles it: no other pose is sampled)."""
    rows = sum(c.rows for c in mech.closures)
    if rows == 0:
        return RankReport(0, 0, mech.neutral())
    scale = mech.velocity_scale()  # fixed while the rank is sought: computed once
    q0 = _closed_start(mech, scale)
    if q0 is None:
        return RankReport(rows, rows, None)
    J0 = stacked_jacobian(mech, q0, scale)
    if _rank(J0) == rows:  # no pose has more than full rank: the neighbours below could not raise it
        return RankReport(rows, rows, q0)
    rng = Seeded(20261122)
    poses = [q0]
    null = _null_space(J0)
    for _ in range(_NEIGHBOURS):
        if null.shape[1] == 0:
            break
        step = null @ rng.normal(size=null.shape[1])
        step *= _STEP / max(np.max(np.abs(step)), 1e-300)
        q = close_least_squares(mech, pin.integrate(mech.model, q0, step * scale), scale=scale)
        if q is not None:
            poses.append(q)
    if len(poses) == 1:  # no neighbour closed: other closed poses, so one singular pose cannot decide
        seeds = Seeded(11)
        for _ in range(4):
            start = pin.integrate(mech.model, q0, seeds.normal(size=mech.model.nv) * scale)
            q = close_least_squares(mech, start, scale=scale)
            if q is not None:
                poses.append(q)
    jacobians = [J0] + [stacked_jacobian(mech, q, scale) for q in poses[1:]]
    ranks = [_rank(J) for J in jacobians]
    best = int(np.argmax(ranks))
    rank = ranks[best]
    redundant = ()
    if rank < rows:
        J, start, names = jacobians[best], 0, []
        for c in mech.closures:
            others = np.vstack([J[:start], J[start + c.rows:]])
            if _rank(others) + c.rows > rank:
                names.append(c.name)
            start += c.rows
        redundant = tuple(names)
    return RankReport(rank, rows, poses[best], redundant)


def _closed_start(mech, scale: np.ndarray) -> np.ndarray | None:
    """The reference configuration, closed; else a few seeded starts around it."""
    q = close_least_squares(mech, mech.neutral(), scale=scale)
    rng = Seeded(7)
    for _ in range(3):
        if q is not None:
            return q
        start = pin.integrate(mech.model, mech.neutral(), rng.normal(size=mech.model.nv) * scale)
        q = close_least_squares(mech, start, scale=scale)
    return q


def _null_space(J: np.ndarray) -> np.ndarray:
    if J.shape[0] == 0:
        return np.eye(J.shape[1])
    _, s, Vt = np.linalg.svd(J)
    rank = int(np.sum(s > RANK_TOL * max(s[0], 1e-300))) if s.size else 0
    return Vt[rank:].T


def idle_joints(mech, drivers: list[str], q: np.ndarray | None) -> list[str]:
    """Joints that can move while every driver is held, largest share first.

    Each motion of the null space of the dependent columns of the constraint Jacobian is
    named by the joint carrying most of it (e.g. the ball joint of a spinning rod).
    """
    if q is None:
        return []
    J = stacked_jacobian(mech, q)
    held = {mech.joints[n].idx_v for n in drivers if n in mech.joints}
    free = [i for i in range(mech.model.nv) if i not in held]
    null = _null_space(J[:, free])
    names: list[str] = []
    owner = {}
    for joint in mech.joints.values():
        for k in range(joint.nv):
            owner[joint.idx_v + k] = joint.name
    for column in null.T:
        share = np.abs(column)
        name = owner.get(free[int(np.argmax(share))], "?")
        if name not in names:
            names.append(name)
    return names


def moving_joints(mech, drivers: list[str], q: np.ndarray | None) -> list[str]:
    """Joints that move, with every driver held, in motions that carry some joint's
    origin along: the mechanism itself still moves (a freedom left undriven). Largest
    share first; [] when the only free motions turn links about axes through their joints
    (a rod spinning about its own axis: an idle freedom, `idle_joints`)."""
    if q is None:
        return []
    model, data = mech.model, mech.model.createData()
    scale = mech.velocity_scale()
    J = stacked_jacobian(mech, q, scale)
    pin.computeJointJacobians(model, data, q)
    held = {mech.joints[n].idx_v for n in drivers if n in mech.joints}
    free = [i for i in range(model.nv) if i not in held]
    null = _null_space(J[:, free])
    if null.shape[1] == 0:
        return []
    origins = np.vstack([pin.getJointJacobian(model, data, jid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)[:3]
                         for jid in range(1, model.njoints)]) * scale / mech.length_scale
    _, s, Wt = np.linalg.svd(origins[:, free] @ null)  # joint-origin speeds per unit free motion
    moving = null @ Wt[: int(np.sum(s > RANK_TOL * max(1.0, float(s[0]) if s.size else 0.0)))].T
    if moving.shape[1] == 0:
        return []
    share: dict[str, float] = {}
    for joint in mech.joints.values():
        cols = [k for k, i in enumerate(free) if joint.idx_v <= i < joint.idx_v + joint.nv]
        if cols:
            share[joint.name] = float(np.linalg.norm(moving[cols]))
    top = max(share.values(), default=0.0)
    return sorted((n for n, x in share.items() if x > 1e-6 * top), key=lambda n: -share[n])
