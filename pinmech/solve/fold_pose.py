"""The closed pose at a fold of a driver (a toggle: a rocker's or a non-Grashof crank's
limit angle), located to rounding.

At a fold the driver x cannot move on: the loop's Jacobian in the dependent joints is
singular, and q varies as sqrt(x_fold - x), so no pose taken at driver values short of
the fold gives q at it better than the square root of the distance. A dependent joint
that moves there (the pivot s, the joint fastest along the path before the fold) is a
regular parameter of the same curve: with the pivot driven instead of x, x(s) is smooth
and has its extreme at the fold, so Newton on dx/ds = 0 (the driver's rate and
acceleration per unit pivot rate, d2x/ds2, from the same solver) lands on it in a few
steps, and q there to the closure's rounding.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.solve.continuation import Route

#: Newton on dx/ds = 0 stops when a step in s is below this [rad or sizes of the pivot].
S_TOL = 1e-15
_ITERATIONS = 40


def fold_pose(solver, k: int, driver_q: np.ndarray, q0: np.ndarray, x0: float, estimate: float
              ) -> tuple[float, np.ndarray]:
    """(the driver's value at the fold [rad or m], the closed q there), from a closed
    pose q0 at driver value x0 before it on the sweep's assembly.

    Args:
        solver: the sweep's `LoopSolver` (its mechanism and options).
        k: the swept driver's index among `solver.drivers`; driver_q: every driver's value.
        estimate: the fold's driver value as the engine located it (to about 1e-12).

    Raises:
        PinmechError: no dependent joint is a regular parameter there, or Newton did not land.
    """
    from pinmech.solve.loops import LoopSolver

    mech = solver.mechanism
    q0 = _near(solver, k, driver_q, q0, x0, estimate)  # where x(s) is its quadratic: Newton's ground
    unit = np.zeros(len(solver.drivers))
    unit[k] = 1.0
    pivot = _pivot(solver, solver._rates(q0, unit, np.zeros(len(unit)), limit=math.inf)[0])  # ill-conditioned there
    names = [n for i, n in enumerate(solver.drivers) if i != k] + [pivot]
    by_pivot = LoopSolver(mech, names, tol=solver.tol, max_iterations=solver.max_iterations,
                          max_condition=solver.max_condition, kernel=solver.kernel)
    held = [float(x) for i, x in enumerate(driver_q) if i != k]
    v_in = np.zeros(len(names))
    v_in[-1] = 1.0
    x_idx = mech.joint(solver.drivers[k]).idx_v
    q, s = q0.copy(), mech.coordinate(q0, pivot)
    for _ in range(_ITERATIONS):
        v, a, _ = by_pivot.rates(q, v_in, np.zeros(len(names)))
        if a[x_idx] == 0.0:
            break
        step = -v[x_idx] / a[x_idx]
        q, step = _step(by_pivot, q, held, s, step)
        s += step
        if abs(step) <= S_TOL * max(1.0, abs(s)):
            return mech.coordinate(q, solver.drivers[k]), q
    raise PinmechError(f"{mech.source}: the fold of {solver.drivers[k]} could not be located from the pose "
                       f"before it (Newton with {pivot} as the parameter did not converge)")


def _near(solver, k: int, driver_q: np.ndarray, q0: np.ndarray, x0: float, estimate: float) -> np.ndarray:
    """The closed pose a little short of the fold (a millionth of the way from x0 left,
    or the nearest share that closes), followed from q0 on the sweep's assembly."""
    a, b = np.array(driver_q, dtype=float), np.array(driver_q, dtype=float)
    a[k] = x0
    for share in (1e-6, 1e-4, 1e-2, 1e-1):
        b[k] = estimate - share * (estimate - x0)
        try:
            return solver.follow(q0, a, b, Route(tuple(a.tolist())))
        except PinmechError:
            continue
    return q0


def _step(by_pivot, q: np.ndarray, held: list[float], s: float, step: float) -> tuple[np.ndarray, float]:
    """q moved by `step` of the pivot (halved until the pose closes on the curve)."""
    for _ in range(30):
        try:
            return by_pivot.follow(q, np.array(held + [s]), np.array(held + [s + step]), Route(tuple(held + [s]))), step
        except PinmechError:
            step *= 0.5
    raise PinmechError(f"{by_pivot.mechanism.source}: no pose of the curve near the fold closes")


def _pivot(solver, d1: np.ndarray) -> str:
    """The one-coordinate dependent joint moving fastest per unit driver motion (scaled)."""
    mech = solver.mechanism
    scale = mech.velocity_scale()
    best, name = -1.0, None
    for v, scalar in zip(solver._dep_v, solver.dep_is_scalar):
        joint = next((j for j in mech.joints.values() if j.nv == 1 and j.idx_v == v), None)
        if not scalar or joint is None:
            continue
        speed = abs(d1[v]) / scale[v]
        if speed > best:
            best, name = speed, joint.name
    if name is None:
        raise PinmechError(f"{mech.source}: no one-coordinate dependent joint to locate a fold by")
    return name
