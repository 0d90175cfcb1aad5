"""A drawn linkage's [params] as study parameters (design/study/drawn_params.py): a variant is
the linkage redrawn, its placements (rotations included) copied into the study's model.

References: Norton's four-bar closed form (the law of cosines, scripts/closed_form.py) in
the crank length, and central differences of variants re-solved from scratch (each one
redrawn at p +- h and its cycle solved again), neither of which uses the drawing's
derivative or the implicit-function theorem."""

from __future__ import annotations

from pathlib import Path

import closed_form
import numpy as np
import pytest

from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.variant import StudyMechanism
from pinmech.design.study.tolerance import deviation
from pinmech.exceptions import FrameNotFound, SceneError
from tests.tolerance import REGULAR, closure

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"


def _drawn(params: dict, outputs: dict, scene: str = "four_bar_drawn.toml", steps: int = 25) -> StudyMechanism:
    raw = {"scene": f"../scenes/{scene}", "kind": "sensitivity", "steps": steps, "params": params, "outputs": outputs}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def _theta4(theta2: np.ndarray, a: float) -> np.ndarray:
    """The rocker's angle of models/linkages/four_bar.toml (b, c, d) = (120, 80, 100) mm,
    open assembly (B left of A -> O4), crank a [m]: Norton's closed form."""
    return np.unwrap(closed_form.four_bar(theta2, 0.0, 0.0, a, 0.12, 0.08, 0.10, +1).theta4)


def _omega4(theta2: np.ndarray, a: float) -> np.ndarray:
    """The rocker's angular speed [rad/s] at 120 rpm: Norton's omega4 = a w2 sin(th2 - th3)
    / (c sin(th4 - th3)), the positions from the law of cosines."""
    fb = closed_form.four_bar(theta2, 0.0, 0.0, a, 0.12, 0.08, 0.10, +1)
    return a * 4 * np.pi * np.sin(theta2 - fb.theta3) / (0.08 * np.sin(fb.theta4 - fb.theta3))


def test_crank_param_moves_the_rocker_as_nortons_closed_form():
    """param = "crank" (40 mm) of the drawn four-bar: the rocker angle at 25 poses of a turn
    is theta4 of the law of cosines (tolerance 1e-12 rad: both exact to the closure
    tolerance), on the nominal and on a variant at 45 mm (redrawn: B's compass moves and
    the coupler and rocker frames turn); d(theta4)/d(crank) equals central differences of
    the closed form. Reference step 1e-7 m: truncation (1e-7 / 0.04)^2 ~ 6e-12 relative,
    rounding 1e-16 / 1e-7 ~ 1e-9 rad/m. The study's drawing step 1e-6 m: truncation ~ 6e-10
    relative, rounding 1e-16 * 0.1 / 1e-6 ~ 1e-11; |d theta4 / da| ~ 23 rad/m: tolerance
    1e-7 rad/m (measured 3e-9). The rocker's omega4 at 120 rpm and its d/d(crank) against
    Norton's omega4 formula: the same errors times omega2 = 12.6 rad/s; tolerance 1e-6 of
    the largest |d omega4 / da| (~600 rad/s/m). The rocker's alpha4 (closed_form.four_bar,
    Norton's acceleration loop projected) and its d/d(crank), exact here too (the drawing's
    central differences at fixed q, v, a composed with the acceleration closure): 1e-6 of
    the largest (~2e4 rad/s^2/m)."""
    sm = _drawn({"crank": {"param": "crank"}}, {"links": ["rocker"], "omega": ["rocker"], "alpha": ["rocker"]})
    out = StudyOutputs(sm)
    assert sm.nominal.tolist() == [0.04]
    cycle = sm.cycle(sm.nominal)
    y, dy = cycle_sensitivity(sm, out, cycle)
    np.testing.assert_allclose(np.unwrap(y[:, 0]), _theta4(cycle.values, 0.04), rtol=0, atol=closure(np.pi, REGULAR))
    h = 1e-7
    slope = (_theta4(cycle.values, 0.04 + h) - _theta4(cycle.values, 0.04 - h)) / (2 * h)
    assert np.abs(slope).max() > 1.0
    np.testing.assert_allclose(dy[:, 0, 0], slope, rtol=0, atol=1e-7)
    np.testing.assert_allclose(y[:, 1], _omega4(cycle.values, 0.04), rtol=0, atol=1e-10)
    slope = (_omega4(cycle.values, 0.04 + h) - _omega4(cycle.values, 0.04 - h)) / (2 * h)
    np.testing.assert_allclose(dy[:, 1, 0], slope, rtol=0, atol=1e-6 * np.abs(slope).max())  # ~600 rad/s/m
    alpha4 = lambda a: closed_form.four_bar(cycle.values, 4 * np.pi, 0.0, a, 0.12, 0.08, 0.10, +1).alpha4  # noqa: E731
    np.testing.assert_allclose(y[:, 2], alpha4(0.04), rtol=0, atol=1e-8)
    slope = (alpha4(0.04 + h) - alpha4(0.04 - h)) / (2 * h)
    np.testing.assert_allclose(dy[:, 2, 0], slope, rtol=0, atol=1e-6 * np.abs(slope).max())  # ~2e4 rad/s^2/m
    variant = sm.cycle(np.array([0.045]))
    assert not variant.cause, variant.detail
    y45 = out.cycle(variant.q, variant.v, variant.a)
    np.testing.assert_allclose(np.unwrap(y45[:, 0]), _theta4(cycle.values, 0.045), rtol=0, atol=closure(np.pi, REGULAR))
    sm.write(sm.nominal)


