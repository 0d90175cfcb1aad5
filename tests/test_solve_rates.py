"""End-effector rate problems: text 17.110 against its closed form, real arms by finite
differences, minimum-norm and damped solutions against numpy's pseudo-inverse, errors."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import closed_form
from pinmech import Mechanism, Scene, SingularPoseError, TaskError, analyse, compare, load_hand_file, to_dict
from pinmech.analysis import load_mechanism
from pinmech.analysis_task import scene_pose, scene_tasks
from pinmech.solve_rates import RateSolver, Task

DEG = np.pi / 180


@pytest.fixture(scope="module")
def arm():
    from tests.conftest import MODELS

    return Mechanism.from_urdf(MODELS / "planar_arm.urdf")


def _arm_tasks(vD=(1.0, 0.0), aD=(0.0, 0.0)):
    return [Task("D", ("x", "y"), np.array(vD), np.array(aD)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]


def _arm_q(arm, angles_deg):
    q = arm.neutral()
    for name, angle in zip("ABC", angles_deg):
        arm.set_coordinate(q, name, angle * DEG)
    return q


def test_text_17_110_against_the_closed_form(arm):
    """Cramer's rule on the text's two equations (written without Pinocchio), 1e-10 relative."""
    sol = RateSolver(arm, _arm_tasks()).solve(_arm_q(arm, (50, -65, -75)))
    cf = closed_form.planar_arm_rates(50 * DEG, -15 * DEG, -90 * DEG, 0.3, 0.3, 0.17, np.array([1.0, 0.0]), np.zeros(2))
    assert sol.method == "exact" and sol.nullspace_dim == 0
    np.testing.assert_allclose(sol.v, cf.q_dot, rtol=1e-10)
    np.testing.assert_allclose(sol.a, cf.q_ddot, rtol=1e-10)


def test_text_17_110_printed_answers(scenes_dir):
    """The four printed rates hold to 2 figures; the text's v_C line (sign slip) does not."""
    hand = load_hand_file(scenes_dir / "planar_arm.hand.toml")
    verdicts = {v.hand.label: v.verdict for v in compare(to_dict(analyse(Scene.load(hand.scene))), hand.values)}
    assert verdicts == {
        "text: theta1_dot (omega_AB)": "ok",
        "text: omega_BC = -theta2_dot": "ok",
        "text: theta1_ddot (alpha_AB)": "ok",
        "text: alpha_BC = -theta2_ddot": "ok",
        "text's v_C line, i term, at its own rates": "MISMATCH",
    }


def _end_effector_fd(mech, frame, q, v, a, h=1e-5):
    """Velocity and classical acceleration of a frame by central differences along
    q(t) = q + t v + t^2/2 a on the manifold. h = 1e-5: truncation ~ h^2 |x'''| ~ 1e-10,
    rounding ~ eps / h^2 ~ 1e-6 for the second difference, so acceleration rtol ~ 1e-5."""
    model, data = mech.model, mech.model.createData()
    fid = mech.frame_id(frame)

    def pos(t):
        pin.framesForwardKinematics(model, data, pin.integrate(model, q, t * v + 0.5 * t * t * a))
        return data.oMf[fid].translation.copy()

    p_m, p_0, p_p = pos(-h), pos(0.0), pos(h)
    return (p_p - p_m) / (2 * h), (p_p - 2 * p_0 + p_m) / h**2


def test_planar_arm_motion_by_finite_differences(arm):
    q = _arm_q(arm, (50, -65, -75))
    sol = RateSolver(arm, _arm_tasks(aD=(0.5, -2.0))).solve(q)
    vel, acc = _end_effector_fd(arm, "D", q, sol.v, sol.a)
    np.testing.assert_allclose(vel[:2], [1.0, 0.0], atol=1e-8)
    np.testing.assert_allclose(acc[:2], [0.5, -2.0], atol=2e-4)


@pytest.mark.parametrize("scene, frame", [("ur5.toml", "tool0"), ("panda.toml", "panda_hand_tcp"),
                                          ("talos_left_arm.toml", "gripper_left_base_link")])
def test_real_arms_by_finite_differences(scenes_dir, scene, frame):
    pytest.importorskip("example_robot_data", reason='needs pip install "pinmech[robots]"')
    sc = Scene.load(scenes_dir / scene)
    mech = load_mechanism(sc)
    q, _, _ = scene_pose(sc, mech)
    tasks = scene_tasks(sc)
    tasks[0] = Task(frame, tasks[0].components, tasks[0].velocity, np.array([0.2, 0.0, 0.1, 0.0, 0.0, 0.0]))
    sol = RateSolver(mech, tasks).solve(q)
    vel, acc = _end_effector_fd(mech, frame, q, sol.v, sol.a)
    np.testing.assert_allclose(vel, tasks[0].velocity[:3], atol=1e-8)
    np.testing.assert_allclose(acc, tasks[0].acceleration[:3], atol=2e-4)


def test_talos_scene_models_one_arm_only(scenes_dir):
    pytest.importorskip("example_robot_data", reason='needs pip install "pinmech[robots]"')
    sc = Scene.load(scenes_dir / "talos_left_arm.toml")
    mech = load_mechanism(sc)
    assert mech.model.nv == 7 and set(mech.joints) == {f"arm_left_{i}_joint" for i in range(1, 8)}
    assert mech.locked["torso_2_joint"] == pytest.approx(10 * DEG)


