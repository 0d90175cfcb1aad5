"""Joint limits: a pose beyond a URDF <limit> is reported (text, JSON, CSV), a warning by
default and an error (exit 12) on request.

The R-RTR's slide coordinate is minus the distance CB (B on the crank, AB = 0.1 m; C on
the ground, AC = 0.05 m): q = -sqrt(AB^2 + AC^2 - 2 AB AC cos A). With the slide's limits
made +-0.1 m, it is beyond them exactly where cos A < 0.25 (A between 75.5 and 284.5 deg).
"""

from __future__ import annotations

import csv
import json
import math

import pytest

from pinmech.cli import main
from tests.conftest import MODELS, SCENES
from tests.tolerance import rounding


def _cb(angle_deg: float) -> float:
    return math.sqrt(0.1**2 + 0.05**2 - 2 * 0.1 * 0.05 * math.cos(math.radians(angle_deg)))


@pytest.fixture
def tight(tmp_path):
    text = (MODELS / "r_rtr.urdf").read_text()
    assert 'lower="-0.15" upper="0.15"' in text
    (tmp_path / "tight.urdf").write_text(text.replace('lower="-0.15" upper="0.15"', 'lower="-0.1" upper="0.1"'))
    scene = tmp_path / "tight.toml"
    scene.write_text((SCENES / "r_rtr.toml").read_text().replace('urdf = "../r_rtr.urdf"', 'urdf = "tight.urdf"'))
    return scene


def test_a_pose_beyond_a_limit_is_a_warning_in_text_json_and_stderr(tight, capsys):
    assert main(["solve", str(tight), "--angle", "90 deg"]) == 0
    out, err = capsys.readouterr()
    assert "WARNING: B_slider = -0.111803 m is below its lower limit -0.1 m" in out
    assert "warning: B_slider = -0.111803 m is below its lower limit -0.1 m" in err
    assert main(["solve", str(tight), "--angle", "90 deg", "--json"]) == 0
    [violation] = json.loads(capsys.readouterr().out)["limit_violations"]
    assert violation["joint"] == "B_slider" and violation["lower"] == -0.1
    assert violation["value"] == pytest.approx(-_cb(90), abs=1e-12)  # the closed form, to rounding


