"""Text 17.110 from its scene: the robot arm whose CD stays vertical while D moves at 1 m/s.

The report and JSON against Cramer's rule on the text's equations, the printed answers
through `pinmech check`, the rates verified by moving the arm a small step, the scene's
task format and its errors through the CLI.
"""

from __future__ import annotations

import json

import closed_form
import numpy as np
import pinocchio as pin
import pytest

from pinmech import Scene, analyse, compare, load_hand_file, to_dict
from pinmech.io.scene_model import load_mechanism
from pinmech.io.analysis_task import scene_pose
from pinmech.cli import main
from tests.conftest import SCENES
from tests.tolerance import rounding

DEG = np.pi / 180
ARM = SCENES / "planar_arm.toml"


@pytest.fixture(scope="module")
def result() -> dict:
    return to_dict(analyse(Scene.load(ARM)))


@pytest.fixture(scope="module")
def cramer():
    """The text's two equations solved by Cramer's rule, without Pinocchio."""
    return closed_form.planar_arm_rates(50 * DEG, -15 * DEG, -90 * DEG, 0.3, 0.3, 0.17,
                                        np.array([1.0, 0.0]), np.zeros(2))


def test_the_scene_states_the_texts_pose(result):
    """theta1 = 50 deg, BC 15 deg below the horizontal, CD vertical with D below C."""
    angles = {name: result["links"][name]["angle"] / DEG for name in ("AB", "BC", "CD")}
    np.testing.assert_allclose(list(angles.values()), [50.0, -15.0, -90.0], rtol=rounding(1.0))
    C, D = (np.array(result["points"][p]["position"]) for p in "CD")
    np.testing.assert_allclose(D - C, [0.0, -0.17, 0.0], atol=rounding(0.5))


def test_link_rates_against_cramers_rule(result, cramer):
    links = result["links"]
    omega = [links[n]["angular_velocity"][2] for n in ("AB", "BC", "CD")]
    alpha = [links[n]["angular_acceleration"][2] for n in ("AB", "BC", "CD")]
    np.testing.assert_allclose(omega[:2], [cramer.omega_AB, cramer.omega_BC], rtol=1e-10)
    np.testing.assert_allclose(alpha[:2], [cramer.alpha_AB, cramer.alpha_BC], rtol=1e-10)
    np.testing.assert_allclose([omega[2], alpha[2]], [0.0, 0.0], atol=rounding(10.0, result["accuracy"]["condition_number"]))
    joints = result["joints"]
    np.testing.assert_allclose([joints[n]["v"] for n in "ABC"], cramer.q_dot, rtol=1e-10)
    np.testing.assert_allclose([joints[n]["a"] for n in "ABC"], cramer.q_ddot, rtol=1e-10)


def test_D_moves_as_asked(result):
    D = result["points"]["D"]
    np.testing.assert_allclose(D["velocity"], [1.0, 0.0, 0.0], atol=rounding(1.0, result["accuracy"]["condition_number"]))
    np.testing.assert_allclose(D["acceleration"], [0.0, 0.0, 0.0], atol=rounding(10.0, result["accuracy"]["condition_number"]))


def test_json_task_section(result):
    task = result["task"]
    assert (task["method"], task["rank"], task["nullspace_dim"]) == ("exact", 3, 0)
    assert task["condition_number"] == pytest.approx(result["accuracy"]["condition_number"])
    rows = [(r["frame"], r["component"], r["reference"]) for r in task["rows"]]
    assert rows == [("D", "x", "world"), ("D", "y", "world"), ("CD", "wz", "world")]
    np.testing.assert_allclose([r["requested_velocity"] for r in task["rows"]], [1.0, 0.0, 0.0])
    np.testing.assert_allclose([r["achieved_velocity"] for r in task["rows"]], [1.0, 0.0, 0.0], atol=rounding(1.0, task["condition_number"]))
    np.testing.assert_allclose([r["achieved_acceleration"] for r in task["rows"]], 0.0, atol=rounding(10.0, task["condition_number"]))
    assert task["velocity_error"] < rounding(1.0, task["condition_number"])
    assert task["acceleration_error"] < rounding(10.0, task["condition_number"])
    assert set(result) >= {"joints", "links", "points", "accuracy", "task"}


def test_text_report(capsys):
    assert main(["solve", str(ARM)]) == 0
    out = capsys.readouterr().out
    assert "pose: A = 50 deg, B = -65 deg, C = -75 deg" in out
    assert "AB         omega = -3.5526 rad/s (k)   alpha = -12.0521 rad/s^2 (k)" in out
    assert "BC         omega =  2.36413 rad/s (k)   alpha =  16.532 rad/s^2 (k)" in out
    assert "CD         omega =  0 rad/s (k)   alpha =  0 rad/s^2 (k)" in out
    assert "D          v = ( 1,  0) m/s" in out
    assert "D          a = ( 0,  0) m/s^2   |a| =  0 m/s^2" in out  # rounding noise shown as 0
    assert "method: exact (square task, solved exactly)" in out
    assert "D  x  (world)  velocity asked  1 got  1 m/s;  acceleration asked  0 got  0 m/s^2" in out


