"""Real arms from example-robot-data: UR5 (square 6-D task), Panda (redundant), Talos (one arm).

The rates are checked by moving each robot a small step and differencing the task frame's
motion; the models are checked to hold only the joints a scene moves, and to be built
without meshes.
"""

from __future__ import annotations

import importlib
import sys

import numpy as np
import pinocchio as pin
import pytest

from pinmech import (
    Mechanism,
    ModelError,
    RateSolver,
    Scene,
    SceneError,
    Task,
    analyse,
    load_mechanism,
)
from pinmech.io.analysis_task import scene_pose, scene_tasks
from pinmech.cli import main
from tests.conftest import SCENES
from tests.tolerance import rounding

erd = pytest.importorskip("example_robot_data", reason='needs pip install "pinmech[robots]"')

DEG = np.pi / 180
ROBOT_SCENES = [("ur5.toml", "tool0", "exact", 6), ("panda.toml", "panda_hand_tcp", "minimum_norm", 7),
                ("talos_left_arm.toml", "gripper_left_base_link", "minimum_norm", 7)]


def _scene(name: str):
    scene = Scene.load(SCENES / name)
    mech = load_mechanism(scene)
    q, _, _ = scene_pose(scene, mech)
    return scene, mech, q


@pytest.mark.parametrize("name, frame, method, nv", ROBOT_SCENES)
def test_rates_move_the_frame_as_asked(name, frame, method, nv):
    """q(t) = q (+) (t q_dot + t^2/2 q_ddot): the task frame's velocity and classical
    acceleration, linear and angular, by central differences at t = -h, 0, h. The angular
    ones come from phi(t) = log3(R(t) R(0)^T), whose first and second derivatives at t = 0
    are exactly omega and alpha (world axes). h = 1e-4 s: truncation h^2 |x'''| ~ 1e-8,
    rounding eps |x| / h^2 ~ 2e-8, so 1e-6 holds with margin. The asked acceleration is
    not zero, so the drift term Jdot q_dot is tested too."""
    scene, mech, q = _scene(name)
    task = scene_tasks(scene)[0]
    asked_a = np.array([0.2, -0.1, 0.3, 0.5, -0.4, 0.2])
    sol = RateSolver(mech, [Task(frame, task.components, task.velocity, asked_a)]).solve(q)
    assert (sol.method, mech.model.nv, sol.nullspace_dim) == (method, nv, nv - 6)

    h, data, fid = 1e-4, mech.model.createData(), mech.frame_id(frame)
    p, R = [], []
    for t in (-h, 0.0, h):
        pin.framesForwardKinematics(mech.model, data, pin.integrate(mech.model, q, t * sol.v + 0.5 * t * t * sol.a))
        p.append(data.oMf[fid].translation.copy())
        R.append(data.oMf[fid].rotation.copy())
    phi = [pin.log3(Rt @ R[1].T) for Rt in R]
    velocity = np.r_[(p[2] - p[0]) / (2 * h), (phi[2] - phi[0]) / (2 * h)]
    acceleration = np.r_[(p[2] - 2 * p[1] + p[0]) / h**2, (phi[2] - 2 * phi[1] + phi[0]) / h**2]
    np.testing.assert_allclose(velocity, task.velocity, atol=1e-6)
    np.testing.assert_allclose(acceleration, asked_a, atol=1e-6)


