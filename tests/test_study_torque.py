"""The driver torque as a study output, against Norton's matrix method by hand
(scripts/closed_form_forces.py: Newton-Euler link by link, no Pinocchio), and its
sensitivity (central differences of re-solved variants, design/study/variant_differences.py)
against central differences of that hand solution in the link lengths."""

from __future__ import annotations

from pathlib import Path

import closed_form_forces as cff
import numpy as np
import pytest

from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.variant import StudyMechanism
from pinmech.exceptions import SceneError
from tests.conftest import length_slopes

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"
OMEGA2 = 4 * np.pi  # models/scenes/four_bar_dynamic.toml: 120 rpm, gravity 9.81 m/s^2 along -y,
BRAKE = -0.5  # and a -0.5 N m torque on the rocker


def _study(scene: str, outputs: dict, steps: int = 25) -> StudyMechanism:
    raw = {"scene": f"../scenes/{scene}", "kind": "sensitivity", "steps": steps, "outputs": outputs,
           "params": {"crank": {"joint": "A", "component": "x"}, "ground": {"joint": "O4", "component": "x"},
                      "coupler": {"cut": "B", "side": "parent", "component": "x"},
                      "rocker": {"cut": "B", "side": "child", "component": "x"}}}
    return StudyMechanism(parse_study(raw, STUDIES / "inline.toml"))


def hand_torque(theta2: np.ndarray, a: float, b: float, c: float, d: float) -> np.ndarray:
    """The crank torque [N m] at each crank angle, by Norton's 9 x 9 system (the bodies of
    models/four_bar_dynamic.urdf: cff.FOUR_BAR_BODIES)."""
    return np.array([cff.four_bar_forces(t, OMEGA2, 0.0, a, b, c, d, *cff.FOUR_BAR_BODIES, gravity=(0.0, -9.81),
                                         rocker_torque=BRAKE).T for t in theta2])


def test_driver_torque_and_its_sensitivity_are_newton_euler_by_hand():
    """The four-bar with masses (a, b, c, d) = (40, 120, 80, 100) mm at 120 rpm: T at 25
    poses of a turn equals the hand solution (tolerance 1e-10 N m against |T| ~ 1 N m:
    both exact up to the closure tolerance 1e-13 of the loop times the rates' condition),
    and dT/dp for each length equals central differences of the hand solution. Reference
    step 1e-6 m: truncation (1e-6 / 0.04)^2 ~ 6e-10 relative, rounding 1e-16 / 1e-6 ~
    1e-10 relative. The study's step 1e-5 m: truncation ~ 1e-8 relative, the solve's
    error over h ~ 1e-8 relative; tolerance 1e-6 of the largest |dT/dp| (~100 N m/m)."""
    sm = _study("four_bar_dynamic.toml", {"torque": ["O2"]})
    outputs = StudyOutputs(sm)
    assert outputs.names == ["O2.torque"] and outputs.kinds == ["torque"]
    cycle = sm.cycle(sm.nominal)
    y, dy = cycle_sensitivity(sm, outputs, cycle)
    nominal = np.array([0.04, 0.12, 0.08, 0.10])  # a, b, c, d
    np.testing.assert_allclose(y[:, 0], hand_torque(cycle.values, *nominal), rtol=0, atol=1e-10)
    slopes = length_slopes(hand_torque, cycle.values, sm.spec.params, nominal, h=1e-6)
    assert np.abs(slopes).max() > 1.0  # the lengths do move the torque
    np.testing.assert_allclose(dy[:, 0], slopes, rtol=0, atol=1e-6 * np.abs(slopes).max())


def test_a_torque_names_a_driver():
    with pytest.raises(SceneError, match=r"outputs.torque: 'A' is not a driver of the scene \(its drivers: O2\)"):
        StudyOutputs(_study("four_bar_dynamic.toml", {"torque": ["A"]}, steps=3))
