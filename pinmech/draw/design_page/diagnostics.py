"""The diagnostics panel of the page, read from the poses the turn already swept (no second
sweep): the engine's planar linkage, dyads and outputs (`DesignSweep`, the ones `pinmech
sweep` reports), each loop's Grashof class (and a four-bar's Barker type), each dyad's
transmission angle at every pose (the engine's `dyad_angles` on the swept frames,
`swept.py`) with its least and largest value located between the poses, the outputs' limit
positions (drawn as ghosts) located from the swept rates, swing or stroke and the time ratio
Q, and the folds where the turn stopped (`swept_extremes.py`: one closing solve each).
Angles leave here in degrees, lengths in metres.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.solve.barker import barker_class
from pinmech.solve.limit_positions import travel


def turn_diagnostics(turn) -> dict:
    """The panel's data for a solved turn (`frame.Turn`): JSON-ready."""
    from pinmech.draw.design_page.swept import SweptLinkage, unit_rates
    from pinmech.solve.diagnostics_sweep import DesignSweep
    from pinmech.solve.transmission import dyad_angles

    design = DesignSweep(turn.sweep)
    if not design.applicable:
        return {"applicable": False, "reason": design.reason}
    x, q, dq, ddq = unit_rates(turn)
    swept = SweptLinkage(design.linkage, q, dq, ddq)
    whole = turn.sweep.is_angular and len(x) == len(turn.values)  # a whole turn: its ends are one pose
    folds = _fold_poses(design, turn, x, q)
    mu = [np.full(len(turn.values), np.nan) for _ in design.dyads]
    dyads = []
    for d, series in zip(design.dyads, mu):
        angles = dyad_angles(swept, d)
        series[:len(x)] = angles.mu_acute
        dyads.append(_dyad(design, d, x, q, angles.mu, series, folds, whole))
    return {
        "applicable": True,
        "loops": [_loop(c, turn) for c in _loop_classes(design.linkage)],
        "dyads": dyads,
        "outputs": [_output(design, o, _limits(design, swept, o, x, q, whole), turn) for o in design.outputs],
        "folds": [{"driver": fx, "points": ghost_points(turn, fq)} for fx, fq in folds],
    }


def _limits(design, swept, output, x, q, whole: bool) -> list:
    """The output's limit positions over the swept poses (each once a turn), with their poses."""
    from pinmech.draw.design_page.swept_extremes import limit_poses
    from pinmech.solve.diagnostics_sweep import once_a_turn

    if output.kind == "pin":
        rate, change = swept.turn_rate(output.output)
    else:
        slide = output.ground
        sign = 1.0 if slide.links[1] == output.output else -1.0
        rate, change = swept.slide_rate(output.output, swept.direction(slide.links[0], slide.axis), sign)
    return once_a_turn(limit_poses(design, output, x, q, rate, change), whole)


def _fold_poses(design, turn, x: np.ndarray, q: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """(driver value, closed q) at the fold where the turn stopped, located from the pose
    before it (the engine's `fold_pose`); none where it cannot be located."""
    from pinmech.solve.fold_pose import fold_pose

    out = []
    for index, fold in turn.folds.items():
        if index == 0 or index > len(x):
            continue
        try:
            out.append(fold_pose(design.solver, design.k, design.finder.x, q[index - 1], float(x[index - 1]), fold))
        except PinmechError:
            continue
    return out


def _loop_classes(linkage) -> list:
    from pinmech.solve.grashof import loop_classes

    return loop_classes(linkage)


def _loop(loop, turn) -> dict:
    """A loop's class; a four-bar's Barker type with its input the link the driver turns."""
    out = {"kind": loop.kind, "links": list(loop.links), "class": loop.label, "condition": loop.condition,
           "cranks": list(loop.cranks)}
    if loop.kind == "four-bar":
        ground, a, coupler, c = loop.links
        driven = turn.sweep.mechanism.joint(turn.sweep.driver).child_link
        first, last = (a, c) if driven != c else (c, a)
        lengths = loop.lengths
        barker = barker_class(lengths[ground], lengths[first], lengths[coupler], lengths[last])
        out["barker"] = f"{barker.name} {barker.code}"
        out["input"] = first
    return out


def _dyad(design, dyad, x, q, mu: np.ndarray, acute: np.ndarray, folds: list, whole: bool) -> dict:
    """A dyad's acute transmission angle over the turn [deg], its least and largest value of
    mu on [0, 180] deg and where, the largest pressure angle (the folds' poses included:
    the ends of the motion)."""
    from pinmech.draw.design_page.swept_extremes import Extreme, angle_extreme
    from pinmech.solve.transmission import dyad_angles

    low, high = angle_extreme(design, dyad, x, q, mu, 1.0, whole), angle_extreme(design, dyad, x, q, mu, -1.0, whole)
    for fx, fq in folds:
        design.linkage.place(fq)
        at = float(dyad_angles(design.linkage, dyad).mu)
        low = Extreme(at, fx, True) if at < low.value else low
        high = Extreme(at, fx, True) if at > high.value else high
    return {"name": dyad.name(design.linkage), "pin": dyad.joint.name, "kind": dyad.kind,
            "mu": [None if math.isnan(v) else v for v in acute.tolist()],
            "least": low.value, "least_at": low.at, "largest": high.value, "largest_at": high.at,
            "pressure": max(90.0 - low.value, high.value - 90.0), "refined": low.refined and high.refined}


def _output(design, output, found: list, turn) -> dict:
    """An output's limit positions (each a ghost: every drawn point there), swing or stroke, Q."""
    name = design.linkage.names[output.output]
    span = 2 * math.pi if turn.sweep.is_angular else None
    limits = [limit for limit, _ in found]
    t = travel(limits, span)
    labelled = {(x.driver, x.value): x.label for x in (t.limits if t else ())}
    return {
        "name": name, "kind": output.kind,
        "limits": [{"label": labelled.get((x.driver, x.value), x.label), "kind": x.kind, "driver": x.driver,
                    "value": x.value, "toggle": x.toggle, "points": ghost_points(turn, q)} for x, q in found],
        "travel": None if t is None else t.travel,
        "ratio": None if t is None else t.ratio,
    }


def ghost_points(turn, q: np.ndarray) -> dict[str, list[float]]:
    """Every drawn point's place [m] at a closed configuration q (a ghost of the linkage)."""
    from pinmech.solve.sweep_frames import frame_paths

    mech = turn.sweep.mechanism
    zero = np.zeros((1, mech.model.nv))
    try:
        paths = frame_paths(mech, turn.names, np.asarray(q, dtype=float)[None, :], zero, zero)
    except PinmechError:
        return {}
    return {n: paths.position[0, i, :2].tolist() for i, n in enumerate(turn.names)}
