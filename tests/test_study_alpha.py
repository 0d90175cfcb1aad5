"""A link's angular acceleration as a study output: its value against Norton's closed form
for the four-bar's rocker (derived here from the loop equation, not from pinmech), and its
exact sensitivity (the implicit-function theorem on the acceleration closure rows,
design/study/accel_sensitivity.py) against central differences of that closed form in the link
lengths, and against central differences of variants re-solved from scratch."""

from __future__ import annotations

from pathlib import Path

import closed_form
import numpy as np
import pytest

from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.variant import StudyMechanism
from pinmech.exceptions import SceneError
from tests.conftest import length_slopes

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
OMEGA2 = 4 * np.pi  # the scene's 120 rpm, constant: alpha2 = 0


def norton_alpha4(theta2: np.ndarray, a: float, b: float, c: float, d: float) -> np.ndarray:
    """Norton (Design of Machinery, eq. 7.12): differentiating a e^{i th2} + b e^{i th3}
    - c e^{i th4} - d = 0 twice in time and splitting real and imaginary parts,

        A alpha3 ... : alpha4 = (C E - B F) / (A E - B D),
        A = c sin th4, B = b sin th3, D = c cos th4, E = b cos th3,
        C = a alpha2 sin th2 + a w2^2 cos th2 + b w3^2 cos th3 - c w4^2 cos th4,
        F = a alpha2 cos th2 - a w2^2 sin th2 - b w3^2 sin th3 + c w4^2 sin th4,

    with w3, w4 from the first derivative (eq. 6.18). Only the positions th3, th4 come from
    the law-of-cosines solution (scripts/closed_form.py), on the scene's open assembly."""
    fb = closed_form.four_bar(theta2, OMEGA2, 0.0, a, b, c, d, +1)
    t3, t4, w2, al2 = fb.theta3, fb.theta4, OMEGA2, 0.0
    w3 = a * w2 / b * np.sin(t4 - theta2) / np.sin(t3 - t4)
    w4 = a * w2 / c * np.sin(theta2 - t3) / np.sin(t4 - t3)
    A, B, D, E = c * np.sin(t4), b * np.sin(t3), c * np.cos(t4), b * np.cos(t3)
    C = a * al2 * np.sin(theta2) + a * w2**2 * np.cos(theta2) + b * w3**2 * np.cos(t3) - c * w4**2 * np.cos(t4)
    F = a * al2 * np.cos(theta2) - a * w2**2 * np.sin(theta2) - b * w3**2 * np.sin(t3) + c * w4**2 * np.sin(t4)
    return (C * E - B * F) / (A * E - B * D)


def _four_bar(outputs: dict, steps: int = 37) -> StudyMechanism:
    raw = {"scene": "../scenes/four_bar.toml", "kind": "sensitivity", "steps": steps, "outputs": outputs,
           "params": {"crank": {"joint": "A", "component": "x"}, "ground": {"joint": "O4", "component": "x"},
                      "coupler": {"cut": "B", "side": "parent", "component": "x"},
                      "rocker": {"cut": "B", "side": "child", "component": "x"}}}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def test_rocker_alpha_and_its_sensitivity_are_nortons_closed_form():
    """The bundled four-bar (a, b, c, d) = (40, 120, 80, 100) mm at 120 rpm: alpha4 at 37
    poses of a turn equals Norton's formula (values up to ~500 rad/s^2; tolerance 1e-8
    rad/s^2: both are exact up to the closure tolerance 1e-13 of the loop times
    omega2^2 / length ~ 1e3), and d(alpha4)/dp for each length equals central
    differences of Norton's formula. Reference step 1e-6 m: truncation (1e-6/0.04)^2 ~
    6e-10 relative, rounding 1e-16 * 500 / 1e-6 ~ 5e-8 rad/s^2/m against |d alpha4/dp|
    up to ~2e4 rad/s^2/m. The exact derivative carries rounding times the loop's
    condition number: tolerance 1e-7 of the largest (measured 2e-9, the reference's own
    truncation)."""
    sm = _four_bar({"alpha": ["rocker"], "omega": ["rocker"]})
    outputs = StudyOutputs(sm)
    assert outputs.names == ["rocker.omega", "rocker.alpha"]
    assert outputs.kinds[-1] == "angular acceleration"
    cycle = sm.cycle(sm.nominal)
    y, dy = cycle_sensitivity(sm, outputs, cycle)
    nominal = np.array([0.04, 0.12, 0.08, 0.10])  # a, b, c, d
    expected = norton_alpha4(cycle.values, *nominal)
    np.testing.assert_allclose(y[:, 1], expected, rtol=0, atol=1e-8)
    assert np.abs(expected).max() > 100  # a real acceleration, not a zero compared with a zero
    slopes = length_slopes(norton_alpha4, cycle.values, sm.spec.params, nominal, h=1e-6)
    np.testing.assert_allclose(dy[:, 1], slopes, rtol=0, atol=1e-7 * np.abs(slopes).max())
    for k, place in enumerate(sm.placements):  # the model keeps the nominal afterwards
        assert place.read() == sm.nominal[k]