def test_drawn_params_sensitivities_are_central_differences_of_resolved_variants():
    """The crank and a derived length at once (the coupler point P, the rocker and the
    transmission angle at B, the rocker's and the coupler's omega at 120 rpm): dy/dp equals central differences of variants redrawn and
    re-solved over the cycle at p +- 1e-6 m (truncation (h/L)^2 ~ 1e-9, the closure
    tolerance over h ~ 1e-8; tolerance 1e-6 of the largest |dy/dp|), the rocker's alpha
    included."""
    sm = _drawn({"crank": {"param": "crank"}}, {"points": ["P"], "links": ["rocker", "coupler"],
                                                "transmission": ["B"], "omega": ["rocker", "coupler"],
                                                "alpha": ["rocker"]})
    out = StudyOutputs(sm)
    cycle = sm.cycle(sm.nominal)
    _, dy = cycle_sensitivity(sm, out, cycle)
    h, ys = 1e-6, []
    for sign in (+1, -1):
        c = sm.cycle(sm.nominal + sign * h)
        assert not c.cause, c.detail
        ys.append(out.cycle(c.q, c.v, c.a))
    sm.write(sm.nominal)
    expected = deviation(ys[0], ys[1], out.kinds)[..., None] / (2 * h)
    for j, name in enumerate(out.names):
        scale = np.abs(expected[:, j]).max()
        np.testing.assert_allclose(dy[:, j], expected[:, j], rtol=0, atol=1e-6 * scale + 1e-9, err_msg=name)


def test_a_drawn_param_is_named_and_refused_where_it_does_not_apply():
    with pytest.raises(FrameNotFound, match=r"params.x.*'bogus'.*crank"):
        _drawn({"x": {"param": "bogus"}}, {"links": ["rocker"]}, steps=3)
    with pytest.raises(SceneError, match=r"params.x.component: a drawn linkage's param .* no component"):
        _drawn({"x": {"param": "crank", "component": "x"}}, {"links": ["rocker"]}, steps=3)
    with pytest.raises(SceneError, match=r"drawn linkage's \[params\]; this scene's model is given by 'urdf'"):
        _drawn({"x": {"param": "crank"}}, {"links": ["rocker"]}, scene="four_bar.toml", steps=3)


def _left(a: np.ndarray, b: np.ndarray, ra: float, rb: float, side: float = 1.0) -> np.ndarray:
    """The meeting point of the circles (a, ra) and (b, rb), left (side +1) or right of a -> b:
    the law of cosines, written here apart from pinmech's compass."""
    d = np.linalg.norm(b - a)
    along = (d * d + ra * ra - rb * rb) / (2 * d)
    u = (b - a) / d
    return a + along * u + side * np.sqrt(ra * ra - along * along) * np.array([-u[1], u[0]])


def test_two_drawn_params_written_one_after_the_other_are_both_drawn():
    """A study writes its params one at a time: the second write must keep the first (the
    Watt six-bar with link5 and link6 changed: the coupler point P at the drawn pose is the
    chain of circle intersections with both new lengths; atol 1e-12 m: rounding of 0.2 m)."""
    sm = _drawn({"link5": {"param": "link5"}, "link6": {"param": "link6"}}, {"points": ["P"]},
                scene="watt_params.toml", steps=2)
    cycle = sm.cycle(np.array([0.095, 0.075]))  # from the crank's drawn angle, 0 deg
    O4, O6, A = np.array([0.1, 0.0]), np.array([0.19, 0.03]), np.array([0.04, 0.0])
    B = _left(A, O4, 0.12, 0.08)
    C = _left(O4, B, 0.06, 0.05, -1.0)
    D = _left(C, O6, 0.095, 0.075)
    P = _left(C, D, 0.045, 0.065)  # the file's CP, DP
    np.testing.assert_allclose(StudyOutputs(sm).pose_values(cycle.q[0]), P, atol=closure(0.2, REGULAR))


def test_a_driver_torque_over_drawn_params_with_masses_is_refused(tmp_path: Path):
    """A drawn param redraws the joints, not the [masses] (here the coupler's centre of mass
    `at` the joint A, which the crank param moves): the torque would be the nominal's masses
    on the variant's geometry, a number that only looks right. It is one named error."""
    linkages = STUDIES.parent / "linkages"
    text = (linkages / "four_bar.toml").read_text(encoding="utf-8")
    (tmp_path / "four_bar.toml").write_text(
        text + '\n[masses]\ncoupler = { mass = "1 kg", at = "A", izz = "1e-3 kg*m^2" }\n', encoding="utf-8")
    scene = (STUDIES.parent / "scenes" / "four_bar_drawn.toml").read_text(encoding="utf-8")
    (tmp_path / "scene.toml").write_text(scene.replace("../linkages/four_bar.toml", "four_bar.toml"), encoding="utf-8")
    raw = {"scene": "scene.toml", "kind": "sensitivity", "steps": 13, "params": {"crank": {"param": "crank"}},
           "outputs": {"torque": ["O2"]}}
    with pytest.raises(SceneError, match=r"outputs\.torque.*drawn params \(crank\).*\[masses\] \(coupler\)"):
        StudyOutputs(StudyMechanism(parse_study(raw, tmp_path / "study.toml")))
