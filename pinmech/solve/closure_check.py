"""Whether a pose's loops are closed, and the error that says how far open they are
(each cut's gap [m] and misalignment [deg]), in the user's words."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from pinmech.exceptions import LoopClosureError
from pinmech.model.closure_core import closure_rows
from pinmech.model.mechanism import Mechanism

#: A closure residual below this (relative to the size) is rounding, not a loop out of reach.
ROUNDING_LEVEL = 1e-14

def describe_joint_values(mechanism: Mechanism, names: Sequence[str], values: Sequence[float]) -> str:
    """One-dof joints' values as a user reads them in an error: angles in degrees, lengths
    in metres ("O2 = 90 deg, slide = 0.15 m"), each rounded to 1e-9 deg or 1e-12 m first:
    a driver a turn on at 360 deg, read back from its cos and sin as -1.4e-16 rad, is
    "0 deg", not "-1.40334186e-14 deg"."""
    return ", ".join(f"{name} = {value_text(mechanism.joint(name).is_angular, value)}"
                     for name, value in zip(names, values))


def value_text(angular: bool, value: float) -> str:
    """A one-dof joint's value [rad or m] as an error prints it: "90 deg" or "0.15 m", to
    10 significant figures after rounding to 1e-9 deg or 1e-12 m (describe_joint_values)."""
    if angular:
        return f"{round(math.degrees(value), 9) + 0.0:.10g} deg"
    return f"{round(value, 12) + 0.0:.10g} m"


def is_closed(independent, full, tol: float):
    """Whether a pose's loops are closed: its independent closure rows within `tol`, and
    every selected row (the ones reduced away as out of the plane too) within ten times
    max(tol, 1e-12), as `LoopSolver.close` accepts them (all dimensionless: lengths in
    loop sizes, angles in rad). Floats give a bool, arrays of poses an array of them."""
    return (independent <= tol) & (full <= max(tol, 1e-12) * 10)


def open_loops_error(mechanism: Mechanism, q: np.ndarray, residual: float, tol: float,
                     where: str) -> LoopClosureError:
    """The error for rates asked at a pose whose loops are open: each open loop's gap
    between its cut frames [m] and the misalignment of its axes [deg], the residual
    relative to the loop's size, and the tolerance."""
    rows_at = closure_rows(mechanism)
    errors, independent = rows_at.errors6(q), rows_at.residual(q)
    said = []
    for c, r6, at in zip(mechanism.closures, errors, rows_at.slices):
        if is_closed(float(np.max(np.abs(independent[at]), initial=0.0)),
                     float(np.max(np.abs(c.selected_rows6 @ r6), initial=0.0)), tol):
            continue
        rows = c.selected
        gap = float(np.linalg.norm(rows[:, :3] @ r6[:3]))  # the distance its rows constrain [m]
        turn = float(np.linalg.norm(rows[:, 3:] @ r6[3:]))  # rad, or the sine of the axes' angle
        angle = math.degrees(math.asin(min(turn, 1.0)) if c.cut_type == "revolute" else turn)
        said.append(f"loop {c.name}'s cut frames are {gap:.3g} m apart ({gap / c.length_scale:.3g} of its size, "
                    f"{c.length_scale:.3g} m)" + (f", axes {angle:.3g} deg apart" if rows[:, 3:].any() else ""))
    return LoopClosureError(
        f"{mechanism.source}: {where}: the loops are open: {'; '.join(said)} (largest closure row "
        f"{residual:.3g}, tolerance {tol:g}, both of the loop's size); rates hold only where the loops "
        "are closed: close them first (LoopSolver.solve or close) and pass that q",
        residual=float(residual), iterations=0, partial=q)


def max_abs(x: np.ndarray) -> float:
    """Largest |x_i| (0 when empty); plain Python below 9 entries, where numpy's call costs more."""
    if x.size < 9:
        return max(map(abs, x.tolist()), default=0.0)
    return float(np.max(np.abs(x)))


def not_closed_error(mechanism: Mechanism, q: np.ndarray, norm: float, solved: float, tol: float, iterations: int,
                     where: str) -> LoopClosureError:
    """The error for loops Newton could not close at the drivers `where` (in the user's
    words): the residual left (`norm`, every selected row; `solved`, the rows Newton
    solves, both of the loop's size) and why, as far as the numbers tell."""
    names = ", ".join(c.name for c in mechanism.closures)
    if norm <= ROUNDING_LEVEL:
        why = f"that is rounding level: the tolerance {tol:g} is tighter than floating point allows"
    elif solved <= tol:
        why = ("the rows dropped as out of the mechanism's plane do not close: the two sides of the cut "
               "are not in one plane (check the z of the origins and the axes)")
    else:
        why = "the pose is out of reach for these dimensions, or the guess is on no branch"
    return LoopClosureError(
        f"{mechanism.source}: loop(s) {names} cannot be closed at {where} "
        f"(residual {norm:.3g} of the loop's size after {iterations} Newton iterations): {why}",
        residual=float(norm), iterations=iterations, partial=q)
