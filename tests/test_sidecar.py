"""Gepetto's extended URDF (URDF + robot.yaml): a five-bar and a Delta against closed forms.

Five-bar: the end effector is the intersection of two circles of the distal lengths about
the elbows (the elbows from the motor angles); its velocity is the central difference of
that construction. Delta: the motor angles come from the closed-form inverse kinematics of a
chosen platform position (each leg: a cos + b sin = K); pinmech, driving the motors, must put
the platform there. Tolerances: loops close to 1e-13 of the size (~0.3 m) and the condition
numbers stay below 1e2 here, so positions agree to 1e-12 m (1e-10 allowed); central
differences with h = 1e-6 carry ~1e-10 m/s round-off (1e-7 of the speed allowed).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinmech import Scene, analyse
from pinmech.cli import main
from pinmech.exceptions import ModelError
from pinmech.model.sidecar import load_extended_urdf
from pinmech.solve.loops import LoopSolver
from tests.tolerance import closure, rounding

# The delta's and the five-bar's loops close to 1e-13 of their size at condition numbers
# below 1e2 (the module docstring): tests/tolerance.py closure.
COND = 1e2

MODELS = Path(__file__).resolve().parents[1] / "models"
FIVE = (MODELS / "five_bar" / "robot.urdf", MODELS / "five_bar" / "robot.yaml")
DELTA = (MODELS / "delta" / "robot.urdf", MODELS / "delta" / "robot.yaml")
L1, L2, D = 0.06, 0.09, 0.10


def five_bar_end(t1: float, t2: float) -> np.ndarray:
    """End effector from absolute motor angles: circles (B1, L2) and (B2, L2), P above B1 -> B2."""
    B1 = L1 * np.array([math.cos(t1), math.sin(t1)])
    B2 = np.array([D, 0.0]) + L1 * np.array([math.cos(t2), math.sin(t2)])
    d = np.linalg.norm(B2 - B1)
    u = (B2 - B1) / d
    return B1 + d / 2 * u + math.sqrt(L2**2 - d * d / 4) * np.array([-u[1], u[0]])


def test_five_bar_end_effector_is_the_circle_intersection():
    mech = load_extended_urdf(*FIVE)
    assert mech.motors == ["mot1", "mot2"] and mech.mobility == 2
    solver = LoopSolver(mech, ["mot1", "mot2"])
    q = mech.neutral()
    h = 1e-6
    frame = mech.points["closedloop1_A"]
    for q1, q2 in [(-0.1, 0.1), (-0.2, 0.3), (0.1, 0.35), (0.3, 0.5)]:
        w1, w2 = 2.0, -1.0
        sol = solver.solve([q1, q2], [w1, w2], [0.0, 0.0], guess=q)
        q = sol.q
        pin.forwardKinematics(mech.model, solver.data, sol.q, sol.v)
        pin.updateFramePlacements(mech.model, solver.data)
        t1, t2 = 2 * math.pi / 3 + q1, math.pi / 3 + q2
        np.testing.assert_allclose(solver.data.oMf[frame].translation[:2], five_bar_end(t1, t2), atol=1e-10)
        fd = (five_bar_end(t1 + h * w1, t2 + h * w2) - five_bar_end(t1 - h * w1, t2 - h * w2)) / (2 * h)
        v = pin.getFrameVelocity(mech.model, solver.data, frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear
        np.testing.assert_allclose(v[:2], fd, atol=1e-7 * np.linalg.norm(fd))


R, r, LA, LB, Z0 = 0.10, 0.03, 0.10, 0.25, -0.20
THETA0 = 0.1563663122422725  # the URDF's arm angle at q = 0 (its comment), checked below


def delta_angle(P: np.ndarray, gamma: float) -> float:
    """Arm angle below horizontal of the leg at gamma for the platform at P (elbow out)."""
    rh = np.array([math.cos(gamma), math.sin(gamma), 0.0])
    Dv = P + (r - R) * rh
    a, b = Dv @ rh, -Dv[2]
    K = (LA**2 + Dv @ Dv - LB**2) / (2 * LA)
    return math.atan2(b, a) - math.acos(K / math.hypot(a, b))


def test_delta_reference_matches_its_inverse_kinematics():
    assert delta_angle(np.array([0.0, 0.0, Z0]), 0.0) == pytest.approx(THETA0, abs=rounding(math.pi))


@pytest.mark.parametrize("target", [(0.02, -0.01, -0.21), (-0.04, 0.03, -0.18), (0.0, 0.05, -0.25)])
def test_delta_platform_goes_where_inverse_kinematics_says(target):
    mech = load_extended_urdf(*DELTA)
    assert mech.mobility == 3 and mech.idle_joints(mech.motors) == []
    P = np.array(target)
    gammas = [0.0, 2 * math.pi / 3, 4 * math.pi / 3]
    q_motors = [delta_angle(P, g) - THETA0 for g in gammas]
    Pdot = np.array([0.1, -0.2, 0.05])
    h = 1e-6
    w = [(delta_angle(P + h * Pdot, g) - delta_angle(P - h * Pdot, g)) / (2 * h) for g in gammas]
    solver = LoopSolver(mech, mech.motors)
    q = mech.neutral()
    for k in (0.5, 1.0):  # two steps from the reference pose
        q = solver.solve([k * x for x in q_motors], guess=q).q
    sol = solver.solve(q_motors, w, [0.0] * 3, guess=q)
    pin.forwardKinematics(mech.model, solver.data, sol.q, sol.v)
    pin.updateFramePlacements(mech.model, solver.data)
    tool = mech.points["tool"]
    np.testing.assert_allclose(solver.data.oMf[tool].translation, P, atol=1e-10)
    v = pin.getFrameVelocity(mech.model, solver.data, tool, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear
    np.testing.assert_allclose(v, Pdot, atol=1e-7)


def test_motors_are_the_default_drivers(scenes_dir):
    analysis = analyse(Scene.load(scenes_dir / "delta.toml"))
    assert analysis.drivers.names == ("mot1", "mot2", "mot3")
    np.testing.assert_allclose(analysis.motion.points["tool"].position, [0.0, 0.0, Z0], atol=closure(0.3, analysis.solution.accuracy.condition))


def test_five_bar_scene_and_snapshot(scenes_dir, tmp_path):
    assert main(["solve", str(scenes_dir / "five_bar.toml")]) == 0
    out = tmp_path / "five.html"
    assert main(["snapshot", str(scenes_dir / "five_bar.toml"), "-o", str(out)]) == 0
    assert out.stat().st_size > 10_000


@pytest.mark.parametrize("yaml_text, words", [
    ("closed_loop: [['closedloop1_A', 'nowhere']]\ntype: ['3d']\nname_mot: ['mot1', 'mot2']\n",
     ["closed_loop", "nowhere"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['4d']\nname_mot: ['mot1', 'mot2']\n", ["type", "4d"]),
    ("closed_loop: [['closedloop1_A']]\nname_mot: []\n", ["closed_loop", "two frame names"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\nname_mot: ['motor9']\n", ["name_mot", "motor9"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\nmotors: ['mot1']\n", ["unknown key", "motors"]),
    ("closed_loop: [[\n", ["malformed YAML"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\njoint_name: ['elbow9']\njoint_type: ['CARDAN']\n",
     ["joint_name", "elbow9"]),
    # entries that are not names: a number, a list, null, a boolean (were a TypeError or Boost.Python.ArgumentError)
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\nname_mot: [[mot1], mot2]\n", ["name_mot", "entry 1", "['mot1']"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\njoint_name: [3]\njoint_type: [FIXED]\n",
     ["joint_name", "entry 1", "got 3"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\nname_mot: [null, true]\n", ["name_mot", "got None"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: [[3d]]\n", ["type", "entry 1"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_A']]\n", ["closed_loop", "to itself"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\n1: [x]\nfoo: 2\n", ["unknown key", "1, foo"]),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\nname_mot: [mot1, mot1]\n", ["name_mot", "listed twice"]),
])
def test_sidecar_errors_name_the_file_and_key(tmp_path, yaml_text, words):
    sidecar = tmp_path / "robot.yaml"
    sidecar.write_text(yaml_text)
    with pytest.raises(ModelError) as err:
        load_extended_urdf(FIVE[0], sidecar)
    message = str(err.value)
    assert str(sidecar) in message and "\n" not in message
    for word in words:
        assert word in message, message


def test_a_6d_closure_on_a_planar_five_bar_locks_it(tmp_path):
    """6d welds the two distal ends (3 planar rows instead of 2): mobility 4 - 3 = 1, one motor."""
    sidecar = tmp_path / "robot.yaml"
    sidecar.write_text("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['6d']\nname_mot: ['mot1']\n")
    mech = load_extended_urdf(FIVE[0], sidecar)
    assert mech.mobility == 1 and mech.constraint_rows == 3 and mech.motors == ["mot1"]


def test_joint_changes_fixed_and_spherical(tmp_path):
    """FIXED elbow2: a four-bar (mobility 1). SPHERICAL elbow1: distal1 spins idle between two
    ball joints (3 = 2 + 1 idle), and pinmech names elbow1 when the two motors are driven."""
    sidecar = tmp_path / "robot.yaml"
    base = "closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['3d']\nname_mot: ['mot1']\n"
    sidecar.write_text(base + "joint_name: ['elbow2']\njoint_type: ['FIXED']\n")
    fixed = load_extended_urdf(FIVE[0], sidecar)
    assert "elbow2" not in fixed.joints and fixed.mobility == 1
    q = LoopSolver(fixed, ["mot1"]).solve([-0.1], guess=fixed.neutral()).q  # the four-bar closes
    assert np.isfinite(q).all()
    sidecar.write_text(base + "joint_name: ['elbow1']\njoint_type: ['SPHERICAL']\n")
    ball = load_extended_urdf(FIVE[0], sidecar)
    assert ball.joints["elbow1"].nq == 4 and ball.mobility == 3
    assert ball.idle_joints(["mot1", "mot2"]) == ["elbow1"]


def test_locking_the_joint_that_carries_a_cut_moves_the_cut_onto_its_parent():
    """elbow2 locked at 0.2 rad: distal2 (which carries closedloop1_B) joins proximal2. Driving
    mot1 must give the pose of the unlocked five-bar driven by mot1 and elbow2 = 0.2."""
    locked = load_extended_urdf(*FIVE, locked={"elbow2": 0.2})
    assert "elbow2" not in locked.joints and locked.mobility == 1
    free = load_extended_urdf(*FIVE)
    q_free = LoopSolver(free, ["mot1", "elbow2"]).solve([-0.1, 0.2], guess=free.neutral()).q
    q_locked = LoopSolver(locked, ["mot1"]).solve([-0.1], guess=locked.neutral()).q
    d_free, d_locked = free.model.createData(), locked.model.createData()
    pin.framesForwardKinematics(free.model, d_free, q_free)
    pin.framesForwardKinematics(locked.model, d_locked, q_locked)
    for point in ("closedloop1_A", "closedloop1_B"):
        np.testing.assert_allclose(d_locked.oMf[locked.points[point]].translation,
                                   d_free.oMf[free.points[point]].translation, atol=closure(0.3, COND))


def test_a_locked_motor_is_neither_a_missing_joint_nor_a_default_driver():
    """Locking mot2 of the five-bar (its other motor driven) was refused as "motor 'mot2' is
    not a joint of robot.urdf": the lock had taken it out of the model. Now the five-bar
    with mot2 held is a four-bar driven by mot1, and mot2 is no motor of it."""
    folder = MODELS / "five_bar"
    mech = load_extended_urdf(folder / "robot.urdf", folder / "robot.yaml", locked={"mot2": math.radians(15)})
    assert "mot2" not in mech.joints and mech.motors == ["mot1"] and mech.mobility == 1
    held = load_extended_urdf(folder / "robot.urdf", folder / "robot.yaml")
    assert held.motors == ["mot1", "mot2"]


def _five_bar_named_after_links(tmp_path, yaml_extra: str = "") -> tuple[Path, Path]:
    """The five-bar with every joint named after its child link (as MuJoCo Menagerie names them)."""
    text = FIVE[0].read_text()
    for joint, link in (("mot1", "proximal1"), ("elbow1", "distal1"), ("mot2", "proximal2"), ("elbow2", "distal2"),
                        ("to_closedloop1_A", "closedloop1_A"), ("to_closedloop1_B", "closedloop1_B")):
        text = text.replace(f'joint name="{joint}"', f'joint name="{link}"')
    urdf, sidecar = tmp_path / "robot.urdf", tmp_path / "robot.yaml"
    urdf.write_text(text)
    sidecar.write_text("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['3d']\n"
                       "name_mot: ['proximal1', 'proximal2']\n" + yaml_extra)
    return urdf, sidecar


@pytest.mark.parametrize("how", ["[lock]", "joint_type FIXED"])
def test_joints_named_after_links_lock_and_close(tmp_path, how):
    """Elbow 2 held at its drawn angle e = 1.6185 rad: proximal 2 and distal 2 are one rigid
    link, so the end P is L2 from the elbow B1 = L1 u(t1) and |L1 + L2 u(e)| from the second
    motor O2 (law of cosines)."""
    if how == "[lock]":
        urdf, sidecar = _five_bar_named_after_links(tmp_path)
        mech = load_extended_urdf(urdf, sidecar, locked={"distal2": 0.0})
    else:
        urdf, sidecar = _five_bar_named_after_links(tmp_path, "joint_name: ['distal2']\njoint_type: ['FIXED']\n")
        mech = load_extended_urdf(urdf, sidecar)
    assert mech.mobility == 1
    solver = LoopSolver(mech, ["proximal1"])
    e, O2 = 1.6185128527327788, np.array([D, 0.0])
    rigid = math.sqrt(L1**2 + L2**2 + 2 * L1 * L2 * math.cos(e))
    q = mech.neutral()
    for q1 in (0.0, 0.1, 0.2):
        q = solver.solve([q1], [0.0], [0.0], guess=q).q
        pin.framesForwardKinematics(mech.model, solver.data, q)
        P = solver.data.oMf[mech.points["closedloop1_A"]].translation[:2]
        t1 = 2 * math.pi / 3 + q1
        B1 = L1 * np.array([math.cos(t1), math.sin(t1)])
        # lengths of 0.1 m solved to 1e-13 of the size: 1e-12 m allowed
        np.testing.assert_allclose([np.linalg.norm(P - B1), np.linalg.norm(P - O2)], [L2, rigid], atol=closure(0.1, COND))


def test_a_mimic_through_the_sidecar_couples_the_motors(tmp_path):
    """mot2 follows mot1 (<mimic multiplier="-1">): one driver moves both, and the end is the
    circle intersection at t1 = 2 pi/3 + q1, t2 = pi/3 - q1 (as the URDF alone would say)."""
    text = FIVE[0].read_text()
    for motor in ("mot1", "mot2"):
        text = text.replace(f'<joint name="{motor}" type="continuous">', f'<joint name="{motor}" type="revolute">')
    text = text.replace('<origin xyz="0.1 0 0" rpy="0 0 1.0471975511965976"/><axis xyz="0 0 1"/></joint>',
                        '<origin xyz="0.1 0 0" rpy="0 0 1.0471975511965976"/><axis xyz="0 0 1"/>'
                        '<limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="mot1" multiplier="-1"/>'
                        '</joint>')
    text = text.replace('<origin xyz="0 0 0" rpy="0 0 2.0943951023931953"/><axis xyz="0 0 1"/></joint>',
                        '<origin xyz="0 0 0" rpy="0 0 2.0943951023931953"/><axis xyz="0 0 1"/>'
                        '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
    urdf, sidecar = tmp_path / "robot.urdf", tmp_path / "robot.yaml"
    urdf.write_text(text)
    sidecar.write_text(FIVE[1].read_text().replace("name_mot: ['mot1', 'mot2']", "name_mot: ['mot1']"))
    mech = load_extended_urdf(urdf, sidecar)
    assert mech.mobility == 1 and "mot2" in mech.mimics
    solver = LoopSolver(mech, ["mot1"])
    q = mech.neutral()
    for q1 in (0.05, 0.1, 0.2):
        q = solver.solve([q1], [0.0], [0.0], guess=q).q
        pin.framesForwardKinematics(mech.model, solver.data, q)
        P = solver.data.oMf[mech.points["closedloop1_A"]].translation[:2]
        # positions solved to 1e-13 of the 0.1 m size: 1e-12 m allowed
        np.testing.assert_allclose(P, five_bar_end(2 * math.pi / 3 + q1, math.pi / 3 - q1), atol=closure(0.1, COND))
        assert mech.coordinate(q, "mot2") == pytest.approx(-q1, abs=rounding(math.pi))
    locked = load_extended_urdf(urdf, sidecar, locked={"mot1": 0.1})  # locking the leader holds its follower
    assert locked.locked == {"mot1": 0.1, "mot2": -0.1} and locked.mobility == 0


def test_gepettos_five_bar_with_pins_at_its_6d_closure_says_which_lock_it_needs(tmp_path, capsys):
    """Gepetto's published five-bar closes a 6d loop between two frames that each turn on a
    revolute joint about the same axis (closedloop1_A, closedloop1_B): the welded pair spins
    idly, mobility 3 for 2 motors. The error gives the [lock] line; with it, the end is the
    circle intersection."""
    text = FIVE[0].read_text()
    for side, link in (("A", "sphere"), ("B", "sphere_2")):
        text = text.replace(f'<link name="closedloop1_{side}"/>', f'<link name="{link}"/>')
        text = text.replace(f'<joint name="to_closedloop1_{side}" type="fixed">',
                            f'<joint name="closedloop1_{side}" type="continuous"><axis xyz="0 0 1"/>')
        text = text.replace(f'<child link="closedloop1_{side}"/>', f'<child link="{link}"/>')
    (tmp_path / "robot.urdf").write_text(text)
    (tmp_path / "robot.yaml").write_text("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['6d']\n"
                                         "name_mot: ['mot1', 'mot2']\n")
    scene = tmp_path / "five.toml"
    scene.write_text('urdf = "robot.urdf"\nsidecar = "robot.yaml"\n')
    assert main(["solve", str(scene)]) == 5
    # Either pin of the welded pair stops the spin: which one the rank search names is a tie
    # that rounding breaks (closedloop1_B with numpy's AVX2/AVX-512 paths off), so either is right.
    named = re.findall(r'\[lock\] (closedloop1_[AB]) = "0 deg"', capsys.readouterr().err)
    assert len(named) == 1, named
    mech = load_extended_urdf(tmp_path / "robot.urdf", tmp_path / "robot.yaml", locked={named[0]: 0.0})
    solver = LoopSolver(mech, ["mot1", "mot2"])
    q = solver.solve([-0.2, 0.3], [0.0, 0.0], [0.0, 0.0], guess=mech.neutral()).q
    pin.framesForwardKinematics(mech.model, solver.data, q)
    P = solver.data.oMf[mech.frame_id("sphere")].translation[:2]
    # as the five-bar above: 1e-12 m on a 0.1 m mechanism
    np.testing.assert_allclose(P, five_bar_end(2 * math.pi / 3 - 0.2, math.pi / 3 + 0.3), atol=closure(0.1, COND))


def _five_bar_scene(tmp_path: Path, drivers: str = "") -> Path:
    """A five-bar scene of the bundled URDF + robot.yaml, with the [drivers] given (default none)."""
    scene = tmp_path / "five.toml"
    scene.write_text(f'urdf = "{FIVE[0]}"\nsidecar = "{FIVE[1]}"\n[report]\npoints = ["closedloop1_A"]\n{drivers}',
                     encoding="utf-8")
    return scene


def test_set_on_one_motor_keeps_the_other_default_motor(tmp_path, capsys):
    """Without [drivers], robot.yaml's motors drive at the reference pose (q = 0). `--set` on
    mot1 silently dropped mot2 (then the mobility error); mot2 now keeps its default, and the
    end effector is where the two circles of the distal lengths meet (five_bar_end), within
    1e-10 m (loops close to 1e-13 of 0.19 m, condition ~2)."""
    import json

    scene = _five_bar_scene(tmp_path)
    assert main(["solve", str(scene), "--set", 'drivers.mot1.angle="10 deg"', "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out["drivers"]) == ["mot1", "mot2"]
    np.testing.assert_allclose([out["drivers"]["mot1"]["q"], out["drivers"]["mot2"]["q"]], [math.radians(10), 0.0],
                               atol=rounding(math.pi))
    end = five_bar_end(2 * math.pi / 3 + math.radians(10), math.pi / 3)
    np.testing.assert_allclose(out["points"]["closedloop1_A"]["position"][:2], end, atol=1e-10)


def test_a_driver_that_is_no_motor_replaces_the_motors_and_the_error_says_so(tmp_path, capsys):
    """`--set` on a joint robot.yaml does not call a motor: the motors are not added to it,
    and the mobility error names them and says why they are not driving."""
    scene = _five_bar_scene(tmp_path)
    assert main(["solve", str(scene), "--set", 'drivers.elbow1.angle="10 deg"']) == 5
    err = capsys.readouterr().err
    assert "robot.yaml" in err and "mot1, mot2" in err and "elbow1" in err, err


def test_one_motor_of_two_the_mobility_error_says_the_mechanism_still_moves(tmp_path, capsys):
    """With mot1 alone driven the five-bar still moves as a whole (mot2 and both elbows
    turn together): the error called elbow2 'a rod spinning about its own axis'."""
    scene = _five_bar_scene(tmp_path, '[drivers.mot1]\nangle = "10 deg"\n')
    assert main(["solve", str(scene)]) == 5
    err = capsys.readouterr().err
    assert "own axis" not in err and "rod" not in err, err
    assert "still move" in err and "mot2" in err and "drive one more joint" in err, err


def test_sweeping_without_drivers_says_which_drivers_to_add(tmp_path, capsys):
    """A robot.yaml scene without [drivers] was told about task scenes when swept."""
    scene = _five_bar_scene(tmp_path)
    assert main(["sweep", str(scene)]) == 4
    err = capsys.readouterr().err.strip()
    assert "task" not in err and "[drivers.mot1]" in err and "mot2" in err and str(scene) in err, err


def test_the_loop_is_named_by_its_two_frames(tmp_path, capsys):
    """The loop was labelled 'closedloop1_ACclosedloop1_B'; an assembly table may name it
    with an en dash, as printed, or a plain hyphen."""
    mech = load_extended_urdf(*FIVE)
    assert [c.name for c in mech.closures] == ["closedloop1_A\u2013closedloop1_B"]
    scene = tmp_path / "five.toml"
    scene.write_text(f'urdf = "{FIVE[0]}"\nsidecar = "{FIVE[1]}"\n'
                     'assembly = { "closedloop1_A-closedloop1_B" = "-" }\n', encoding="utf-8")
    assert main(["solve", str(scene)]) == 0
    assert "loop closedloop1_A\u2013closedloop1_B" in capsys.readouterr().out
