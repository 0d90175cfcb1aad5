"""The diagnostics panel of the page, read from the sweep's own diagnostics
(`pinmech.solve.diagnostics_sweep.DesignSweep`, the ones `pinmech sweep` prints): each
loop's Grashof class (and a four-bar's Barker type), each dyad's transmission angle over
the turn with its least value (located between the poses), the outputs' limit positions
(drawn as ghosts), swing or stroke and the time ratio Q, and the folds where the turn
stopped. Angles leave here in degrees, lengths in metres.
"""

from __future__ import annotations

import math

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.solve.barker import barker_class
from pinmech.solve.limit_positions import travel


def turn_diagnostics(turn) -> dict:
    """The panel's data for a solved turn (`frame.Turn`): JSON-ready."""
    design = _design_sweep(turn.sweep)
    if not design.applicable:
        return {"applicable": False, "reason": design.reason}
    mu = [np.full(len(turn.values), np.nan) for _ in design.dyads]
    for pose in sweep_poses(turn):
        out = design.evaluate(pose)
        for series, angles in zip(mu, out.get("angles", ())):
            series[pose.index] = angles[1]
    linkage = design.linkage
    return {
        "applicable": True,
        "loops": [_loop(x, turn) for x in _loop_classes(linkage)],
        "dyads": [_dyad(d, x, series, linkage) for d, x, series in zip(design.dyads, design.angle_extremes(), mu)],
        "outputs": [_output(design, o, found, turn) for o, found in zip(design.outputs, design.limit_poses())],
        "folds": [{"driver": x, "points": ghost_points(turn, q)} for x, q in design.fold_poses()],
    }


def _design_sweep(sweep):
    """The sweep's diagnostics (`DesignSweep`), fed poses whose motion is their configuration."""
    from pinmech.solve.diagnostics_sweep import DesignSweep

    class ArrayDesign(DesignSweep):
        def _q(self, motion) -> np.ndarray:  # the turn's q row, carried as the pose's motion
            return motion

    return ArrayDesign(sweep)


def sweep_poses(turn) -> list:
    """The turn's poses as `pinmech sweep` yields them to its diagnostics (`SweepPose`), each
    carrying its configuration q in place of its motion (None where it failed)."""
    from pinmech.io.sweep import SweepPose

    out = []
    for i, value in enumerate(turn.values.tolist()):
        error = turn.errors.get(i)
        if error is not None:  # the turn stopped here: the poses after it were not solved
            out.append(SweepPose(i, value, None, None, f"{type(error).__name__}: {error}", fold=turn.folds.get(i)))
            break
        out.append(SweepPose(i, value, turn.q[i], None, note=turn.notes.get(i, "")))
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


def _dyad(dyad, extremes, series: np.ndarray, linkage) -> dict:
    """A dyad's acute transmission angle over the turn [deg] and its least value and where."""
    return {"name": dyad.name(linkage), "pin": dyad.joint.name, "kind": dyad.kind,
            "mu": [None if math.isnan(x) else x for x in series.tolist()],
            "least": extremes.low, "least_at": extremes.low_at, "largest": extremes.high,
            "largest_at": extremes.high_at, "pressure": extremes.pressure, "refined": extremes.refined}


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
