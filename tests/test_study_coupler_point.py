"""A coupler point dimensioned as a designer tolerances it: at R_PA = p from A and delta_3 =
gamma from the coupler's line A -> B (a bearing construction of the drawn linkage), with p
and gamma as study parameters.

Reference: Norton's four-bar (the law of cosines, scripts/closed_form.py) gives theta3;
then P = A + p (cos(theta3 + gamma), sin(theta3 + gamma)), so by hand
dP/dp = (cos, sin)(theta3 + gamma) and dP/dgamma = p (-sin, cos)(theta3 + gamma): the
coupler point does not move the loop.
"""

from __future__ import annotations

import math
from pathlib import Path

import closed_form
import numpy as np
import pytest

from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.variant import StudyMechanism
from pinmech.exceptions import SceneError
from pinmech.model.linkage import linkage_from_spec
from pinmech.model.linkage_spec import read_linkage_spec

MODELS = Path(__file__).resolve().parents[1] / "models"
STUDIES = MODELS / "studies"
P_LEN, GAMMA = math.hypot(0.06, 0.03), math.atan2(0.03, 0.06)  # the bundled file's p [m] and gamma [rad]


def test_a_bearing_construction_is_at_p_from_a_turned_gamma_from_ab():
    """The drawn P is A + p (cos, sin)(phi_AB + gamma), phi_AB the drawn coupler's angle
    (to 1e-16 m: one rotation of a 0.1 m vector)."""
    spec, source = read_linkage_spec(MODELS / "linkages" / "four_bar_coupler_point.toml")
    points = linkage_from_spec(spec, source).points
    A, B = points["A"], points["B"]
    phi = math.atan2(B[1] - A[1], B[0] - A[0]) + GAMMA
    np.testing.assert_allclose(points["P"], A + P_LEN * np.array([math.cos(phi), math.sin(phi)]), rtol=0, atol=2e-16)


def test_study_of_p_and_gamma_is_the_closed_form():
    """The bundled study: P over one turn (73 poses) is Norton's four-bar plus the bearing
    (1e-11 m: the loop closed to 1e-13 m times its condition number); dP/dp and dP/dgamma
    are the hand derivatives above. The study's drawing differences (step 1e-6 m or rad):
    truncation 1e-12 relative, rounding 1e-16 * 0.1 m / 1e-6 ~ 1e-11; tolerance 1e-8 (m/m,
    m/rad) against values of order 0.07. The rocker does not depend on p or gamma: its
    sensitivity 0 to the same 1e-8."""
    sm = StudyMechanism(parse_study({**_raw(), "kind": "sensitivity"}, STUDIES / "inline.toml"))
    assert [place.kind for place in sm.placements] == ["length", "angle", "length"]
    np.testing.assert_allclose(sm.nominal, [P_LEN, GAMMA, 0.04], rtol=0, atol=1e-15)
    cycle = sm.cycle(sm.nominal)
    y, dy = cycle_sensitivity(sm, StudyOutputs(sm), cycle)
    fb = closed_form.four_bar(sm.values, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10, +1)
    t = fb.theta3 + GAMMA
    A = 0.04 * np.column_stack([np.cos(sm.values), np.sin(sm.values)])
    np.testing.assert_allclose(y[:, :2], A + P_LEN * np.column_stack([np.cos(t), np.sin(t)]), rtol=0, atol=1e-11)
    np.testing.assert_allclose(dy[:, :2, 0], np.column_stack([np.cos(t), np.sin(t)]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(dy[:, :2, 1], P_LEN * np.column_stack([-np.sin(t), np.cos(t)]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(dy[:, 2, :2], 0.0, rtol=0, atol=1e-8)


def _raw() -> dict:
    return {"scene": "../scenes/four_bar_coupler_point.toml", "steps": 73,
            "params": {"p": {"param": "p"}, "gamma": {"param": "gamma"}, "crank": {"param": "crank"}},
            "outputs": {"points": ["P"], "links": ["rocker"]}}


def test_an_angle_param_takes_its_tolerance_in_degrees():
    """gamma toleranced "0.5 deg" at 3 sigma: sigma 0.5/3 deg in rad; "0.5 mm" on it is
    refused by name."""
    raw = {**_raw(), "kind": "tolerance", "samples": 4}
    raw["params"] = {**raw["params"], "gamma": {"param": "gamma", "tolerance": "0.5 deg"}}
    sm = StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))
    np.testing.assert_allclose(sm.spec.params[1].sigma, math.radians(0.5) / 3, rtol=1e-15)
    raw["params"]["gamma"] = {"param": "gamma", "tolerance": "0.5 mm"}
    with pytest.raises(SceneError, match=r"gamma is an angle.*give them in deg"):
        StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


@pytest.mark.parametrize("unit, error", [("deg", None), ("mm", r"gamma is an angle: give from and to in deg")])
def test_a_grid_over_an_angle_param_is_in_degrees(unit, error):
    """gamma from 20 to 30 deg in 3 points: P at each is the bearing's; in mm: refused."""
    raw = {**_raw(), "kind": "grid", "steps": 5, "params": {"gamma": {"param": "gamma"}},
           "grid": {"gamma": {"from": f"20 {unit}", "to": f"30 {unit}", "count": 3}}}
    spec = parse_study(raw, STUDIES / "inline.toml")
    if error:
        with pytest.raises(SceneError, match=error):
            StudyMechanism(spec)
        return
    np.testing.assert_allclose(spec.grid[0].values, np.radians([20.0, 25.0, 30.0]), rtol=1e-15)
    assert spec.grid[0].kind == "angle"