# ------------------------------------------------------------------ the printed solution
def test_printed_answers_and_slipped_lines(capsys):
    """The four boxed answers are correctly rounded; the two v_C lines with a sign slip,
    evaluated at the text's own rates, are not what C does."""
    hand = load_hand_file(SCENES / "planar_arm.hand.toml")
    verdicts = {v.hand.label: v.verdict for v in compare(to_dict(analyse(Scene.load(hand.scene))), hand.values)}
    assert verdicts == {
        "text: theta1_dot (omega_AB)": "ok",
        "text: omega_BC = -theta2_dot": "ok",
        "text: theta1_ddot (alpha_AB)": "ok",
        "text: alpha_BC = -theta2_ddot": "ok",
        "text's cross-product line, v_C j term, at its own rates": "MISMATCH",
        "text's expanded v_C line, i term, at its own rates": "MISMATCH",
    }
    assert main(["check", str(SCENES / "planar_arm.hand.toml")]) == 1
    assert "4 ok, 0 within rounding, 2 mismatch" in capsys.readouterr().out


def test_the_slipped_lines_evaluated_as_the_hand_file_says():
    """The hand file's -1.39 and 0.64 are the text's two lines at its rates -3.6, -2.4."""
    r1 = r2 = 0.3
    s1, c1, s2, c2 = np.sin(50 * DEG), np.cos(50 * DEG), np.sin(15 * DEG), np.cos(15 * DEG)
    th1_dot, th2_dot = -3.6, -2.4
    cross_line_y = r1 * th1_dot * c1 + r2 * th2_dot * c2           # v_B + r2 th2_dot (-s2 i + c2 j)
    expanded_line_x = -r1 * th1_dot * s1 + r2 * th2_dot * s2       # (-r1 th1_dot s1 + r2 th2_dot s2) i
    equation_x = -r1 * th1_dot * s1 - r2 * th2_dot * s2            # the equation solved: right
    assert round(cross_line_y, 2) == -1.39 and round(expanded_line_x, 2) == 0.64
    assert round(equation_x, 1) == 1.0


def test_the_text_solved_its_accelerations_with_unrounded_rates(cramer):
    """Its own acceleration equations with its printed rates (-3.6, -2.4) give -12.4 and
    -17.0, not its printed -12.1 and -16.5: it rounded the rates for print only."""
    r1 = r2 = 0.3
    s1, c1, s2, c2 = np.sin(50 * DEG), np.cos(50 * DEG), np.sin(15 * DEG), np.cos(15 * DEG)
    M = np.array([[-r1 * s1, -r2 * s2], [r1 * c1, -r2 * c2]])  # unknowns theta1_ddot, theta2_ddot

    def accelerations(w1, w2):
        return np.linalg.solve(M, [r1 * w1**2 * c1 + r2 * w2**2 * c2, r1 * w1**2 * s1 - r2 * w2**2 * s2])

    np.testing.assert_allclose(np.round(accelerations(-3.6, -2.4), 1), [-12.4, -17.0])
    exact = accelerations(cramer.omega_AB, -cramer.omega_BC)  # theta2_dot = -omega_BC
    np.testing.assert_allclose(exact, [cramer.alpha_AB, -cramer.alpha_BC], rtol=rounding(1.0, np.linalg.cond(M)))
    np.testing.assert_allclose(np.round(exact, 1), [-12.1, -16.5])


