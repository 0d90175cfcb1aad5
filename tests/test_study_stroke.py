"""A slider's stroke (max - min of s over the cycle) as a study output, against the
slider-crank's closed form, and its sensitivity (the envelope theorem, design/study/stroke.py)
against that closed form differentiated by hand.

Offset slider-crank, crank r, rod l, offset e: the piston's extremes are where crank and
rod are in line (the outer and inner dead centres), at distances l + r and l - r from the
crank's pivot, so along the slide

    stroke = sqrt((l + r)^2 - e^2) - sqrt((l - r)^2 - e^2)        (2 r when e = 0)
    d/dr = (l + r) / S1 + (l - r) / S2,   d/dl = (l + r) / S1 - (l - r) / S2,
    d/de = -e / S1 + e / S2,              S1, S2: the two square roots.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.variant import StudyMechanism
from pinmech.exceptions import SceneError
from tests.tolerance import REGULAR, closure, rounding

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
R, L = 0.05, 0.15  # models/slider_crank.urdf: crank O-A, rod A-B [m]


def _slider_crank(offset_mm: float, steps: int = 70, outputs=None) -> StudyMechanism:
    raw = {"scene": "../scenes/slider_crank.toml", "kind": "sensitivity", "steps": steps,
           "outputs": outputs or {"strokes": ["slide"]},
           "params": {"crank": {"joint": "A", "component": "x"},
                      "rod": {"cut": "B", "side": "parent", "component": "x"},
                      "offset": {"joint": "slide", "component": "y", "nominal": f"{offset_mm} mm"}}}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def closed_stroke(r: float, l: float, e: float) -> tuple[float, np.ndarray]:
    """(stroke [m], d stroke / d(r, l, e) [m/m]) of the offset slider-crank (the module)."""
    s1, s2 = np.sqrt((l + r) ** 2 - e**2), np.sqrt((l - r) ** 2 - e**2)
    return s1 - s2, np.array([(l + r) / s1 + (l - r) / s2, (l + r) / s1 - (l - r) / s2, -e / s1 + e / s2])


@pytest.mark.parametrize("offset_mm", [10.0, 0.0, -25.0])
def test_stroke_and_its_sensitivity_are_the_closed_form(offset_mm):
    """The bundled slider-crank (r, l) = (50, 150) mm with its 10 mm offset, in line (2 r)
    and at -25 mm, over 70 poses of a turn (every 5.2 deg from 45 deg: the dead centres fall between the
    poses, so the extremes must be located, not read off the poses; reading them off
    would be wrong by up to ~1e-4 m). Stroke: tolerance 1e-14 m (the closure tolerance
    1e-13 of the loop's residual, which vanishes at Newton's last step; measured 6e-17 m).
    dStroke/dp: exact at both dead centres (the envelope theorem, the extremes located by
    the secant on ds/dtheta = 0), each ds/dp carrying rounding times the loop's condition
    number: tolerance 1e-12 m/m (measured 4e-16; golden section alone left 2e-9)."""
    sm = _slider_crank(offset_mm)
    outputs = StudyOutputs(sm)
    assert outputs.names == ["slide.stroke"] and outputs.kinds == ["length"]
    cycle = sm.cycle(sm.nominal)
    assert not cycle.cause, cycle.detail
    y, dy = cycle_sensitivity(sm, outputs, cycle)
    stroke, slopes = closed_stroke(R, L, offset_mm * 1e-3)
    if offset_mm == 0.0:
        assert stroke == pytest.approx(2 * R, abs=rounding(R))
    sampled = np.ptp(cycle.q[:, sm.mechanism.joints["slide"].idx_q])
    assert stroke - sampled > 1e-7  # the poses miss the dead centres: the test can tell
    np.testing.assert_allclose(y[:, 0], stroke, rtol=0, atol=closure(R + L))
    np.testing.assert_allclose(dy[:, 0], np.broadcast_to(slopes, (len(y), 3)), rtol=0, atol=closure(1.0, REGULAR, 1))


def test_a_stroke_names_a_prismatic_joint():
    with pytest.raises(SceneError, match=r"outputs.strokes: 'rod' is not a prismatic joint"):
        StudyOutputs(_slider_crank(10.0, steps=3, outputs={"strokes": ["rod"]}))


def test_every_tolerance_variants_stroke_is_the_closed_form_at_its_own_lengths():
    """A tolerance study (20 variants, sigma 0.5 mm on r, l and e): each variant's stroke
    equals sqrt((l+r)^2-e^2) - sqrt((l-r)^2-e^2) at its own sampled lengths (tolerance
    1e-13 m: the closure tolerance; the extremes located to the solver's precision)."""
    from pinmech.design.study.run import study

    raw = {"scene": "../scenes/slider_crank.toml", "kind": "tolerance", "steps": 70, "samples": 20, "seed": 7,
           "batch": 10, "outputs": {"strokes": ["slide"]},
           "params": {"crank": {"joint": "A", "component": "x", "sigma": "0.5 mm"},
                      "rod": {"cut": "B", "side": "parent", "component": "x", "sigma": "0.5 mm"},
                      "offset": {"joint": "slide", "component": "y", "sigma": "0.5 mm"}}}
    result = study(parse_study(raw, STUDIES / "inline.toml"), workers=0)
    p, y, causes = result.variants
    assert causes == [""] * 20
    expected = [closed_stroke(r, l, e)[0] for r, l, e in p]
    np.testing.assert_allclose(y[:, :, 0], np.broadcast_to(np.array(expected)[:, None], y.shape[:2]), rtol=0,
                               atol=closure(0.2))


def test_the_golden_section_fallback_locates_the_same_stroke(monkeypatch):
    """Where the secant from the poses leaves their bracket, golden section narrows it
    first (forced here): the same stroke and derivatives as the closed form (tolerances as
    above)."""
    from pinmech.design.study.stroke import Stroke

    monkeypatch.setattr(Stroke, "_from_poses", lambda self, q, i, lo, hi: (None, q[i]))
    sm = _slider_crank(10.0)
    outputs = StudyOutputs(sm)
    y, dy = cycle_sensitivity(sm, outputs, sm.cycle(sm.nominal))
    stroke, slopes = closed_stroke(R, L, 0.01)
    np.testing.assert_allclose(y[:, 0], stroke, rtol=0, atol=closure(R + L))
    np.testing.assert_allclose(dy[:, 0], np.broadcast_to(slopes, (len(y), 3)), rtol=0, atol=closure(1.0, REGULAR, 1))
