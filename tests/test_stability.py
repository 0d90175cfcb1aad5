"""Numerical stability: scale, speed and angle extremes give the same dimensionless answers.

The R-RTR is rescaled from micrometres to kilometres (every length in its URDF times k)
and driven from 1e-3 to 1e5 rpm. Kinematics scales exactly: angles are unchanged,
omega_3 / omega_1 and alpha_3 / omega_1^2 are unchanged, v_D / (omega_1 k) and
a_D / (omega_1^2 k) are unchanged. pinmech's tolerances are relative to the mechanism's
size, so all of these must agree to 1e-10 relative with the 1 m, 1 rad/s case.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import closed_form
from pinmech import LoopSolver, Mechanism, Scene, evaluate_motion
from pinmech.sweep import Sweep


def scaled_urdf(text: str, k: float) -> str:
    """Every length of a URDF times k: origins, box sizes, radii, lengths, prismatic limits."""
    def scale_numbers(match: re.Match) -> str:
        numbers = " ".join(f"{float(x) * k!r}" for x in match.group(2).split())
        return f'{match.group(1)}="{numbers}"'

    text = re.sub(r'\b(xyz|size|radius|length)="([^"]*)"', scale_numbers, text)
    return re.sub(r'\b(lower|upper)="([^"]*)"', scale_numbers, text)


def _dimensionless(models_dir, tmp_path, k, rpm):
    path = tmp_path / f"r_rtr_{k:g}.urdf"
    path.write_text(scaled_urdf((models_dir / "r_rtr.urdf").read_text(), k))
    mech = Mechanism.from_urdf(path)
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", 0.35)
    mech.set_coordinate(guess, "B_slider", -0.6 * k)
    w1 = rpm * np.pi / 30
    solver = LoopSolver(mech, ["A"])
    sol = solver.solve([np.radians(30)], [w1], [0.0], guess=guess)
    m = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"], links=["link3"])
    link3, d = m.links["link3"], m.points["D"]
    return np.r_[link3.angle, link3.angular_velocity[2] / w1, link3.angular_acceleration[2] / w1**2,
                 d.position[:2] / k, d.velocity[:2] / (w1 * k), d.acceleration[:2] / (w1**2 * k)]


@pytest.mark.parametrize("k", [1e-6, 1e-3, 1.0, 1e3])
@pytest.mark.parametrize("rpm", [1e-3, -50.0, 1e5])
def test_same_dimensionless_answers_from_micrometres_to_kilometres(models_dir, tmp_path, k, rpm):
    reference = closed_form.r_rtr(np.radians(30), 1.0, 0.0)
    expected = np.r_[reference.phi3, reference.omega3, reference.alpha3, reference.D, reference.vD, reference.aD]
    np.testing.assert_allclose(_dimensionless(models_dir, tmp_path, k, rpm), expected, rtol=1e-10, atol=1e-12)


def test_scaled_urdf_helper_scales_lengths_only():
    assert scaled_urdf('<origin xyz="0.1 0 2" rpy="0 0 1.5"/>', 10.0) == '<origin xyz="1.0 0.0 20.0" rpy="0 0 1.5"/>'


@pytest.mark.parametrize("angle", [np.pi, -np.pi, np.pi - 1e-12, -np.pi + 1e-12, 1e6, -1e6, 2 * np.pi * 1e5 + 0.5])
def test_crank_angles_at_the_wrap_and_after_many_turns(models_dir, angle):
    """A continuous crank stored as (cos, sin): any angle gives the pose of angle mod 2 pi."""
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    guess = mech.neutral()
    mech.set_coordinate(guess, "B_slider", -0.06)
    solver = LoopSolver(mech, ["A"])
    sol = solver.solve([angle], [1.0], [0.0], guess=guess)
    m = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"])
    cf = closed_form.r_rtr(angle, 1.0, 0.0)
    np.testing.assert_allclose(m.points["D"].position[:2], cf.D, atol=1e-13)
    np.testing.assert_allclose(m.points["D"].acceleration[:2], cf.aD, atol=1e-12)
    assert -np.pi <= mech.coordinate(sol.q, "A") <= np.pi


def test_degrees_and_radians_give_the_same_pose(r_rtr_scene):
    from pinmech import analyse

    deg = analyse(Scene.load(r_rtr_scene, ['drivers.A.angle="30 deg"']))
    rad = analyse(Scene.load(r_rtr_scene, [f'drivers.A.angle="{np.pi / 6!r} rad"']))
    np.testing.assert_allclose(deg.solution.q, rad.solution.q, rtol=0, atol=1e-15)


def test_a_hundred_turns_stay_on_the_branch(r_rtr_scene):
    """3600 poses over 100 crank turns: every pose on branch +1, and the last equals the first."""
    sweep = Sweep.from_scene(Scene.load(r_rtr_scene))
    values = sweep.start + np.linspace(0, 200 * np.pi, 3601)
    first = last = None
    for pose in sweep.poses(values):
        m = pose.motion
        assert (m.points["D"].position - m.points["C"].position) @ (m.points["B"].position - m.points["C"].position) > 0
        first = first or m
        last = m
    np.testing.assert_allclose(last.points["D"].position, first.points["D"].position, atol=1e-14)
    np.testing.assert_allclose(last.points["D"].acceleration, first.points["D"].acceleration, atol=1e-11)