def test_a_pose_within_the_limits_says_nothing(tight, capsys):
    assert main(["solve", str(tight), "--angle", "30 deg", "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["limit_violations"] == [] and "warning" not in err and _cb(30) < 0.1


def test_limits_as_errors_exit_12_naming_the_joint(tight, capsys):
    assert main(["solve", str(tight), "--angle", "90 deg", "--limits", "error"]) == 12
    err = capsys.readouterr().err
    assert "B_slider = -0.111803 m is below its lower limit -0.1 m (URDF <limit>)" in err and "Traceback" not in err
    assert main(["solve", str(tight), "--angle", "90 deg", "--set", 'report.limits="error"']) == 12


def test_a_sweep_marks_the_poses_beyond_the_limits(tight, tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", str(tight), "--steps", "19", "--csv", str(out)]) == 0  # 30 to 390 deg by 20 deg
    rows = list(csv.DictReader(out.open()))
    beyond = [float(r["A.q [deg]"]) for r in rows if r["beyond_limits"] == "B_slider"]
    assert beyond == [a for a in range(30, 391, 20) if math.cos(math.radians(a)) < 0.25]
    assert "10 of 19 poses put joints beyond their limits" in capsys.readouterr().err
    assert main(["sweep", str(tight), "--steps", "19", "--csv", str(out), "--limits", "error"]) == 12
    assert "stopped at A = 90 deg: B_slider" in capsys.readouterr().err


def test_malformed_limits_are_model_errors(tmp_path):
    from pinmech import Mechanism, ModelError

    text = (MODELS / "r_rtr.urdf").read_text()
    for bad, message in (('lower="x" upper="0.15"', 'lower value \\(x\\) is not a valid float'),  # urdfdom's
                         ('lower="0.2" upper="0.15"', 'lower="0.2" is above upper="0.15"')):
        (tmp_path / "bad.urdf").write_text(text.replace('lower="-0.15" upper="0.15"', bad))
        with pytest.raises(ModelError, match=message):
            Mechanism.from_urdf(tmp_path / "bad.urdf")


def test_a_joint_locked_beyond_its_limit_is_reported(tmp_path, capsys):
    # The planar arm's joints are limited to +-3.14159265 rad; C locked at 200 deg is beyond.
    scene = tmp_path / "arm.toml"
    scene.write_text(f'urdf = "{MODELS / "planar_arm.urdf"}"\n[lock]\nC = "200 deg"\n[pose]\nA = "50 deg"\n'
                     'B = "-65 deg"\n[[task]]\nframe = "D"\ncomponents = ["x", "y"]\nvelocity = ["1 m/s", "0 m/s"]\n')
    assert main(["solve", str(scene), "--json"]) == 0
    [violation] = json.loads(capsys.readouterr().out)["limit_violations"]
    assert violation == {"joint": "C", "value": pytest.approx(math.radians(200)), "lower": -3.14159265,
                         "upper": 3.14159265}


def test_an_arm_path_beyond_a_limit_is_a_warning_or_stops(tmp_path, capsys):
    # The planar arm's D moves at 1 m/s along x: B opens from -65 deg (to -58.2 deg at 19 ms).
    # Limited to [-65.5, -60] deg, it leaves its range on the way.
    text = (MODELS / "planar_arm.urdf").read_text()
    old = '<origin xyz="0.30 0 0"/><axis xyz="0 0 1"/>\n    <limit lower="-3.14159265" upper="3.14159265"'
    assert text.count(old) == 2
    head, _, tail = text.partition('<joint name="B" type="revolute">')
    tail = tail.replace(old, '<origin xyz="0.30 0 0"/><axis xyz="0 0 1"/>\n    <limit lower="-1.1432" upper="-1.0472"', 1)
    (tmp_path / "arm.urdf").write_text(head + '<joint name="B" type="revolute">' + tail)
    scene = tmp_path / "arm.toml"
    scene.write_text((SCENES / "planar_arm.toml").read_text().replace('urdf = "../planar_arm.urdf"',
                                                                      'urdf = "arm.urdf"'))
    assert main(["path", str(scene), "--duration", "0.02 s", "--csv", str(tmp_path / "p.csv")]) == 0
    err = capsys.readouterr().err
    assert "path points put joints beyond their limits (first at t = " in err and ": B = " in err
    assert main(["path", str(scene), "--duration", "0.02 s", "--csv", str(tmp_path / "p.csv"), "--limits", "error"]) == 12
    assert "stopped at t = " in capsys.readouterr().err


# ---------------------------------------------------------------- every route reads its file's limits
ARM_MJCF = """<mujoco><worldbody><body name="upper"><joint name="shoulder" axis="0 0 1" range="-30 60"/>
  <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.01"/>
  <body name="fore" pos="0.3 0 0"><joint name="slide" type="slide" axis="1 0 0" range="-0.05 0.05"/>
    <geom size="0.01"/><site name="tip"/></body></body></worldbody></mujoco>"""


def test_mjcf_ranges_are_mujocos_limits_and_are_checked(tmp_path, capsys):
    """`range` in the compiler's default unit (degrees) for a hinge, metres for a slide, read as
    MuJoCo reads them (its jnt_range, in radians); driving the shoulder to 90 deg is beyond 60 deg."""
    mujoco = pytest.importorskip("mujoco")
    from pinmech.model.mjcf import load_mjcf

    (tmp_path / "arm.xml").write_text(ARM_MJCF)
    m = mujoco.MjModel.from_xml_string(ARM_MJCF)
    mech = load_mjcf(tmp_path / "arm.xml")
    for j in range(m.njnt):
        limit = mech.limits[m.joint(j).name]
        assert m.jnt_limited[j]
        assert (limit.lower, limit.upper) == pytest.approx(tuple(m.jnt_range[j]), abs=rounding(math.pi))
    scene = tmp_path / "arm.toml"
    scene.write_text('mjcf = "arm.xml"\n[drivers.shoulder]\nangle = "90 deg"\n[drivers.slide]\nposition = "0 mm"\n'
                     '[report]\nlimits = "error"\n')
    assert main(["solve", str(scene)]) == 12
    assert "shoulder = 90 deg is above its upper limit 60 deg (MJCF range)" in capsys.readouterr().err
    scene.write_text(scene.read_text().replace('"90 deg"', '"45 deg"'))
    assert main(["solve", str(scene)]) == 0


def test_a_limited_ball_joint_is_checked_where_mujoco_finds_it_beyond(tmp_path):
    """A ball joint's range "0 30" (degrees) bounds the angle it turns. Turned 40 deg about
    (1, 2, 2)/3, MuJoCo's compiler puts a joint-limit row with a negative distance (beyond it);
    pinmech reports 40 deg against 30."""
    mujoco = pytest.importorskip("mujoco")
    import numpy as np

    from pinmech.solve.limits import limits_at
    from pinmech.model.mjcf import load_mjcf

    text = ('<mujoco><worldbody><body name="rod"><joint name="ball" type="ball" range="0 30"/><geom size="0.01"/>'
            '</body></worldbody></mujoco>')
    (tmp_path / "ball.xml").write_text(text)
    axis, angle = np.array([1.0, 2.0, 2.0]) / 3, math.radians(40)
    m = mujoco.MjModel.from_xml_string(text)
    d = mujoco.MjData(m)
    d.qpos[:] = [math.cos(angle / 2), *(math.sin(angle / 2) * axis)]
    mujoco.mj_forward(m, d)
    rows = d.efc_type == mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT
    assert rows.sum() == 1 and d.efc_pos[rows][0] == pytest.approx(math.radians(30 - 40), abs=rounding(np.pi))
    mech = load_mjcf(tmp_path / "ball.xml")
    q = np.array([*(math.sin(angle / 2) * axis), math.cos(angle / 2)])  # Pinocchio: x y z w
    [violation] = limits_at(mech, q)
    assert violation.joint == "ball" and violation.value == pytest.approx(angle, abs=rounding(np.pi))
    assert violation.upper == pytest.approx(math.radians(30), abs=rounding(math.pi))


def test_urdf_limits_through_a_sidecar_are_checked(tmp_path, capsys):
    """The five-bar's first motor made revolute with <limit lower="-0.1" upper="0.1">: driven
    to 0.3 rad it is beyond, as the same URDF alone says."""
    text = (MODELS / "five_bar" / "robot.urdf").read_text()
    text = text.replace('<joint name="mot1" type="continuous">', '<joint name="mot1" type="revolute">')
    text = text.replace('<origin xyz="0 0 0" rpy="0 0 2.0943951023931953"/><axis xyz="0 0 1"/></joint>',
                        '<origin xyz="0 0 0" rpy="0 0 2.0943951023931953"/><axis xyz="0 0 1"/>'
                        '<limit lower="-0.1" upper="0.1" effort="1" velocity="1"/></joint>', 1)
    (tmp_path / "robot.urdf").write_text(text)
    (tmp_path / "robot.yaml").write_text((MODELS / "five_bar" / "robot.yaml").read_text())
    scene = tmp_path / "five.toml"
    scene.write_text('urdf = "robot.urdf"\nsidecar = "robot.yaml"\n[drivers.mot1]\nangle = "0.3 rad"\n'
                     '[drivers.mot2]\nangle = "0.2 rad"\n[report]\nlimits = "error"\n')
    assert main(["solve", str(scene)]) == 12
    assert "mot1 = 17.1887 deg is above its upper limit 5.72958 deg" in capsys.readouterr().err
