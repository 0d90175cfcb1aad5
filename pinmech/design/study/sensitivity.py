"""Exact first-order sensitivities of a study's outputs to its parameters, by the
implicit-function theorem on the loop-closure equations.

The closure residual r(q, p) = 0 holds on every variant; with the drivers held,

    J_dep dq_dep/dp + J_p = 0    =>    dq/dp = -J_dep^-1 J_p          (tangent space)

J_dep: the closure Jacobian's columns of the dependent joints (the compiled core's, the
derivative of the residual once the loop is closed). J_p, derived here: a parameter is a
translation component of a placement, so a unit change moves frames rigidly without
turning them. A joint origin translates the joint's whole subtree along u = R_parent e_k;
a cut frame's origin translates that frame alone along u = R_joint e_k. The cut's relative
position r = R_P^T (p_C - p_P) then changes by R_P^T (u_C - u_P), its orientation rows not
at all: J_p = rows6 @ [R_P^T (u_C - u_P); 0], the core's `translation_rows` times u_C - u_P.

An output y(q, p) (a point's world position, a link's angle in the plane, a slider's
coordinate) then has dy/dp = J_y dq/dp + dy/dp|_q, the last term u where the parameter
moves the point's frame (for a drawn linkage's param, J_p and dy/dp|_q are central
differences of the drawing at fixed q, drawn_params.py); speeds (a slider's, a link's
omega): rate_sensitivity.py; a link's angular acceleration: accel_sensitivity.py; a
driver's torque: central differences of re-solved variants (variant_differences.py).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.exceptions import SingularPoseError
from pinmech.design.study.accel_sensitivity import acceleration_sensitivity
from pinmech.design.study.rate_sensitivity import link_omega_sensitivity, velocity_sensitivity
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.stroke import stroke_sensitivity
from pinmech.design.study.variant import StudyMechanism, VariantCycle
from pinmech.design.study.variant_differences import central_differences
from pinmech.model.closure_core import closure_rows

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def parameter_jacobian(sm: StudyMechanism, data: pin.Data) -> np.ndarray:
    """J_p (rows, n_par): the closure residual's derivative w.r.t. each parameter at fixed q
    (`data` at sm.q_at, `StudyMechanism.at`, with frame placements up to date)."""
    rows = closure_rows(sm.mechanism)
    D = rows.translation_rows(sm.q_at)
    columns = []
    for place in sm.placements:
        if place.drawn:  # the drawing's central differences at fixed q (drawn_params.py)
            columns.append(place.column(lambda: rows.residual(sm.q_at)))
            continue
        u = place.direction(data)
        moved = [u * (place.moves_frame(c.child_frame, sm.subtree) - place.moves_frame(c.parent_frame, sm.subtree))
                 for c in sm.mechanism.closures]
        columns.append(np.concatenate([D[at] @ m for at, m in zip(rows.slices, moved)]))
    return np.array(columns).T


def configuration_sensitivity(sm: StudyMechanism, data: pin.Data) -> np.ndarray:
    """dq/dp on the tangent space (nv, n_par), drivers held: -J_dep^-1 J_p at the closed q
    of `data`. Raises SingularPoseError where J_dep is singular (a fold, a dead centre)."""
    model, mech, solver = sm.model, sm.mechanism, sm.solver
    J = closure_rows(mech).jacobian(sm.q_at)
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


def output_sensitivity(sm: StudyMechanism, outputs: StudyOutputs, q: np.ndarray, v: np.ndarray,
                       a: np.ndarray | None = None) -> np.ndarray:
    """dy/dp at the closed pose q with joint velocities v (and accelerations a: the
    alphas' rows too) [m/m, rad/m, per s per m, per s^2 per m]: the rows of the outputs
    before `outputs.strokes_at` (rate outputs: rate_sensitivity.py, accel_sensitivity.py)."""
    data = sm.at(q)
    Y_q, Y_p = outputs.jacobians(data)
    for k, place in enumerate(sm.placements):
        if place.drawn:  # the drawing's central differences at fixed q (drawn_params.py)
            Y_p[:, k] = place.column(lambda: outputs.pose_values(q))
    dq = configuration_sensitivity(sm, data)
    rows = [Y_q @ dq + Y_p]
    alpha = a is not None and bool(outputs.alpha)
    if outputs.sliders or outputs.omega or alpha:
        dv, dV = velocity_sensitivity(sm, q, v, dq, outputs.omega)
        rows += [dv[[iv for _, iv in outputs.sliders]]]
        rows += [link_omega_sensitivity(sm, f, outputs.normal, dV[i], dv)[None] for i, f in enumerate(outputs.omega)]
        if alpha:
            rows += [acceleration_sensitivity(sm, q, v, a, dq, dv, outputs.alpha)]
    return np.vstack(rows)


def cycle_sensitivity(sm: StudyMechanism, outputs: StudyOutputs, cycle: VariantCycle) -> tuple[np.ndarray, np.ndarray]:
    """The outputs (steps, n_out) and dy/dp (steps, n_out, n_par) at each pose of a solved
    cycle of the variant now written in the model. Exact but for the driver torques:
    central differences of re-solved variants (variant_differences.py)."""
    y = outputs.cycle(cycle.q, cycle.v, cycle.a)
    dy = np.zeros((*y.shape, len(sm.placements)))
    head = outputs.strokes_at.start
    if head:
        dy[:, :head] = [output_sensitivity(sm, outputs, qi, vi, ai) for qi, vi, ai in zip(cycle.q, cycle.v, cycle.a)]
    if outputs.strokes:  # the envelope theorem at each stroke's extremes (stroke.py)
        dy[:, outputs.strokes_at] = [stroke_sensitivity(sm, s, *s.extremes(cycle.q)[1::2],
                                                        lambda q: configuration_sensitivity(sm, sm.at(q)))
                                     for s in outputs.strokes]
    if outputs.torque_at.stop > outputs.torque_at.start:
        dy[:, outputs.torque_at] = central_differences(sm, outputs, outputs.torque_at)
    return y, dy
