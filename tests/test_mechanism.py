"""Loading URDFs: named points, links, joints, locked joints, and malformed `<constraint>`s."""

from __future__ import annotations

import numpy as np
import pytest

from pinmech import FrameNotFound, Mechanism, ModelError
from tests._mechanisms import four_bar_urdf, write
from tests.tolerance import rounding


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
        assert np.hypot(*q[:2]) == pytest.approx(1.0, abs=rounding(1.0))
        assert mech.coordinate(q, "A") == pytest.approx(np.arctan2(np.sin(angle), np.cos(angle)), abs=rounding(np.pi))


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


# ---------------------------------------------------------------- <mimic> joints
R1, R2, R3 = 0.30, 0.30, 0.17  # the planar 3R arm's links AB, BC, CD [m] (planar_arm.urdf)


def _mimic_arm(tmp_path, models_dir, mimic='<mimic joint="B" multiplier="2" offset="0.1"/>'):
    text = (models_dir / "planar_arm.urdf").read_text()
    return write(tmp_path, "arm.urdf", text.replace('<joint name="C" type="revolute">',
                                                    f'<joint name="C" type="revolute">{mimic}'))


def _tip(qa, qb, va, vb, aa, ab):
    """Closed form of D on the 3R arm with q_C = 2 q_B + 0.1: position, velocity, acceleration."""
    th = np.array([qa, qa + qb, qa + 3 * qb + 0.1])  # absolute angles of AB, BC, CD
    w = np.array([va, va + vb, va + 3 * vb])
    al = np.array([aa, aa + ab, aa + 3 * ab])
    r = np.array([R1, R2, R3])
    e, n = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)])
    return e @ r, n @ (r * w), n @ (r * al) - e @ (r * w**2)


def test_a_mimic_joint_follows_its_leader_in_positions_and_rates(tmp_path, models_dir):
    from pinmech import evaluate_motion

    mech = Mechanism.from_urdf(_mimic_arm(tmp_path, models_dir))
    assert mech.model.nv == 2 and mech.mimics["C"].leader == "B"  # C is no freedom of its own
    q, v, a = np.array([0.4, -0.7]), np.array([1.3, -2.1]), np.array([0.5, 3.0])
    motion = evaluate_motion(mech, mech.model.createData(), q, v, a)
    position, velocity, acceleration = _tip(*q, *v, *a)
    d = motion.points["D"]
    # The closed form and Pinocchio agree to rounding: 1e-12 of the 0.77 m arm and its rates.
    np.testing.assert_allclose(d.position[:2], position, atol=rounding(0.77))
    np.testing.assert_allclose(d.velocity[:2], velocity, atol=rounding(0.77 * np.abs(v).sum()))
    np.testing.assert_allclose(d.acceleration[:2], acceleration, atol=rounding(0.77 * (np.abs(a).sum() + np.abs(v).sum() ** 2)))
    c = motion.joints["C"]
    assert (c.q, c.v, c.a) == pytest.approx((2 * -0.7 + 0.1, 2 * -2.1, 2 * 3.0), abs=rounding(6.0))


def test_locking_a_mimic_leader_holds_its_follower_where_it_follows(tmp_path, models_dir):
    mech = Mechanism.from_urdf(_mimic_arm(tmp_path, models_dir), locked={"B": -0.7})
    assert mech.model.nv == 1 and mech.locked["C"] == pytest.approx(-1.3, abs=rounding(np.pi))
    from pinmech import evaluate_motion

    motion = evaluate_motion(mech, mech.model.createData(), np.array([0.4]), np.array([1.3]), np.array([0.5]))
    np.testing.assert_allclose(motion.points["D"].position[:2], _tip(0.4, -0.7, 0, 0, 0, 0)[0], atol=rounding(0.77))


