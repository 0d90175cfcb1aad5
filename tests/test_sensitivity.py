"""Sensitivities by the implicit-function theorem, checked against finite differences.

Two references, neither of which uses the derivative formulas of pinmech/design/study/sensitivity.py:
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
from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.file import load_study, parse_study
from pinmech.design.study.variant import StudyMechanism
from pinmech.design.study.tolerance import deviation
from tests.tolerance import REGULAR, closure

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
SCENES = STUDIES.parent / "scenes"


def _study(scene: str, params: dict, points=(), links=(), steps: int = 25) -> StudyMechanism:
    raw = {"scene": f"../scenes/{scene}", "kind": "sensitivity", "steps": steps, "params": params,
           "outputs": {"points": list(points), "links": list(links)}}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def _implicit_and_differences(raw: dict, path: Path) -> tuple[StudyOutputs, np.ndarray, np.ndarray]:
    """The outputs of the sensitivity study `raw` (read as if at path), dy/dp over its
    nominal cycle by the implicit-function theorem, and central differences of re-solved
    variants (h = 1e-6 m), both (steps, n_out, n_par)."""
    sm = StudyMechanism(parse_study(raw, path))
    out = StudyOutputs(sm)
    cycle = sm.cycle(sm.nominal)
    assert not cycle.cause, cycle.detail
    _, dy = cycle_sensitivity(sm, out, cycle)
    return out, dy, _resolved_differences(sm, out, 1e-6)


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
            ys.append(outputs.cycle(cycle.q, cycle.v, cycle.a))
        columns.append(deviation(ys[0], ys[1], outputs.kinds) / (2 * h))  # angles: across +-pi too
    sm.write(sm.nominal)
    return np.stack(columns, axis=-1)


def test_four_bar_sensitivities_are_the_law_of_cosines_differentiated():
    """The bundled four-bar (a, b, c, d) = (40, 120, 80, 100) mm, P at (60, 30) mm on the
    coupler: d(theta4)/dp and dP/dp over one turn (every 5 deg) equal central differences
    of the closed form (law of cosines, circle intersection) in a, b, c, d. Step h = 1e-7 m
    (1e-6 of the 0.1 m loop): truncation h^2 |y'''| ~ 1e-12, rounding 1e-16 / 1e-6 ~ 1e-10
    rad/m; the IFT derivative carries the closure tolerance times the condition number
    (< 1e-10). Tolerance 1e-7 (rad/m or m/m) against values of order 10. The rocker's
    omega4 at 120 rpm (Norton's formula, closed_form.four_bar): its d/dp of order 600
    rad/s/m carries omega2 = 12.6 rad/s times those errors: tolerance 2e-6 rad/s/m."""
    sm = StudyMechanism(load_study(STUDIES / "four_bar_sensitivity.toml"))
    outputs = StudyOutputs(sm)
    assert outputs.names == ["P.x", "P.y", "rocker.angle", "rocker.omega"]
    cycle = sm.cycle(sm.nominal)
    y, dy = cycle_sensitivity(sm, outputs, cycle)
    theta2, h = cycle.values, 1e-7

    def closed(a, b, c, d):
        fb = closed_form.four_bar(theta2, 4 * np.pi, 0.0, a, b, c, d, +1)  # 120 rpm
        A = a * np.stack([np.cos(theta2), np.sin(theta2)], axis=-1)
        c3, s3 = np.cos(fb.theta3), np.sin(fb.theta3)
        P = A + np.stack([0.06 * c3 - 0.03 * s3, 0.06 * s3 + 0.03 * c3], axis=-1)
        return np.column_stack([P, np.unwrap(fb.theta4), fb.omega4])

    nominal = np.array([0.04, 0.12, 0.08, 0.10])  # a, b, c, d
    np.testing.assert_allclose(y[:, :2], closed(*nominal)[:, :2], rtol=0, atol=closure(np.pi, REGULAR))  # the same assembly
    order = {"crank": 0, "coupler": 1, "rocker": 2, "ground": 3}  # study parameter -> (a, b, c, d)
    for k, param in enumerate(sm.spec.params):
        step = np.zeros(4)
        step[order[param.name]] = h
        expected = (closed(*(nominal + step)) - closed(*(nominal - step))) / (2 * h)
        np.testing.assert_allclose(dy[:, :3, k], expected[:, :3], rtol=0, atol=1e-7, err_msg=param.name)
        np.testing.assert_allclose(dy[:, 3, k], expected[:, 3], rtol=0, atol=2e-6, err_msg=param.name)


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
    _, dy = cycle_sensitivity(sm, outputs, cycle)
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
    with pytest.raises(SceneError, match=r"params.x.nominal: '0.1' .*"):
        _study("four_bar.toml", {"x": {"joint": "A", "component": "x", "nominal": "0.1"}}, ["P"])


@pytest.mark.parametrize("scene, params, outputs", [
    ("four_bar.toml", {"crank": ("joint", "A", "x"), "ground_y": ("joint", "O4", "y"), "rocker": ("cut", "B", "x"),
                       "coupler_y": ("cut", "B", "y")}, {"omega": ["rocker", "coupler"], "points": ["P"]}),
    ("slider_crank.toml", {"offset": ("joint", "slide", "y"), "rod": ("cut", "B", "x"), "crank": ("joint", "A", "x")},
     {"sliders": ["slide"], "omega": ["rod"]}),
    ("jansen_leg.toml", {"crank": ("joint", "A1", "x"), "F": ("cut", "F_pin", "x"), "B2": ("joint", "B2", "y")},
     {"omega": ["foot_triangle"]}),
])
def test_speed_sensitivities_are_central_differences_of_resolved_variants(scene, params, outputs):
    """A link's omega, a slider's s and s_dot at the scene's driver speed (four-bar 120 rpm,
    slider-crank 3000 rpm, Jansen's leg): d/dp by the implicit-function theorem on the
    velocity closure rows equals central differences of variants re-solved from scratch
    (their speeds solved again at each pose). h = 1e-6 m: the truncation error measured
    ~ 4e-7 of |dy/dp| ~ 500 rad/s/m at h = 1e-5 m falls as h^2 (4e-9 relative at 1e-6),
    rounding (closure tolerance 1e-13 of the loop over 2h) below 1e-7 relative; the
    tolerance 1e-6 of each output's largest |dy/dp| leaves a margin of 10 over both."""
    table = {}
    for name, (target, element, axis) in params.items():
        table[name] = {target: element, "component": axis}
        if target == "cut":
            table[name]["side"] = "child" if name in ("F", "rocker") else "parent"
    raw = {"scene": f"../scenes/{scene}", "kind": "sensitivity", "steps": 25, "params": table, "outputs": outputs}
    out, dy, expected = _implicit_and_differences(raw, STUDIES / "inline.toml")
    scale = np.abs(expected).max(axis=(0, 2))
    assert np.all(scale > 0)
    np.testing.assert_allclose(dy, expected, rtol=0, atol=1e-6 * scale.max())
    for j, name in enumerate(out.names):
        np.testing.assert_allclose(dy[:, j], expected[:, j], rtol=0, atol=1e-6 * scale[j], err_msg=name)


def _scene_with_a_point(tmp_path: Path) -> str:
    """The bundled four-bar scene with a point Q of its own on the rocker (`[points.Q]`)."""
    text = (SCENES / "four_bar.toml").read_text().replace('urdf = "../', f'urdf = "{SCENES.parent}/')
    (tmp_path / "four_bar_q.toml").write_text(text + '\n[points.Q]\nlink = "rocker"\nat = ["50 mm", "20 mm", "0 mm"]\n')
    return str(tmp_path / "four_bar_q.toml")


@pytest.mark.parametrize("scene, params, outputs", [
    # MJCF: a body's pos (the coupler's, its joint A's origin), a site (P), the <connect> anchor
    ("four_bar_mjcf.toml", {"coupler_pos_x": {"body": "coupler", "component": "x"},
                            "rocker_pos_y": {"body": "rocker", "component": "y"},
                            "P_x": {"point": "P", "component": "x"}, "P_y": {"point": "P", "component": "y"},
                            "anchor": {"cut": "B", "component": "x"}},
     {"points": ["P"], "links": ["rocker"], "omega": ["rocker"]}),
    # robot.yaml: joint origins of its URDF, a loop's frame as a point (the fixed link, and the
    # cut frame built there, move together), the loop by its cut name
    ("five_bar.toml", {"elbow1_x": {"joint": "elbow1", "component": "x"},
                       "mot2_x": {"joint": "mot2", "component": "x"},
                       "end_A": {"point": "closedloop1_A", "component": "x"},
                       "end_B": {"cut": "closedloop1_A\u2013closedloop1_B", "side": "child", "component": "x"}},
     {"points": ["closedloop1_A"], "links": ["distal2"]}),
    # a scene's own named point ([points.Q] on the rocker) as a parameter and an output
    ("tmp:four_bar_q", {"Q_x": {"point": "Q", "component": "x"}, "crank": {"joint": "A", "component": "x"}},
     {"points": ["Q", "P"], "omega": ["coupler"]}),
])
def test_mjcf_robot_yaml_and_scene_point_parameters_are_central_differences(tmp_path, scene, params, outputs):
    """Parameters of each model kind the issue names: dy/dp by the implicit-function theorem
    equals central differences of variants re-solved from scratch. h = 1e-6 m as for the
    URDF parameters above (truncation ~ (h/L)^2 ~ 1e-8 relative, rounding of the closure
    tolerance 1e-13 over 2h ~ 1e-7 relative); tolerance 1e-6 of each output's largest
    |dy/dp|, plus 1e-9 absolute for the outputs a parameter does not move."""
    path = _scene_with_a_point(tmp_path) if scene.startswith("tmp:") else f"{SCENES}/{scene}"
    raw = {"scene": path, "kind": "sensitivity", "steps": 13, "params": params, "outputs": outputs}
    out, dy, expected = _implicit_and_differences(raw, tmp_path / "inline.toml")
    scale = np.abs(expected).max(axis=(0, 2))
    assert np.abs(expected).max(axis=(0, 1)).min() > 1e-3  # every parameter moves some output
    for j, name in enumerate(out.names):
        np.testing.assert_allclose(dy[:, j], expected[:, j], rtol=0, atol=1e-6 * scale[j] + 1e-9, err_msg=name)


def test_transmission_angle_is_the_law_of_cosines_and_its_sensitivity_central_differences():
    """The four-bar's transmission angle mu at B (between the coupler B->A and the rocker
    B->O4) equals the law of cosines, cos mu = (b^2 + c^2 - |A O4|^2) / (2 b c), to 1e-12
    rad (the closure tolerance); d mu / dp for the four lengths equals central differences
    of re-solved variants (h = 1e-6 m, tolerance 1e-6 of the largest |d mu/dp| ~ 15 rad/m,
    as for the other outputs: truncation ~ (h/L)^2, rounding ~ 1e-13 L / h). The slider-
    crank's (mu = 90 deg - the rod's angle to the slide) is checked the same way."""
    params = {"crank": {"joint": "A", "component": "x"}, "ground": {"joint": "O4", "component": "x"},
              "coupler": {"cut": "B", "side": "parent", "component": "x"},
              "rocker": {"cut": "B", "side": "child", "component": "x"}}
    raw = {"scene": "../scenes/four_bar.toml", "kind": "sensitivity", "steps": 25, "params": params,
           "outputs": {"transmission": ["B"]}}
    sm = StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))
    out = StudyOutputs(sm)
    cycle = sm.cycle(sm.nominal)
    y, dy = cycle_sensitivity(sm, out, cycle)
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    L2 = a * a + d * d - 2 * a * d * np.cos(cycle.values)
    np.testing.assert_allclose(y[:, 0], np.arccos((b * b + c * c - L2) / (2 * b * c)), rtol=0, atol=closure(np.pi, REGULAR))
    expected = _resolved_differences(sm, out, 1e-6)
    np.testing.assert_allclose(dy, expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    raw = {"scene": "../scenes/slider_crank.toml", "kind": "sensitivity", "steps": 25,
           "params": {"offset": {"joint": "slide", "component": "y"}, "rod": {"cut": "B", "component": "x"},
                      "crank": {"joint": "A", "component": "x"}}, "outputs": {"transmission": ["B"]}}
    sm = StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))
    out = StudyOutputs(sm)
    _, dy = cycle_sensitivity(sm, out, sm.cycle(sm.nominal))
    expected = _resolved_differences(sm, out, 1e-6)
    np.testing.assert_allclose(dy, expected, rtol=0, atol=1e-6 * np.abs(expected).max())


def test_a_transmission_angle_names_a_dyad():
    raw = {"scene": "../scenes/four_bar.toml", "kind": "sensitivity", "steps": 5,
           "params": {"crank": {"joint": "A", "component": "x"}}, "outputs": {"transmission": ["A"]}}
    with pytest.raises(SceneError, match=r"inline.toml, outputs.transmission: 'A' is not the middle pin .*: B\)"):
        StudyOutputs(StudyMechanism(parse_study(raw, STUDIES / "inline.toml")))