def test_panda_is_numpys_minimum_norm():
    """7 joints, 6 rows: pinv(J) x_dot, and pinv(J) (x_ddot - Jdot q_dot) for the accelerations."""
    scene, mech, q = _scene("panda.toml")
    sol = RateSolver(mech, scene_tasks(scene)).solve(q)
    data = mech.model.createData()
    pin.computeJointJacobians(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    J = pin.getFrameJacobian(mech.model, data, mech.frame_id("panda_hand_tcp"), pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    np.testing.assert_allclose(sol.v, np.linalg.pinv(J) @ sol.requested_velocity, rtol=1e-10, atol=rounding(np.abs(sol.v).max(), sol.condition))
    jdot_v = sol.achieved_acceleration - J @ sol.a
    np.testing.assert_allclose(sol.a, np.linalg.pinv(J) @ (sol.requested_acceleration - jdot_v), rtol=1e-10,
                               atol=rounding(np.abs(sol.a).max(), sol.condition))
    assert sol.method == "minimum_norm" and sol.nullspace_dim == 1


def test_each_scene_models_only_the_joints_it_moves():
    """Panda: the fingers are locked; Talos: one arm of 32 joints, the rest locked at their
    [pose] values (the torso at 10 deg), 0 where the pose does not say."""
    _, panda, _ = _scene("panda.toml")
    assert set(panda.joints) == {f"panda_joint{i}" for i in range(1, 8)}
    assert panda.locked["panda_finger_joint1"] == pytest.approx(0.02)
    _, talos, _ = _scene("talos_left_arm.toml")
    assert set(talos.joints) == {f"arm_left_{i}_joint" for i in range(1, 8)}
    assert len(talos.locked) == 25 and talos.locked["torso_2_joint"] == pytest.approx(10 * DEG)
    assert talos.locked["arm_right_4_joint"] == 0.0


def test_locked_joints_hold_their_scene_values():
    """The torso turned 10 deg in the scene: the reduced model's gripper sits where the full
    model's does with the torso at 10 deg."""
    scene, talos, q = _scene("talos_left_arm.toml")
    full = Mechanism.from_urdf(scene.urdf)
    q_full = full.neutral()
    for name in talos.joints:
        full.set_coordinate(q_full, name, talos.coordinate(q, name))
    full.set_coordinate(q_full, "torso_2_joint", 10 * DEG)
    placements = []
    for mech, config in ((talos, q), (full, q_full)):
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, config)
        placements.append(data.oMf[mech.frame_id("gripper_left_base_link")].homogeneous)
    np.testing.assert_allclose(placements[0], placements[1], atol=rounding(1.0))


def test_a_free_flyer_root_rebuilds_the_loaders_model():
    """Mechanism.from_urdf(..., root_joint="free_flyer") has the sizes of erd.load("talos")."""
    scene = Scene.load(SCENES / "talos_left_arm.toml")
    mech = Mechanism.from_urdf(scene.urdf, root_joint="free_flyer")
    robot = erd.load("talos")
    sizes = (robot.model.nq, robot.model.nv, robot.model.njoints, robot.model.nframes)
    assert (mech.model.nq, mech.model.nv, mech.model.njoints, mech.model.nframes) == sizes == (39, 38, 34, 121)
    assert mech.joints["root_joint"].kind == "other"
    with pytest.raises(ModelError, match="root_joint must be None or one of free_flyer, got 'planar'"):
        Mechanism.from_urdf(scene.urdf, root_joint="planar")


def test_no_geometry_is_built(monkeypatch):
    """Meshes and collision geometry are built only to draw: loading and solving never ask."""

    def refuse(*args, **kwargs):
        raise AssertionError("geometry was built")

    monkeypatch.setattr(pin, "buildGeomFromUrdf", refuse)
    for name, *_ in ROBOT_SCENES:
        analyse(Scene.load(SCENES / name))


def test_cli_solves_each_robot_scene(capsys):
    for name, frame, method, _ in ROBOT_SCENES:
        assert main(["solve", str(SCENES / name)]) == 0
        out = capsys.readouterr().out
        assert f"method: {method}" in out and f"{frame} x  (world)" in out


def test_unknown_robot_and_unknown_moved_joint(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text('robot = "ur6"\n[pose]\n[[task]]\nframe = "tool0"\ncomponents = ["x"]\nvelocity = ["1 m/s"]\n')
    with pytest.raises(SceneError, match=r"unknown robot 'ur6' \(did you mean ur5, .*\?\); example-robot-data has \d+: a1, "):
        analyse(Scene.load(scene))
    scene.write_text('robot = "ur5"\nmove = ["elbow"]\n[[task]]\nframe = "tool0"\ncomponents = ["x"]\n'
                     'velocity = ["1 m/s"]\n')
    with pytest.raises(SceneError, match=r"unknown joint \(in move\) 'elbow'"):
        analyse(Scene.load(scene))


def test_without_the_robots_extra_the_error_names_it(monkeypatch, capsys):
    """No example-robot-data: an ImportError that says what to install, one line from the CLI."""
    monkeypatch.setitem(sys.modules, "example_robot_data", None)
    with pytest.raises(ImportError, match=r'pip install "pinmech\[robots\]"'):
        _ = Scene.load(SCENES / "ur5.toml").urdf
    assert main(["solve", str(SCENES / "ur5.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'robot = "ur5" needs example-robot-data' in err


def test_reduced_models_script_runs(monkeypatch, capsys):
    """The benchmark's table has a row per model (one repeat each: a smoke run, not a timing)."""
    script = importlib.import_module("reduced_models")
    for name in ("LOAD_REPEATS", "SOLVE_REPEATS", "MESH_REPEATS"):
        monkeypatch.setattr(script, name, 1)
    script.main()
    out = capsys.readouterr().out
    for row in ("| ur5.toml | full | 6 | 6 |", "| panda.toml | scene | 7 | 7 |",
                "| talos_left_arm.toml | full | 39 | 38 |", "| talos_left_arm.toml | scene | 7 | 7 |"):
        assert row in out