# ------------------------------------------------------------------ finite differences
def test_moving_the_arm_a_small_step_moves_D_and_CD_as_asked():
    """q(t) = q (+) (t q_dot + t^2/2 q_ddot); D's position and CD's orientation by central
    differences at t = -h, 0, h. h = 1e-4 s: the truncation error is h^2 |x'''| / 6 ~ 1e-8
    (|x'''| ~ 1e2 m/s^3 here) and rounding eps |x| / h^2 ~ 2e-8, so 1e-6 holds with margin."""
    scene = Scene.load(ARM)
    analysis = analyse(scene)
    mech = load_mechanism(scene)
    q, _, _ = scene_pose(scene, mech)
    v, a = analysis.solution.v, analysis.solution.a
    positions, rotations = _along(mech, q, v, a, "D", h=1e-4)
    h = 1e-4
    np.testing.assert_allclose((positions[2] - positions[0]) / (2 * h), [1.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose((positions[2] - 2 * positions[1] + positions[0]) / h**2, 0.0, atol=1e-6)
    phi = [pin.log3(R @ rotations[1].T) for R in rotations]  # CD's turn from t = 0, world axes
    np.testing.assert_allclose((phi[2] - phi[0]) / (2 * h), 0.0, atol=1e-6)
    np.testing.assert_allclose((phi[2] - 2 * phi[1] + phi[0]) / h**2, 0.0, atol=1e-6)


def _along(mech, q, v, a, frame, h):
    """Position and rotation of a frame at t = -h, 0, h along q (+) (t v + t^2/2 a)."""
    model, data, fid = mech.model, mech.model.createData(), mech.frame_id(frame)
    positions, rotations = [], []
    for t in (-h, 0.0, h):
        pin.framesForwardKinematics(model, data, pin.integrate(model, q, t * v + 0.5 * t * t * a))
        positions.append(data.oMf[fid].translation.copy())
        rotations.append(data.oMf[fid].rotation.copy())
    return positions, rotations


# ------------------------------------------------------------------ options through the CLI
def test_over_determined_task_from_the_command_line(capsys):
    """A fourth row (C moves at 2 m/s along x): exit 8 with one line; least squares on request."""
    extra = ('task=[{frame="D", components=["x","y"], velocity=["1 m/s","0 m/s"]}, '
             '{frame="CD", components=["wz"], velocity=["0 rad/s"]}, '
             '{frame="C", components=["x"], velocity=["2 m/s"]}]')
    assert main(["solve", str(ARM), "--set", extra]) == 8
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "over-determined" in err and 'method = "least_squares"' in err
    assert main(["solve", str(ARM), "--set", extra, "--set", 'rates.method="least_squares"']) == 0
    out = capsys.readouterr().out
    assert "method: least_squares (least squares, as asked: the rows cannot all hold" in out
    assert "C  x  (world)  velocity asked  2 got" in out


def test_singular_pose_from_the_command_line(capsys):
    """Stretched arm: exit 7 naming the pose; damped on request, reporting what it misses."""
    stretched = ['pose.A="0 deg"', 'pose.B="0 deg"', 'pose.C="-90 deg"']
    args = ["solve", str(ARM)] + [x for s in stretched for x in ("--set", s)]
    assert main(args) == 7
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "singular at A = 0 deg, B = 0 deg, C = -90 deg (" in err  # as the scene wrote them
    assert main(args + ["--set", 'rates.method="damped"', "--json"]) == 0
    task = json.loads(capsys.readouterr().out)["task"]
    assert task["method"] == "damped" and task["velocity_error"] > 0.5


@pytest.mark.parametrize(
    "override, code, message",
    [
        ('task=[{frame="E", components=["x"], velocity=["1 m/s"]}]', 4, "unknown frame (in task[0]) 'E'"),
        ('task=[{frame="D", components=["vx"], velocity=["1 m/s"]}]', 4, "must be a list of x, y, z, wx, wy, wz"),
        ('task=[{frame="D", components="x", velocity=["1 m/s"]}]', 4, "must be a list of"),
        ('task=[{frame="D", components=["x"], velocity=["1 rad/s"]}]', 4, "task[0].velocity.x: '1 rad/s' is not a"),
        ('task=[{frame="D", components=["wz"], velocity=["1 m/s"]}]', 4, "task[0].velocity.wz: '1 m/s' has no angle"),
        ('task=[{frame="D", components=["x"], velocity=["1 m/s"], acceleration=["1 m/s"]}]', 4,
         "task[0].acceleration.x: '1 m/s' is not a"),
        ('task=[{frame="D", components=["x"], velocity=["1"]}]', 4, "'1' has no unit: write it as '1 m/s'"),
        ('task=[{frame="D", components=["x", "y"], velocity=["1 m/s"]}]', 4, "one quantity per component (2)"),
        ('task=[{frame="D", components=["x"], speed=["1 m/s"]}]', 4, "unknown keys ['speed']"),
        ('task=[{frame="D", velocity=["1 m/s"]}]', 4, "missing keys ['components']"),
        ('task=[{frame="D", components=["x"], velocity=["1 m/s"], reference="tool"}]', 4,
         'task[0].reference: reference must be "world" or "local"'),
        ('task=[{frame="D", components=["x", "y", "z"], velocity=["1 m/s", "0 m/s", "1 m/s"]}]', 8,
         "no joint of the model gives D.z at any pose"),
        # a scene's misspelling: exit 4 naming the key (it was 8, an inconsistent task)
        ('rates.method="pinv"', 4, "rates.method: must be one of exact, least_squares, damped"),
        ('rates.lambda=0.1', 4, "rates: unknown key(s) lambda; known: method, damping, max_condition"),
        ('pose.E="10 deg"', 4, "unknown joint (in [pose]) 'E'"),
        ('pose.A="10 mm"', 4, "pose.A: '10 mm' has no angle unit"),
    ],
)
def test_task_scene_errors_are_one_line(override, code, message, capsys):
    assert main(["solve", str(ARM), "--set", override]) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("pinmech: error: ") and message in err