@pytest.mark.parametrize(
    "mimic, locked, message",
    [
        ('<mimic joint="B"/>', {"C": 0.2}, "cannot be locked while B moves: lock B instead"),
        ('<mimic joint="B" multiplier="2"/>', {"C": 0.2, "B": 0.2}, r"locked at 0.2 but follows 'B'.*= 0.4"),
        ('<mimic joint="nope"/>', {}, 'joint="nope" is not another revolute or prismatic joint'),
        ('<mimic joint="C"/>', {}, 'joint="C" is not another'),
        ('<mimic joint="B" multiplier="x"/>', {}, 'multiplier="x" is not a finite number'),
        ('<mimic joint="B" offset="nan"/>', {}, 'offset="nan" is not a finite number'),
    ],
)
def test_mimic_joints_that_cannot_be_honoured_are_refused(tmp_path, models_dir, mimic, locked, message):
    with pytest.raises(ModelError, match=message):
        Mechanism.from_urdf(_mimic_arm(tmp_path, models_dir, mimic), locked=locked)


def test_a_mimic_follower_cannot_be_set_directly(tmp_path, models_dir):
    mech = Mechanism.from_urdf(_mimic_arm(tmp_path, models_dir))
    with pytest.raises(ModelError, match="'C' follows 'B'.*give B's value"):
        mech.set_coordinate(mech.neutral(), "C", 0.3)


def test_a_locked_joint_may_share_its_name_with_a_link(tmp_path, models_dir):
    """Joint AB drives link AB: Pinocchio's reduction found "several frames" by that name."""
    text = (models_dir / "planar_arm.urdf").read_text().replace('<joint name="A" type', '<joint name="AB" type')
    mech = Mechanism.from_urdf(write(tmp_path, "arm.urdf", text), locked={"AB": 0.4})
    assert mech.model.nv == 2 and "AB" in mech.links
    from pinmech import evaluate_motion

    motion = evaluate_motion(mech, mech.model.createData(), np.array([0.0, -0.6]), np.zeros(2), np.zeros(2))
    th = np.array([0.4, 0.4, -0.2])
    np.testing.assert_allclose(motion.points["D"].position[:2], np.array([np.cos(th), np.sin(th)]) @ [R1, R2, R3],
                               atol=rounding(0.77))


def test_a_model_with_one_freedom_left_loads(models_dir):
    """Pinocchio returns a one-column Jacobian as a vector; the plane is still found."""
    mech = Mechanism.from_urdf(models_dir / "planar_arm.urdf", locked={"B": 0.3, "C": 0.2})
    assert mech.model.nv == 1
    np.testing.assert_allclose(mech.plane_normal, [0, 0, 1], atol=rounding(1.0))


def _chain(tmp_path, n: int):
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
                     '<origin xyz="0.1 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>'
                     "</joint>" for i in range(n))
    return write(tmp_path, "chain.urdf", f'<?xml version="1.0"?><robot name="c">{links}{joints}</robot>')


def test_a_chain_of_2000_links_is_refused_in_one_line_before_allocating(tmp_path):
    # Pinocchio's Data holds nv^3 tensors (4 GB at 400): 2,000 would be MemoryError after minutes.
    import time

    start = time.perf_counter()
    with pytest.raises(ModelError, match=r"keeps 2000 degrees of freedom \(2000 joints\); .* about 500 GB .* "
                                         "at most 256: lock"):
        Mechanism.from_urdf(_chain(tmp_path, 2000))
    assert time.perf_counter() - start < 20


def test_locking_brings_a_long_chain_within_the_limit(tmp_path, monkeypatch):
    import pinmech.model.pinocchio_build

    monkeypatch.setattr(pinmech.model.pinocchio_build, "MAX_DOF", 20)
    urdf = _chain(tmp_path, 25)
    with pytest.raises(ModelError, match="keeps 25 degrees of freedom"):
        Mechanism.from_urdf(urdf)
    assert Mechanism.from_urdf(urdf, locked={f"j{i}": 0.1 for i in range(5)}).model.nv == 20


def test_a_scene_driving_or_guessing_a_mimic_follower_is_told_to_use_its_leader(tmp_path, models_dir):
    from pinmech import Scene, SceneError, analyse

    _mimic_arm(tmp_path, models_dir)
    task = '[[task]]\nframe = "D"\ncomponents = ["x", "y"]\nvelocity = ["1 m/s", "0 m/s"]\n'
    for text in ('[drivers.C]\nangle = "10 deg"\n[drivers.A]\nangle = "10 deg"\n', f'[guess]\nC = "10 deg"\n{task}'):
        scene = write(tmp_path, "s.toml", f'urdf = "arm.urdf"\n{text}')
        with pytest.raises(SceneError, match="'C' follows 'B' \\(URDF <mimic>\\)"):
            analyse(Scene.load(scene))


