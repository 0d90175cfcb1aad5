"""Sensitivities by the implicit-function theorem, checked against finite differences.

Two references, neither of which uses the derivative formulas of pinmech/design/sensitivity.py:
- central differences of the closed-form four-bar (scripts/closed_form.py, the law of
  cosines), no pinmech at all;
- central differences of re-solved variants: each parameter written into the model at
  p +- h and the cycle solved again from scratch (closure tolerance 1e-13 of the loop).
"""

from __future__ import annotations

from pathlib import Path

import closed_form
import numpy as np
import pytest

from pinmech.exceptions import FrameNotFound, SceneError
from pinmech.design.sensitivity import StudyOutputs, cycle_sensitivity
from pinmech.design.study_file import load_study, parse_study
from pinmech.design.study_variant import StudyMechanism
from pinmech.design.tolerance import deviation

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
SCENES = STUDIES.parent / "scenes"


def _study(scene: str, params: dict, points=(), links=(), steps: int = 25) -> StudyMechanism:
    raw = {"scene": f"../scenes/{scene}", "kind": "sensitivity", "steps": steps, "params": params,
           "outputs": {"points": list(points), "links": list(links)}}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def _resolved_differences(sm: StudyMechanism, outputs: StudyOutputs, h: float) -> np.ndarray:
    """(steps, n_out, n_par) central differences of variants re-solved over the cycle at p +- h e_k."""
    columns = []
    for k in range(len(sm.nominal)):
        ys = []
        for sign in (+1, -1):
            p = sm.nominal.copy()
            p[k] += sign * h
            cycle = sm.cycle(p)  # leaves p in the model: the outputs are read on that variant
            assert not cycle.cause, cycle.detail
            ys.append(outputs.values(cycle.q))
        columns.append(deviation(ys[0], ys[1], outputs.kinds) / (2 * h))  # angles: across +-pi too
    sm.write(sm.nominal)
    return np.stack(columns, axis=-1)


def test_four_bar_sensitivities_are_the_law_of_cosines_differentiated():
    """The bundled four-bar (a, b, c, d) = (40, 120, 80, 100) mm, P at (60, 30) mm on the
    coupler: d(theta4)/dp and dP/dp over one turn (every 5 deg) equal central differences
    of the closed form (law of cosines, circle intersection) in a, b, c, d. Step h = 1e-7 m
    (1e-6 of the 0.1 m loop): truncation h^2 |y'''| ~ 1e-12, rounding 1e-16 / 1e-6 ~ 1e-10
    rad/m; the IFT derivative carries the closure tolerance times the condition number
    (< 1e-10). Tolerance 1e-7 (rad/m or m/m) against values of order 10."""
    sm = StudyMechanism(load_study(STUDIES / "four_bar_sensitivity.toml"))
    outputs = StudyOutputs(sm)
    assert outputs.names == ["P.x", "P.y", "rocker.angle"]
    cycle = sm.cycle(sm.nominal)
    y, dy = cycle_sensitivity(sm, outputs, cycle.q)
    theta2, h = cycle.values, 1e-7

    def closed(a, b, c, d):
        fb = closed_form.four_bar(theta2, 0.0, 0.0, a, b, c, d, +1)
        A = a * np.stack([np.cos(theta2), np.sin(theta2)], axis=-1)
        c3, s3 = np.cos(fb.theta3), np.sin(fb.theta3)
        P = A + np.stack([0.06 * c3 - 0.03 * s3, 0.06 * s3 + 0.03 * c3], axis=-1)
        return np.column_stack([P, np.unwrap(fb.theta4)])

    nominal = np.array([0.04, 0.12, 0.08, 0.10])  # a, b, c, d
    np.testing.assert_allclose(y[:, :2], closed(*nominal)[:, :2], rtol=0, atol=1e-12)  # the same assembly
    order = {"crank": 0, "coupler": 1, "rocker": 2, "ground": 3}  # study parameter -> (a, b, c, d)
    for k, param in enumerate(sm.spec.params):
        step = np.zeros(4)
        step[order[param.name]] = h
        expected = (closed(*(nominal + step)) - closed(*(nominal - step))) / (2 * h)
        np.testing.assert_allclose(dy[:, :, k], expected, rtol=0, atol=1e-7, err_msg=param.name)


