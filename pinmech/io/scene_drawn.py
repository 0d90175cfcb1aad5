"""A drawn model's pose (a linkage file's, an MJCF file's qpos0) as a scene's reference,
on the turn from which the scene's own pose is reached.

A driver angle names the crank's physical angle, so the drawn pose and the scene's pose are
one wherever their angles differ by whole turns (a crank drawn at -10.69 deg and a scene at
349.31 deg: no motion, no fold crossed). Otherwise the scene's pose is reached by
continuation the shorter way round; a rocker whose fold lies that way (it cannot pass 0
deg, say) is followed the other way round instead, which is the only way it can go.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.exceptions import DriverLimitError
from pinmech.model.mechanism import Mechanism
from pinmech.solve.loops import LoopSolver


def nearest_turn(mechanism: Mechanism, names: tuple[str, ...], drawn: list[float], asked: np.ndarray) -> list[float]:
    """The drawn driver values [rad or m], each angle moved by whole turns to within half a
    turn of the scene's value."""
    out = []
    for name, value, target in zip(names, drawn, np.asarray(asked, dtype=float).tolist()):
        if mechanism.joint(name).is_angular and math.isfinite(target):
            value += 2 * math.pi * round((target - value) / (2 * math.pi))
        out.append(value)
    return out


def set_drawn_reference(solver: LoopSolver, mechanism: Mechanism, asked: np.ndarray, assembly) -> None:
    """Make the drawn pose the solver's reference, on the turn from which the scene's
    driver values `asked` [rad or m] are reached (module doc): the shorter way round, else
    (one angular driver meeting a fold) the other. Where neither reaches them, the shorter
    way stays, and the solve that asks for them names its fold."""
    names = solver.drivers
    drawn = [mechanism.coordinate(mechanism.reference, name) for name in names]
    first = nearest_turn(mechanism, names, drawn, asked)
    solver.set_reference(first, mechanism.neutral(), assembly)
    moving = [k for k, (a, b) in enumerate(zip(first, np.asarray(asked, dtype=float).tolist())) if a != b]
    if len(moving) != 1 or not mechanism.joint(names[moving[0]]).is_angular:
        return
    k = moving[0]
    try:
        solver.solve(asked)
        return
    except DriverLimitError:
        pass
    other = list(first)
    other[k] += math.copysign(2 * math.pi, float(asked[k]) - first[k])
    solver.set_reference(other, mechanism.neutral(), assembly)
    try:
        solver.solve(asked)
    except DriverLimitError:
        solver.set_reference(first, mechanism.neutral(), assembly)