def test_redundant_task_is_minimum_norm(scenes_dir):
    """Panda: 7 joints, 6 rows; the answer is numpy's pseudo-inverse solution."""
    pytest.importorskip("example_robot_data", reason='needs pip install "pinmech[robots]"')
    sc = Scene.load(scenes_dir / "panda.toml")
    mech = load_mechanism(sc)
    q, _, _ = scene_pose(sc, mech)
    solver = RateSolver(mech, scene_tasks(sc))
    sol = solver.solve(q)
    data = mech.model.createData()
    pin.computeJointJacobians(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    J = pin.getFrameJacobian(mech.model, data, mech.frame_id("panda_hand_tcp"), pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    assert sol.method == "minimum_norm" and sol.nullspace_dim == 1
    np.testing.assert_allclose(sol.v, np.linalg.pinv(J) @ solver.x_dot, rtol=1e-10, atol=1e-12)


def test_damped_least_squares_is_the_regularised_pseudo_inverse(arm):
    q = _arm_q(arm, (50, -65, -75))
    lam = 0.05
    solver = RateSolver(arm, _arm_tasks(), method="damped", damping=lam)
    sol = solver.solve(q)
    J = solver._stack(q, np.zeros(3))[0]
    expected = np.linalg.solve(J.T @ J + lam**2 * np.eye(3), J.T @ solver.x_dot)
    np.testing.assert_allclose(sol.v, expected, rtol=1e-12)
    assert sol.method == "damped" and sol.velocity_error > 0  # it says how far it is from the asked motion


@pytest.mark.parametrize("bend", [0.0, 180.0])
def test_stretched_or_folded_arm_is_singular(arm, bend):
    """B = 0 (stretched) or 180 deg (folded back): D cannot move along the arm's line."""
    with pytest.raises(SingularPoseError, match=r"task Jacobian is singular at A = 0\.5, B = ") as info:
        RateSolver(arm, _arm_tasks()).solve(_arm_q(arm, (0.5 / DEG, bend, -30)))
    assert info.value.sigma_min < 1e-9


def test_damped_solution_at_the_singular_pose_reports_its_error(arm):
    """Stretched along x, D can move along x only by turning CD, which the task forbids:
    the damped answer is finite, and the report shows it misses most of the 1 m/s asked."""
    q = _arm_q(arm, (0.0, 0.0, -90))
    sol = RateSolver(arm, _arm_tasks(), method="damped", damping=1e-2).solve(q)
    assert np.all(np.isfinite(sol.v)) and not sol.is_exact()
    assert sol.velocity_error > 0.5
    np.testing.assert_allclose(sol.requested_velocity - sol.achieved_velocity,
                               [1.0 - sol.achieved_velocity[0], -sol.achieved_velocity[1], -sol.achieved_velocity[2]])


def test_over_determined_task(arm):
    tasks = [Task("D", ("x", "y", "wz"), np.ones(3), np.zeros(3)), Task("C", ("x",), np.ones(1), np.zeros(1))]
    with pytest.raises(TaskError, match="4 equations .* for 3 joint freedoms: over-determined"):
        RateSolver(arm, tasks).solve(_arm_q(arm, (50, -65, -75)))
    sol = RateSolver(arm, tasks, method="least_squares").solve(_arm_q(arm, (50, -65, -75)))
    assert sol.method == "least_squares" and sol.velocity_error > 0


def test_task_on_a_closed_loop_obeys_the_loop(models_dir):
    """R-RTR: ask D's x velocity; the crank rate found reproduces it and the loop stays closed."""
    from pinmech import LoopSolver

    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", 0.35)
    mech.set_coordinate(guess, "B_slider", -0.06)
    solver = LoopSolver(mech, ["A"])
    q, _, _ = solver.close(guess, [np.radians(30)])
    sol = RateSolver(mech, [Task("D", ("x",), np.array([0.935792321]), np.array([-1.0766009]))]).solve(q)
    # The textbook pose at -50 rpm gives v_D,x = 0.935792 and a_D,x = -1.0766: the crank must be at -50 rpm
    np.testing.assert_allclose(sol.v[mech.joint("A").idx_v], -50 * np.pi / 30, rtol=1e-8)
    assert sol.closure_velocity_residual < 1e-12 and sol.closure_acceleration_residual < 1e-10


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(frame="D", components=("q",), velocity=np.zeros(1), acceleration=np.zeros(1)), "must be distinct names"),
        (dict(frame="D", components=("x", "x"), velocity=np.zeros(2), acceleration=np.zeros(2)), "must be distinct"),
        (dict(frame="D", components=("x",), velocity=np.zeros(2), acceleration=np.zeros(1)), "needs 1 finite"),
        (dict(frame="D", components=("x",), velocity=np.array([np.nan]), acceleration=np.zeros(1)), "finite"),
        (dict(frame="D", components=("x",), velocity=np.zeros(1), acceleration=np.zeros(1), reference="tool"),
         "reference must be"),
    ],
)
def test_malformed_tasks(kwargs, message):
    with pytest.raises(TaskError, match=message):
        Task(**kwargs)


def test_unknown_task_frame(arm):
    from pinmech import FrameNotFound

    with pytest.raises(FrameNotFound, match="unknown point or frame 'E'"):
        RateSolver(arm, [Task("E", ("x",), np.zeros(1), np.zeros(1))])
