"""Whether a pose Newton found from a user's guess is on the reference's assembly.

The assembly signature (branches.py) names one of a block's assemblies only where the
block has two: a block of several loops solved together (a Stephenson six-bar driven at
its far crank: four assemblies, two of each sign) has more than one sign can tell apart.
The complete check is the definition itself: the reference's assembly at the asked driver
values is the pose continuation reaches from the reference (continuation.py); the pose
from the guess is on it when it is that pose. Both are first taken to rounding by Newton,
so that the comparison does not depend on the closure tolerance: two poses of one root
then differ by about residual / sigma_min (sigma_min the dependent Jacobian's smallest
singular value, dimensionless), two roots by about sigma_min or more.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.solve.continuation import Route
from pinmech.solve.closure_check import value_text
from pinmech.solve.core import core_for
from pinmech.exceptions import AssemblyError, PinmechError

#: Newton iterations taking a closed pose to rounding (it is closed to `tol` already:
#: quadratic convergence needs two or three).
POLISH_ITERATIONS = 8
#: Two poses of one root differ by at most this many times residual / sigma_min (the
#: Newton correction's size, with room for the max-norms of a few rows); never less
#: than GAP_FLOOR (rad, or loop sizes).
GAP_FACTOR = 1e2
GAP_FLOOR = 1e-9


def check_guessed_pose(solver, q: np.ndarray, driver_q: np.ndarray,
                       start: tuple[np.ndarray, np.ndarray] | None = None) -> Route:
    """Raise AssemblyError unless q (closed at driver_q from a guess) is the pose that
    continuation from `solver.reference` (or from `start`, a closed pose on it and its
    driver values) reaches there. Leaves the solver's data at q.

    Returns:
        the continuation's route (its change points, if it passed any).

    Raises:
        AssemblyError: q is another pose (both named, with their largest joint gap), or
            the reference's assembly cannot be followed to driver_q (its reason chained).
    """
    ref = solver.reference
    q0, x0 = start if start is not None else (ref.q, ref.driver_q)
    route = Route(tuple(x0.tolist()))
    where = solver.describe_drivers(driver_q)
    try:
        continued = solver.follow(q0, x0, driver_q, route)
    except PinmechError as exc:
        raise AssemblyError(
            f"{solver.mechanism.source}: at {where} the pose from the guess cannot be checked against the "
            f"reference's assembly, which cannot be followed there from "
            f"{solver.describe_drivers(x0)}: {exc}", expected=ref.signs, found=(),
            drivers=solver.drivers, value=tuple(driver_q.tolist())) from exc
    q_guess, res_guess, sigma = _polished(solver, q, driver_q)
    q_cont, res_cont, _ = _polished(solver, continued, driver_q)
    gap, joint = _largest_gap(solver, q_guess, q_cont)
    bound = max(GAP_FLOOR, GAP_FACTOR * max(res_guess, res_cont) / sigma) if sigma > 0 else GAP_FLOOR
    if gap > bound:
        raise AssemblyError(
            f"{solver.mechanism.source}: at {where} the pose from the guess is on another assembly than the "
            f"reference's (a signature need not tell them apart): joint {joint} is {_joint_value(solver, joint, q_guess)} "
            f"there and {_joint_value(solver, joint, q_cont)} on the reference's assembly, followed by continuation "
            f"from {solver.describe_drivers(x0)} (a gap of {gap:.3g} rad or loop sizes, where one pose "
            f"would differ by {bound:.1g} at most): solve without a guess, or use a second solver for the other "
            f"assembly", expected=ref.signs, found=(), drivers=solver.drivers, value=tuple(driver_q.tolist()))
    return route


def _polished(solver, q: np.ndarray, driver_q: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Newton with the drivers held while the residual decreases, at most
    POLISH_ITERATIONS (the compiled core's `close` with a zero tolerance): (q, its
    residual, the smallest singular value of the dimensionless dependent Jacobian there)."""
    compiled = core_for(solver)
    x = np.asarray(driver_q, dtype=float)
    tol, compiled.tol = compiled.tol, 0.0
    try:
        q = compiled.close(solver.set_drivers(q, x), x, POLISH_ITERATIONS, True)[0]
    finally:
        compiled.tol = tol
    norm = float(np.max(np.abs(compiled.residual(q)), initial=0.0))
    sigma = float(compiled.rates_at(q, np.zeros(len(x)), np.zeros(len(x)))[4])
    return q, norm, sigma


def _largest_gap(solver, q0: np.ndarray, q1: np.ndarray) -> tuple[float, str]:
    """The largest joint difference (angles modulo a turn [rad], slides in loop sizes) and
    the joint where it is."""
    import pinocchio as pin

    dv = pin.difference(solver.model, q0, q1)
    best, name = 0.0, ""
    for joint_name, joint in solver.mechanism.joints.items():
        for i in range(joint.idx_v, joint.idx_v + joint.nv):
            d = float(dv[i])
            d = math.remainder(d, 2 * math.pi) if joint.is_angular else d * float(solver._v_scale_inv[i])
            if abs(d) > best:
                best, name = abs(d), joint_name
    return best, name


def _joint_value(solver, name: str, q: np.ndarray) -> str:
    """A joint's value as a user reads it: degrees, metres, or its coordinates."""
    joint = solver.mechanism.joint(name)
    if joint.nv != 1:
        return str(np.round(q[joint.idx_q:joint.idx_q + joint.nq], 6).tolist())
    value = solver.mechanism.coordinate(q, name)
    return value_text(joint.is_angular, value)