def test_move_lists_leaders_and_their_mimic_followers_go_with_them(tmp_path, models_dir):
    """move = ["A", "B"]: C (mimicking B) is neither locked at 0 nor an error: it follows B."""
    from pinmech import Scene, analyse

    _mimic_arm(tmp_path, models_dir)
    task = '[[task]]\nframe = "D"\ncomponents = ["x", "y"]\nvelocity = ["1 m/s", "0 m/s"]\n'
    scene = write(tmp_path, "s.toml", f'urdf = "arm.urdf"\nmove = ["A", "B"]\n[pose]\nA = "10 deg"\nB = "20 deg"\n{task}')
    analysis = analyse(Scene.load(scene))
    assert "C" not in analysis.mechanism.locked
    assert analysis.motion.joints["C"].q == pytest.approx(2 * np.radians(20) + 0.1, abs=rounding(np.pi))
    scene = write(tmp_path, "s.toml", f'urdf = "arm.urdf"\nmove = ["A"]\n[pose]\nA = "10 deg"\nB = "20 deg"\n{task}'
                  .replace('components = ["x", "y"]', 'components = ["x"]').replace('["1 m/s", "0 m/s"]', '["1 m/s"]'))
    held = analyse(Scene.load(scene)).mechanism.locked  # B locked at its pose value, C where it follows
    assert held["C"] == pytest.approx(2 * np.radians(20) + 0.1, abs=rounding(np.pi))


def test_a_mimic_pair_with_a_continuous_joint_is_refused_in_one_line(tmp_path, models_dir):
    # R-RTR: A is continuous (cos, sin); Pinocchio cannot make a one-coordinate slide follow it.
    text = (models_dir / "r_rtr.urdf").read_text().replace(
        '<joint name="B_slider" type="prismatic">', '<joint name="B_slider" type="prismatic"><mimic joint="A"/>')
    with pytest.raises(ModelError, match="'A' is a continuous joint") as info:
        Mechanism.from_urdf(write(tmp_path, "r.urdf", text))
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("written", ["0 0 1e200", "0 0 1e-200", "0 0 3e-320"])
def test_a_cut_axis_at_any_scale_is_its_unit_vector(tmp_path, written):
    """Issue 22 item 9 (its class: every user vector normalised): a <constraint>'s axis is
    xyz / |xyz| whatever the scale; 1e200 overflowed the norm and 1e-200 underflowed it.
    Expected: the z axis, exactly."""
    from tests._mechanisms import four_bar_urdf, write

    text = four_bar_urdf().replace('<parent_axis xyz="0 0 1"/>', f'<parent_axis xyz="{written}"/>')
    assert written in text
    closure = Mechanism.from_urdf(write(tmp_path, "fb.urdf", text)).closures[0]
    np.testing.assert_allclose(closure.axis, [0.0, 0.0, 1.0], rtol=0, atol=0)


@pytest.mark.parametrize("axis", ["[0.0, 0.0, 1e200]", "[0.0, 0.0, 1e-200]"])
def test_a_drawn_linkage_axis_at_any_scale_is_its_unit_vector(tmp_path, axis, models_dir):
    """The same for a linkage file's [axes]: R1's axis, written at 1e200 or 1e-200 of the
    bundled RSUR's [0, 0, 1], gives the same mechanism (the z axis, exactly)."""
    from pinmech.model.linkage import parse_linkage

    text = (models_dir / "linkages" / "rsur.toml").read_text().replace("R1 = [0.0, 0.0, 1.0]", f"R1 = {axis}")
    path = tmp_path / "rsur.toml"
    path.write_text(text)
    np.testing.assert_allclose(parse_linkage(path).axes["R1"], [0.0, 0.0, 1.0], rtol=0, atol=0)
