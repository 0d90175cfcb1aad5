"""The report shows every joint: one-dof joints, `<mimic>` followers and planar joints."""

from __future__ import annotations

import numpy as np
import pytest

from pinmech import Scene, analyse, to_dict, to_text
from tests._mechanisms import write
from tests.tolerance import rounding

PUCK = """<?xml version="1.0"?>
<robot name="puck">
  <link name="ground"/>
  <link name="puck"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="slide" type="planar"><parent link="ground"/><child link="puck"/><axis xyz="0 0 1"/></joint>
  <link name="P"/>
  <joint name="point_P" type="fixed"><parent link="puck"/><child link="P"/><origin xyz="0.1 0 0"/></joint>
</robot>
"""


@pytest.fixture
def puck(tmp_path):
    """A puck on a planar joint at the origin; its point P, 0.1 m along x, moves at 1 m/s
    along x while the puck turns at 2 rad/s."""
    write(tmp_path, "puck.urdf", PUCK)
    scene = write(tmp_path, "puck.toml", 'urdf = "puck.urdf"\n[[task]]\nframe = "P"\ncomponents = ["x", "y"]\n'
                  'velocity = ["1 m/s", "0 m/s"]\n[[task]]\nframe = "puck"\ncomponents = ["wz"]\n'
                  'velocity = ["2 rad/s"]\n')
    return analyse(Scene.load(scene))


def test_a_planar_joint_is_in_the_joints_report(puck):
    # Rigid body: v_P = v_O + w x OP, so v_O = (1, 0) - 2 k x (0.1, 0) = (1, -0.2) m/s; the
    # joint frame is the world's at theta = 0. a_P = 0 gives a_O = w^2 OP = (0.4, 0) m/s^2, and
    # the joint's own (body-frame) acceleration is a_O - w x v_O = (0, -2) m/s^2.
    joint = to_dict(puck)["joints"]["slide"]
    assert joint["type"] == "planar"
    np.testing.assert_allclose(joint["q"], [0, 0, 0], atol=rounding(1.0))
    np.testing.assert_allclose(joint["v"], [1, -0.2, 2], atol=rounding(2.0))
    np.testing.assert_allclose(joint["a"], [0, -2, 0], atol=rounding(2.0))
    line = next(x for x in to_text(puck).splitlines() if x.strip().startswith("slide"))
    assert "theta =  0 deg" in line and "v = ( 1, -0.2) m/s (joint frame), omega =  2 rad/s" in line


def test_a_mimic_follower_is_in_the_joints_report(tmp_path, models_dir):
    text = (models_dir / "planar_arm.urdf").read_text().replace(
        '<joint name="C" type="revolute">', '<joint name="C" type="revolute"><mimic joint="B" multiplier="-1"/>')
    write(tmp_path, "arm.urdf", text)
    scene = write(tmp_path, "arm.toml", 'urdf = "arm.urdf"\n[pose]\nA = "50 deg"\nB = "-65 deg"\n[[task]]\n'
                  'frame = "D"\ncomponents = ["x", "y"]\nvelocity = ["1 m/s", "0 m/s"]\n')
    report = to_dict(analyse(Scene.load(scene)))["joints"]
    # C = -B: CD keeps AB's direction (50 deg); its rate is minus B's.
    assert report["C"]["q"] == pytest.approx(np.radians(65), abs=rounding(np.pi))
    assert report["C"]["v"] == pytest.approx(-report["B"]["v"], abs=rounding(abs(report["B"]["v"]))) and report["B"]["v"] != 0


def test_a_link_whose_x_axis_is_normal_to_the_plane_reports_its_y_axis_angle(tmp_path, models_dir):
    """Joint C turned so that link CD's x axis is the plane's normal (world z): its x axis has
    no direction in the plane, so phi is that of its y axis, theta_A + theta_B + theta_C + 90 deg."""
    text = (models_dir / "planar_arm.urdf").read_text()
    text = text.replace('<origin xyz="0.30 0 0"/><axis xyz="0 0 1"/>\n    <limit lower="-3.14159265" upper="3.14159265" '
                        'effort="100" velocity="10"/>\n  </joint>\n\n  <link name="A"/>',
                        '<origin xyz="0.30 0 0" rpy="0 -1.5707963267948966 0"/><axis xyz="1 0 0"/>\n    '
                        '<limit lower="-3.2" upper="3.2" effort="1" velocity="1"/>\n  </joint>\n\n  <link name="A"/>')
    text = text.replace('<child link="D"/><origin xyz="0.17 0 0"/>', '<child link="D"/><origin xyz="0 0 -0.17"/>')
    assert 'rpy="0 -1.5707963267948966 0"' in text
    write(tmp_path, "arm.urdf", text)
    scene = write(tmp_path, "arm.toml", 'urdf = "arm.urdf"\n[pose]\nA = "50 deg"\nB = "-65 deg"\nC = "33.376 deg"\n'
                  '[[task]]\nframe = "D"\ncomponents = ["x", "y"]\nvelocity = ["1 m/s", "0 m/s"]\n')
    analysis = analyse(Scene.load(scene))
    cd = analysis.motion.links["CD"]
    assert cd.angle_axis == "y"
    # 50 - 65 + 33.376 + 90 = 108.376 deg, to rounding (1e-12 rad).
    assert cd.angle == pytest.approx(np.radians(108.376), abs=rounding(np.pi))
    assert to_dict(analysis)["links"]["CD"]["angle_axis"] == "y"
    assert "(its y axis: x is normal to the plane)" in to_text(analysis)
    # D, 0.17 m along CD's direction in the plane (its -z axis is world (cos, sin) of 18.376 deg):
    th = np.radians([50, -15, 18.376])
    np.testing.assert_allclose(analysis.motion.points["D"].position[:2],
                               np.array([np.cos(th), np.sin(th)]) @ [0.30, 0.30, 0.17], atol=rounding(0.77))


def test_without_a_guess_the_report_does_not_say_it_closed_from_one(scenes_dir):
    """The five-bar without [guess] was reported "closed from its [guess]" and, two lines on,
    "the scene has no [guess]"."""
    from pinmech import Scene, analyse
    from pinmech.io.report import to_text

    text = to_text(analyse(Scene.load(scenes_dir / "five_bar.toml")))
    assert "the scene has no [guess]" in text and "from its [guess]" not in text
    assert "closed from the neutral configuration" in text


def test_an_open_chain_accuracy_line_speaks_of_no_loop(scenes_dir):
    """An arm (no loop) was given 'closure residual 0 (of each loop's size; the largest loop
    spans ...), 0 Newton iterations'."""
    from pinmech import Scene, analyse
    from pinmech.io.report import to_text

    for scene in ("planar_arm.toml", "ur5.toml"):
        text = to_text(analyse(Scene.load(scenes_dir / scene)))
        accuracy = text.split("\nAccuracy\n")[1].splitlines()[1]
        assert "loop" in accuracy and "no loop" in accuracy and "Newton" not in accuracy, accuracy
        assert "condition number" in accuracy
