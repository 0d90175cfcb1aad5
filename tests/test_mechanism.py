"""Loading URDFs: named points, links, joints, locked joints, and malformed `<constraint>`s."""

from __future__ import annotations

import numpy as np
import pytest

from pinmech import FrameNotFound, Mechanism, ModelError
from tests._mechanisms import four_bar_urdf, write


def test_r_rtr_names(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    assert set(mech.points) == {"A", "B", "C", "D"}
    assert set(mech.links) == {"ground", "link1", "link2", "link3"}
    assert {n: j.kind for n, j in mech.joints.items()} == {"A": "continuous", "B": "continuous", "B_slider": "prismatic"}
    assert mech.joint("B_slider").parent_link == "link2" and mech.joint("B_slider").child_link == "link3"
    # the loop A-B-C: A at 0, B at 0.1 m, C at 0.05 m when all joints are zero (D closes no loop)
    assert mech.length_scale == pytest.approx(0.1)


def test_a_point_and_a_joint_may_share_a_name(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    assert mech.model.frames[mech.frame_id("A")].name == "A"
    assert mech.link_of_frame(mech.frame_id("B")) == "link1"
    assert mech.link_of_frame(mech.frame_id("D")) == "link3"


def test_continuous_joint_coordinates_round_trip(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    q = mech.neutral()
    for angle in (0.3, -3.1, np.pi, 1e6):
        mech.set_coordinate(q, "A", angle)
        assert np.hypot(*q[:2]) == pytest.approx(1.0, abs=1e-15)
        assert mech.coordinate(q, "A") == pytest.approx(np.arctan2(np.sin(angle), np.cos(angle)), abs=1e-15)


def test_locked_joints_leave_the_model(tmp_path):
    """Locking the rocker pivot of a four-bar removes one freedom; the crank then cannot move."""
    mech = Mechanism.from_urdf(write(tmp_path, "fb.urdf", four_bar_urdf()), locked={"O4": 1.2})
    assert "O4" not in mech.joints and mech.model.nv == 2
    assert mech.locked == {"O4": 1.2}
    assert mech.mobility == 0


def test_locking_an_unknown_joint(tmp_path):
    with pytest.raises(FrameNotFound, match="unknown joint to lock 'elbow'"):
        Mechanism.from_urdf(write(tmp_path, "fb.urdf", four_bar_urdf()), locked={"elbow": 0.0})


def _constraint(body: str) -> str:
    return four_bar_urdf().replace(
        four_bar_urdf()[four_bar_urdf().index("<constraint"): four_bar_urdf().index("</constraint>") + 13], body
    )


@pytest.mark.parametrize(
    "body, message",
    [
        ('<constraint name="B" type="hinge"><parent link="coupler"/><child link="rocker"/></constraint>',
         r'<constraint name="B">: type="hinge" is not one of revolute, prismatic, spherical, fixed'),
        ('<constraint name="B" type="revolute"><parent link="coupler"/></constraint>',
         r'<constraint name="B">: missing <child link="..."/>'),
        ('<constraint name="B" type="revolute"><parent link="coupler"/><child link="rockr"/></constraint>',
         r'<child link="rockr"/> names no link of the model'),
        ('<constraint name="B" type="revolute"><parent link="coupler"/><child link="rocker"/>'
         '<parent_origin xyz="0.1 0"/></constraint>', r'xyz="0.1 0" is not three finite numbers'),
        ('<constraint name="B" type="revolute"><parent link="coupler"/><child link="rocker"/>'
         '<parent_origin xyz="0.1 nan 0"/></constraint>', "is not three finite numbers"),
        ('<constraint name="B" type="revolute"><parent link="coupler"/><child link="rocker"/>'
         '<parent_origin xyz="a b c"/></constraint>', "is not three numbers"),
        ('<constraint name="B" type="revolute"><parent link="coupler"/><child link="rocker"/>'
         '<child_axis xyz="0 0 0"/></constraint>', "is not a direction"),
    ],
)
def test_malformed_constraints_name_the_file_and_element(tmp_path, body, message):
    path = write(tmp_path, "fb.urdf", _constraint(body))
    with pytest.raises(ModelError, match=message) as info:
        Mechanism.from_urdf(path)
    assert "fb.urdf" in str(info.value)


@pytest.mark.parametrize(
    "text, message",
    [
        ("<robot name='x'><link name='a'>", "malformed XML"),
        ("<rowboat/>", "root element is <rowboat>, expected <robot>"),
        ("<robot name='x'><link name='a'/><link name='b'/></robot>", "Pinocchio cannot build the model"),
    ],
)
def test_malformed_urdf(tmp_path, text, message):
    with pytest.raises(ModelError, match=message):
        Mechanism.from_urdf(write(tmp_path, "bad.urdf", text))


def test_missing_file(tmp_path):
    with pytest.raises(ModelError, match="no such URDF file"):
        Mechanism.from_urdf(tmp_path / "absent.urdf")
