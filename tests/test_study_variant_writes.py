"""A study variant's dimensions written into the user's own pin.Model in place (no SE3
copied), read back through fresh lookups and through the next solve against the
law-of-cosines four-bar; and a batch whose middle variant is outside its bounds."""

from __future__ import annotations

import math
from pathlib import Path

import closed_form
import numpy as np
import pinocchio as pin

from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.variant import StudyMechanism
from pinmech.design.study.tolerance import Batch, deviation, solve_variants
from tests.tolerance import rounding

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
ORDER = ("crank", "ground", "coupler", "rocker")  # the study's params: a, d, b, c of the four-bar
WHERE = {"crank": {"joint": "A"}, "ground": {"joint": "O4"}, "coupler": {"cut": "B", "side": "parent"},
         "rocker": {"cut": "B", "side": "child"}}


def _study(params: dict) -> StudyMechanism:
    table = {name: {**WHERE[name], "component": "x", **params.get(name, {})} for name in ORDER}
    raw = {"scene": "../scenes/four_bar.toml", "kind": "tolerance", "steps": 37, "samples": 1, "seed": 1,
           "batch": 10, "params": table, "outputs": {"points": ["P"], "links": ["rocker"]}}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def _closed_outputs(theta2: np.ndarray, a: float, d: float, b: float, c: float) -> np.ndarray:
    """P (60, 30) mm on the coupler [m] and theta4 [rad], by the law of cosines
    (scripts/closed_form.py, no Pinocchio), the open assembly of the scene."""
    fb = closed_form.four_bar(theta2, 0.0, 0.0, a, b, c, d, +1)
    c3, s3 = np.cos(fb.theta3), np.sin(fb.theta3)
    return np.column_stack([a * np.cos(theta2) + 0.06 * c3 - 0.03 * s3, a * np.sin(theta2) + 0.06 * s3 + 0.03 * c3,
                            fb.theta4])


def _assert_closed_form(sm: StudyMechanism, y: np.ndarray, p: np.ndarray) -> None:
    """y (steps, 3) is the closed-form four-bar of lengths p: P to 1e-11 m and theta4 to
    1e-10 rad (the loop closed to 1e-13 m, times the condition number < 100; as
    tests/test_tolerance.py)."""
    expected = _closed_outputs(sm.values, *p)
    np.testing.assert_allclose(y[:, :2], expected[:, :2], rtol=0, atol=1e-11)
    np.testing.assert_allclose(deviation(y[:, 2:], expected[:, 2:], ["angle"]), 0.0, rtol=0, atol=1e-10)


def _fresh(model: pin.Model, place) -> float:
    """The placement's component [m] read through a new lookup of the model's vectors."""
    if not place.frames:
        return float(model.jointPlacements[place.joint].translation[place.component])
    return float(model.frames[place.frames[0]].placement.translation[place.component])


def test_written_origins_are_in_the_model_and_in_the_next_solve():
    """Each of the four-bar's lengths written 2 to 5 mm off the nominal (two joint origins,
    the two sides of the cut B): a fresh `model.jointPlacements[j]` / `model.frames[f]`
    reads the value written (a joint origin exactly; a cut frame to 1e-16 m, the write
    moves it by the shift value - old: two roundings of 1e-17 m at 0.1 m), and the next
    solve over the cycle is the law-of-cosines four-bar of those lengths."""
    sm = _study({})
    outputs = StudyOutputs(sm)
    p = np.array([0.045, 0.097, 0.115, 0.083])  # a, d, b, c [m]
    cycle = sm.within(p)
    for place, value in zip(sm.placements, p):
        if place.frames:
            assert abs(_fresh(sm.model, place) - value) <= rounding(value)
        else:
            assert _fresh(sm.model, place) == value
    assert not cycle.cause
    _assert_closed_form(sm, outputs.cycle(cycle.q, cycle.v, cycle.a), p)


def test_a_write_lands_after_frames_are_added_to_the_model():
    """The placements keep the model's own vectors, not their elements: 300 frames added to
    the model afterwards (its frame vector reallocated) and a write still lands in
    model.frames[f] and model.jointPlacements[j], read through fresh lookups."""
    sm = _study({})
    for i in range(300):
        sm.model.addFrame(pin.Frame(f"extra{i}", 1, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    for place, value in zip(sm.placements, (0.041, 0.099, 0.121, 0.079)):
        place.write(value)
        assert abs(_fresh(sm.model, place) - value) <= rounding(value)  # as above: one shift for a cut frame


def test_a_variant_outside_bounds_mid_batch_keeps_its_cause_and_the_next_one_is_solved():
    """A batch of three crank lengths with bounds 39.9 .. 40.1 mm: 40.05, 40.5 (outside), 39.95 mm.
    The middle one is "outside bounds" (the message names it, in mm, as before the batch's
    bounds were checked at once), its outputs are NaN and it is not written; the first and
    the last are each the closed-form four-bar of their own crank (the last closed from the
    nominal's start pose, not from the rejected one); the model is left at the nominal."""
    sm = _study({"crank": {"bounds": ["39.9 mm", "40.1 mm"]}})
    outputs = StudyOutputs(sm)
    p = np.tile(sm.nominal, (3, 1))
    p[:, 0] = (0.04005, 0.0405, 0.03995)
    result = solve_variants(sm, outputs, Batch(0, 0, 3), p)
    assert result.causes == ("", "outside bounds", "")
    assert sm.cycle(p[1]).detail == "params.crank: 40.5 mm is outside 39.9 .. 40.1 mm"
    assert np.all(np.isnan(result.y[1]))
    for i in (0, 2):
        _assert_closed_form(sm, result.y[i], p[i])
    assert [_fresh(sm.model, place) for place in sm.placements] == sm.nominal.tolist()
    assert math.isclose(sm.nominal[0], 0.04, abs_tol=rounding(0.04))  # the scene's crank, 40 mm
