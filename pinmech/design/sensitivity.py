"""Exact first-order sensitivities of a study's outputs to its parameters, by the
implicit-function theorem on the loop-closure equations.

The closure residual r(q, p) = 0 holds on every variant; with the drivers held,

    J_dep dq_dep/dp + J_p = 0    =>    dq/dp = -J_dep^-1 J_p          (tangent space)

J_dep: the closure Jacobian's columns of the dependent joints (`Closure.jacobian`, the
derivative of the residual once the loop is closed). J_p, derived here: a parameter is a
translation component of a placement, so a unit change moves frames rigidly without
turning them. A joint origin translates the joint's whole subtree along u = R_parent e_k;
a cut frame's origin translates that frame alone along u = R_joint e_k. The cut's relative
position r = R_P^T (p_C - p_P) then changes by R_P^T (u_C - u_P), its orientation rows not
at all: J_p = rows6 @ [R_P^T (u_C - u_P); 0].

An output y(q, p) (a point's world position, a link's angle in the plane) then has
dy/dp = J_y dq/dp + dy/dp|_q, the last term u where the parameter moves the point's frame.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.exceptions import SceneError, SingularPoseError
from pinmech.design.study_variant import StudyMechanism
from pinmech.solve.core import _core

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class StudyOutputs:
    """A study's outputs: names, values at a pose, and their derivatives.

    Attributes:
        names: "P.x", "P.y" (world position [m]; z too for a spatial mechanism),
            "rocker.angle" (the link's x axis about the plane normal [rad]).
    """

    def __init__(self, sm: StudyMechanism) -> None:
        mech, spec = sm.mechanism, sm.spec
        self.sm, self.normal = sm, mech.plane_normal
        if spec.links and self.normal is None:
            raise SceneError("link angles are outputs of planar mechanisms; name points instead", path=str(spec.path),
                             key="outputs.links")
        for name in spec.links:
            if name not in mech.links:
                raise SceneError(f"unknown link '{name}' (the model has: {', '.join(mech.links)})",
                                 path=str(spec.path), key="outputs.links")
        self.points = [mech.frame_id(_checked_point(mech, name, spec)) for name in spec.points]
        self.links = [mech.links[name] for name in spec.links]
        self.axes = _plane_axes(self.normal)
        self.names = [f"{n}.{'xyz'[k]}" for n in spec.points for k in self.axes] + [f"{n}.angle" for n in spec.links]
        self.kinds = ["length"] * (len(spec.points) * len(self.axes)) + ["angle"] * len(spec.links)
        if self.normal is not None:
            e1 = np.eye(3)[int(np.argmin(np.abs(self.normal)))]
            e1 = e1 - self.normal * (self.normal @ e1)
            self.e1 = e1 / np.linalg.norm(e1)
            self.e2 = np.cross(self.normal, self.e1)

    def values(self, q: np.ndarray) -> np.ndarray:
        """The outputs (N, n_out) at the poses q (N, nq) [m, rad]: the frames' placements
        from one compiled call for every pose (csrc/kinematics.cpp, at zero rates)."""
        q = np.ascontiguousarray(q, dtype=float)
        frames = np.array(self.points + self.links, dtype=np.int32)
        zero = np.zeros((len(q), self.sm.model.nv))
        rows = np.empty((len(q), len(frames), _core.KINEMATICS_COLUMNS))
        _core.frames_along(self.sm.model, self.sm.data, q, zero, zero, frames, rows)
        pos = rows[:, : len(self.points), 0:3][:, :, list(self.axes)].reshape(len(q), -1)
        x = rows[:, len(self.points):, 3:12:3]  # each link's x axis: the rotation's first column
        ang = np.arctan2(x @ self.e2, x @ self.e1) if self.links else np.zeros((len(q), 0))
        return np.concatenate((pos, ang), axis=1)

    def jacobians(self, data: pin.Data) -> tuple[np.ndarray, np.ndarray]:
        """(dy/dq on the tangent space (n_out, nv), dy/dp at fixed q (n_out, n_par))."""
        model, sm = self.sm.model, self.sm
        rows_q, rows_p = [], []
        for f in self.points:
            J = pin.getFrameJacobian(model, data, f, _LWA).reshape(6, -1)
            direct = np.array([place.direction(data) if place.moves_frame(f, sm.subtree) else np.zeros(3)
                               for place in sm.placements]).reshape(-1, 3).T
            rows_q += [J[k] for k in self.axes]
            rows_p += [direct[k] for k in self.axes]
        for f in self.links:
            J = pin.getFrameJacobian(model, data, f, _LWA).reshape(6, -1)
            rows_q.append(self.normal @ J[3:])
            rows_p.append(np.zeros(len(sm.placements)))
        return np.array(rows_q).reshape(-1, model.nv), np.array(rows_p).reshape(-1, len(sm.placements))


def parameter_jacobian(sm: StudyMechanism, data: pin.Data) -> np.ndarray:
    """J_p (rows, n_par): the closure residual's derivative w.r.t. each parameter at fixed q
    (`data` at q with frame placements up to date)."""
    columns = []
    for place in sm.placements:
        u = place.direction(data)
        rows = []
        for c in sm.mechanism.closures:
            u_P = u if place.moves_frame(c.parent_frame, sm.subtree) else np.zeros(3)
            u_C = u if place.moves_frame(c.child_frame, sm.subtree) else np.zeros(3)
            d6 = np.concatenate((data.oMf[c.parent_frame].rotation.T @ (u_C - u_P), np.zeros(3)))
            rows.append(c._rows6 @ d6)
        columns.append(np.concatenate(rows))
    return np.array(columns).T


def configuration_sensitivity(sm: StudyMechanism, data: pin.Data) -> np.ndarray:
    """dq/dp on the tangent space (nv, n_par), drivers held: -J_dep^-1 J_p at the closed q
    of `data`. Raises SingularPoseError where J_dep is singular (a fold, a dead centre)."""
    model, mech, solver = sm.model, sm.mechanism, sm.solver
    J = np.vstack([c.jacobian(model, data) for c in mech.closures])
    driven = {mech.driver_index(n) for n in solver.drivers}
    dep = [v for v in range(model.nv) if v not in driven]
    J_dep = J[:, dep]
    cond = np.linalg.cond(J_dep)
    if not cond < solver.max_condition:
        raise SingularPoseError(f"{sm.spec.path}: the closure Jacobian is singular at this pose (condition "
                                f"{cond:.3g} > {solver.max_condition:.3g}): no first-order sensitivity there",
                                condition=float(cond), sigma_min=float(np.linalg.svd(J_dep, compute_uv=False)[-1]))
    dq = np.zeros((model.nv, len(sm.placements)))
    dq[dep] = -np.linalg.solve(J_dep, parameter_jacobian(sm, data))
    return dq


def output_sensitivity(sm: StudyMechanism, outputs: StudyOutputs, q: np.ndarray) -> np.ndarray:
    """dy/dp (n_out, n_par) at the closed pose q [m/m, rad/m]."""
    data = sm.at(q)
    Y_q, Y_p = outputs.jacobians(data)
    return Y_q @ configuration_sensitivity(sm, data) + Y_p


def cycle_sensitivity(sm: StudyMechanism, outputs: StudyOutputs, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The outputs (steps, n_out) and dy/dp (steps, n_out, n_par) at each pose of a cycle."""
    y = outputs.values(q)
    dy = np.array([output_sensitivity(sm, outputs, qi) for qi in q])
    return y, dy


def _plane_axes(normal: np.ndarray | None) -> tuple[int, ...]:
    """World components reported for points: those in the plane when it is a coordinate plane."""
    if normal is None:
        return (0, 1, 2)
    axis = int(np.argmax(np.abs(normal)))
    return tuple(k for k in range(3) if k != axis) if abs(normal[axis]) > 1 - 1e-12 else (0, 1, 2)


def _checked_point(mech, name: str, spec) -> str:
    if name not in mech.points and name not in mech.links:
        raise SceneError(f"unknown point '{name}' (the model has: {', '.join(mech.points)})", path=str(spec.path),
                         key="outputs.points")
    return name