@pytest.mark.parametrize("scene, params, points, links", [
    ("four_bar.toml", {"crank": ("joint", "A", "x"), "crank_y": ("joint", "A", "y"), "ground_y": ("joint", "O4", "y"),
                       "coupler_y": ("cut", "B", "y")}, ["P", "B_pin"], ["coupler", "rocker"]),
    ("four_bar.toml", {"O2_x": ("joint", "O2", "x"), "O2_y": ("joint", "O2", "y")}, ["P"], ["coupler"]),  # the driver's own origin
    ("r_rtr.toml", {"A_x": ("joint", "A", "x"), "B_y": ("joint", "B", "y"), "C_ground": ("cut", "C", "x"),
                    "C_y": ("cut", "C", "y")}, ["B", "D"], ["link2", "link3"]),  # a cut frame on the ground
    ("slider_crank.toml", {"offset": ("joint", "slide", "y"), "rod": ("cut", "B", "x"), "crank": ("joint", "A", "x")},
     ["B_pin"], ["rod"]),
    ("jansen_leg.toml", {"crank": ("joint", "A1", "x"), "rocker": ("joint", "D_pin", "x"),
                         "F": ("cut", "F_pin", "x"), "C": ("cut", "C_pin", "y"), "B2": ("joint", "B2", "y")},
     ["G", "C"], ["foot_triangle"]),
])
def test_sensitivities_are_central_differences_of_resolved_variants(scene, params, points, links):
    """Every parameter kind (a joint origin's x or y, the driver's own, either side of a cut,
    a cut frame on the ground, a prismatic joint's origin), on one loop and on Jansen's three: dy/dp at 25 poses of a turn equals
    central differences of variants re-solved from scratch. h = 1e-6 m (1e-5 of the loop):
    truncation (h/L)^2 ~ 1e-10 relative, the closure tolerance 1e-13 L over h gives
    ~1e-8 absolute; tolerance 1e-6 + 1e-6 relative."""
    table = {}
    for name, (target, element, axis) in params.items():
        table[name] = {target: element, "component": axis}
        if target == "cut":
            table[name]["side"] = "child" if name in ("F", "C_y") else "parent"
    sm = _study(scene, table, points, links)
    outputs = StudyOutputs(sm)
    cycle = sm.cycle(sm.nominal)
    assert not cycle.cause, cycle.detail
    _, dy = cycle_sensitivity(sm, outputs, cycle.q)
    expected = _resolved_differences(sm, outputs, 1e-6)
    np.testing.assert_allclose(dy, expected, rtol=1e-6, atol=1e-6)


def test_a_study_file_names_what_the_model_lacks():
    """A joint or a cut the model does not have, an unknown output, a length without a unit."""
    with pytest.raises(FrameNotFound, match=r"inline.toml, params.x.*unknown joint 'Q'"):
        _study("four_bar.toml", {"x": {"joint": "Q", "component": "x"}}, ["P"])
    with pytest.raises(FrameNotFound, match=r"unknown cut 'Z'"):
        _study("four_bar.toml", {"x": {"cut": "Z", "component": "x"}}, ["P"])
    with pytest.raises(SceneError, match=r"outputs.links: unknown link 'bogus'"):
        StudyOutputs(_study("four_bar.toml", {"x": {"joint": "A", "component": "x"}}, ["P"], ["bogus"]))
    with pytest.raises(SceneError, match=r"params.x.tolerance: '0.1' .*"):
        _study("four_bar.toml", {"x": {"joint": "A", "component": "x", "tolerance": "0.1"}}, ["P"])
