"""A joint dragged while the linkage is shown at a crank angle other than the drawn one:
the joint's drawn place is moved so that, at that crank angle, it is where the mouse is.

Each construction is carried back to the drawn pose by what does not change with it:
    compass   its two bases are where the turn has them at that angle (they are built
              before it): both lengths measured there, its side the triangle's there (a
              side changes only through a fold, where the turn stops);
    polar     its base there, its angle less the turn of the link it shares with its base;
    point     on the ground: the mouse; on the driven link: turned back about the link's
              pivot by the driver's turn; on a link carrying two other points: the rigid
              motion those two made, undone.
The new linkage is solved, and the joint must be under the mouse at that angle (within
POSED_TOL); where it is not (a base that moves with the joint, a slide's block), the drag
is refused, saying to return to the drawn pose.
"""

from __future__ import annotations

import math

import msgspec
import numpy as np

from pinmech.draw.design_page.edits import compass_to, with_joint, degrees, millimetres, move_joint
from pinmech.exceptions import ModelError
from pinmech.model.linkage_entries import Compass, Polar
from pinmech.model.linkage_spec import GROUND, LinkageSpec

#: How near the mouse a joint dragged at another crank angle must land [m]: the drawn place
#: is written to 1e-6 m (edits.DECIMALS), carried through lengths ~0.1 m and angles O(1).
POSED_TOL = 1e-5


def move_joint_posed(spec: LinkageSpec, turn, name: str, index: int, to: np.ndarray, source: str) -> LinkageSpec:
    """The spec with joint `name` drawn so that at pose `index` of `turn` it is at `to` [m].

    Raises:
        ModelError: a joint that cannot be carried back to the drawn pose (said with the way out).
    """
    if name not in spec.joints:
        raise ModelError(f"'{name}' is not a joint of the drawing", path=source, element="[joints]")
    to = np.asarray(to, dtype=float)[:2]
    at = {n: turn.position[index, k] for k, n in enumerate(turn.names)}
    drawn = {n: p[:2] for n, p in turn.linkage.points.items()}
    entry = spec.joints[name]
    if isinstance(entry, Compass):
        return with_joint(spec, name, compass_to(entry, to, at, name, source), source)
    if isinstance(entry, Polar):
        turned = _turn_of(name, entry.base, at, drawn, source)
        offset = to - at[entry.base]
        new = msgspec.structs.replace(entry, length=millimetres(float(np.hypot(*offset))),
                                      angle=degrees(math.atan2(offset[1], offset[0]) - turned))
        return with_joint(spec, name, new, source)
    return move_joint(spec, name, _drawn_place(turn, name, index, to, at, drawn, source), drawn, source)


def landed(turn, name: str, index: int, to: np.ndarray) -> bool:
    """Whether joint `name` is at `to` [m] at pose `index` of the new turn (POSED_TOL)."""
    if name not in turn.names or index >= len(turn.values):
        return False
    place = turn.position[index, turn.names.index(name)]
    return bool(np.all(np.isfinite(place)) and np.linalg.norm(place - np.asarray(to)[:2]) < POSED_TOL)


def refusal(name: str, angle: str, source: str) -> ModelError:
    """The error of a joint that cannot be dragged at this crank angle."""
    return ModelError(f"{name} cannot be moved to the mouse at {angle} (what it is built from moves with it): "
                      "return the crank to the drawn pose (0) to drag it", path=source, element=f"[joints] {name}")


def _turn_of(name: str, base: str, at: dict, drawn: dict, source: str) -> float:
    """How far [rad] the rigid pair (base, name) has turned from the drawn pose."""
    now, then = at[name] - at[base], drawn[name] - drawn[base]
    if abs(np.hypot(*now) - np.hypot(*then)) > POSED_TOL:
        raise ModelError(f"{name} is not on a link with its base {base}: return the crank to the drawn pose "
                         "(0) to drag it", path=source, element=f"[joints] {name}")
    return math.atan2(now[1], now[0]) - math.atan2(then[1], then[0])


def _drawn_place(turn, name: str, index: int, to: np.ndarray, at: dict, drawn: dict, source: str) -> np.ndarray:
    """Where a point joint must be drawn for it to be at `to` at pose `index`."""
    linkage, sweep = turn.linkage, turn.sweep
    links = [k for k, v in linkage.links.items() if name in v]
    if GROUND in links:
        return to
    driven = sweep.mechanism.joint(sweep.driver).child_link
    if driven in links and sweep.is_angular:
        pivot = next((n for n in linkage.links[driven] if n != name and n in at), None)
        if pivot is not None:
            return drawn[pivot] + _rotated(to - at[pivot], -(turn.values[index] - turn.values[0]))
    for link in links:
        others = [n for n in linkage.links[link] if n != name and n in at and np.all(np.isfinite(at[n]))]
        if len(others) >= 2:
            (p, q) = others[:2]
            turned = _turn_of(q, p, at, drawn, source)
            return drawn[p] + _rotated(to - at[p], -turned)
    raise ModelError(f"{name} has no link to carry it back to the drawn pose: return the crank to the drawn pose "
                     "(0) to drag it", path=source, element=f"[joints] {name}")


def _rotated(v: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])
