"""Many configurations at once on the configuration manifold: `pin.integrate` and
`pin.difference` row by row, on arrays for one-dof joints (the Hermite interpolation of
sweep poses, hermite.py, and finite differences in scripts)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def integrate_many(model: pin.Model, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """`pin.integrate` of each row of q (N, nq) by the row of dq (N, nv): on arrays for
    one-dof joints (prismatic, revolute, continuous stored as cos/sin), row by row through
    Pinocchio for any other joint."""
    out = np.empty_like(q)
    for joint in model.joints[1:]:
        iq, iv = joint.idx_q, joint.idx_v
        if joint.nq == joint.nv == 1:
            out[:, iq] = q[:, iq] + dq[:, iv]
        elif joint.nq == 2 and joint.nv == 1:
            c, s, w = q[:, iq], q[:, iq + 1], dq[:, iv]
            cw, sw = np.cos(w), np.sin(w)  # a rotation keeps (c, s) unit to rounding
            out[:, iq], out[:, iq + 1] = cw * c - sw * s, sw * c + cw * s
        else:
            return np.array([pin.integrate(model, a, b) for a, b in zip(q, dq)])
    return out


def difference_many(model: pin.Model, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """`pin.difference(q0[i], q1[i])` for each row: on arrays for one-dof joints."""
    out = np.empty((len(q0), model.nv))
    for joint in model.joints[1:]:
        iq, iv = joint.idx_q, joint.idx_v
        if joint.nq == joint.nv == 1:
            out[:, iv] = q1[:, iq] - q0[:, iq]
        elif joint.nq == 2 and joint.nv == 1:
            c0, s0, c1, s1 = q0[:, iq], q0[:, iq + 1], q1[:, iq], q1[:, iq + 1]
            out[:, iv] = np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
        else:
            return np.array([pin.difference(model, a, b) for a, b in zip(q0, q1)])
    return out