@pytest.mark.parametrize("scene, params, links", [
    ("four_bar.toml", {"crank_y": ("joint", "A", "y"), "ground_y": ("joint", "O4", "y"), "rocker": ("cut", "B", "x"),
                       "coupler_y": ("cut", "B", "y")}, ["rocker", "coupler"]),
    ("slider_crank.toml", {"offset": ("joint", "slide", "y"), "rod": ("cut", "B", "x"), "crank": ("joint", "A", "x")},
     ["rod"]),
    ("r_rtr.toml", {"A_x": ("joint", "A", "x"), "C_ground": ("cut", "C", "x"), "C_y": ("cut", "C", "y")},
     ["link2", "link3"]),
    ("jansen_leg.toml", {"crank": ("joint", "A1", "x"), "F": ("cut", "F_pin", "x"), "B2": ("joint", "B2", "y")},
     ["foot_triangle"]),
])
def test_alpha_sensitivities_are_central_differences_of_resolved_variants(scene, params, links):
    """Every parameter kind on one loop (four-bar, slider-crank, R-RTR's cut frame on the
    ground) and on Jansen's three loops: d(alpha)/dp at 25 poses of a turn equals central
    differences of variants re-solved from scratch at p +- 1e-6 m (accelerations solved
    again at each pose). Truncation (h/L)^2 ~ 1e-9 relative, the closure tolerance 1e-13
    of the loop over h times omega^2 ~ 1e-7 relative at 3000 rpm: tolerance 1e-6 of each
    output's largest |d alpha/dp|."""
    table = {}
    for name, (target, element, axis) in params.items():
        table[name] = {target: element, "component": axis}
        if target == "cut":
            table[name]["side"] = "child" if name in ("F", "rocker", "C_y") else "parent"
    raw = {"scene": f"../scenes/{scene}", "kind": "sensitivity", "steps": 25, "params": table,
           "outputs": {"alpha": links}}
    sm = StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))
    out = StudyOutputs(sm)
    cycle = sm.cycle(sm.nominal)
    assert not cycle.cause, cycle.detail
    _, dy = cycle_sensitivity(sm, out, cycle)
    h, columns = 1e-6, []
    for k in range(len(sm.nominal)):
        ys = []
        for sign in (+1, -1):
            p = sm.nominal.copy()
            p[k] += sign * h
            c = sm.cycle(p)
            assert not c.cause, c.detail
            ys.append(out.cycle(c.q, c.v, c.a))
        columns.append((ys[0] - ys[1]) / (2 * h))
    sm.write(sm.nominal)
    expected = np.stack(columns, axis=-1)
    for j, name in enumerate(out.names):
        scale = np.abs(expected[:, j]).max()
        assert scale > 0
        np.testing.assert_allclose(dy[:, j], expected[:, j], rtol=0, atol=1e-6 * scale, err_msg=name)


def test_alpha_is_an_output_of_planar_links_only():
    with pytest.raises(SceneError, match=r"outputs.alpha: unknown link 'bogus'"):
        StudyOutputs(_four_bar({"alpha": ["bogus"]}, steps=3))
