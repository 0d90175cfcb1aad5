"""The size that sets closure tolerances, condition numbers and error bounds is the size of
what closes the loops (issue 11, item 3), and planar and floating joints are scaled like
prismatic ones (item 9).

References: the four-bar's closed form (scripts/closed_form.py, derived without Pinocchio)
and the R-RTR's. Tolerances: answers are held to 1e-12 relative (the README's accuracy
target for a closed pose); the gap left open at the cut is held to the closure tolerance
(1e-13) times the loop's own size, with a factor 10 for the rows Newton does not solve.
"""

from __future__ import annotations

import closed_form
import numpy as np
import pinocchio as pin
import pytest

from pinmech import LoopSolver, Mechanism, evaluate_motion
from tests._mechanisms import four_bar_urdf, scaled_urdf, write
from tests.conftest import MODELS
from tests.tolerance import closure, rounding

A, B, C, D = 0.04, 0.12, 0.08, 0.10
THETA = 1.0


def _with(text: str, extra: str) -> str:
    return text.replace("</robot>", extra + "\n</robot>")


def _far_point(x: float, parent: str = "ground") -> str:
    return (f'<link name="far"/><joint name="to_far" type="fixed"><parent link="{parent}"/>'
            f'<child link="far"/><origin xyz="{x} 0 0"/></joint>')


def _far_body(x: float) -> str:
    """A link with mass (not a named point) hung far away on the ground."""
    return ('<link name="far_body"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" '
            f'iyz="0"/></inertial></link><joint name="to_far_body" type="fixed"><parent link="ground"/>'
            f'<child link="far_body"/><origin xyz="0 {x} 0"/></joint>')


def _cut_gap(mech: Mechanism, q: np.ndarray, name: str) -> float:
    """Distance between the two sides of a cut [m]."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    c = next(c for c in mech.closures if c.name == name)
    return float(np.linalg.norm(data.oMf[c.parent_frame].translation - data.oMf[c.child_frame].translation))


def _four_bar_against_closed_form(mech: Mechanism, omega: float = 2.0, alpha: float = 0.5) -> LoopSolver:
    solver = LoopSolver(mech, ["O2"])
    sol = solver.solve([THETA], [omega], [alpha])
    cf = closed_form.four_bar(THETA, omega, alpha, A, B, C, D)
    o4 = mech.joint("O4")
    assert _cut_gap(mech, sol.q, "B") <= 10 * solver.tol * 0.18  # the loop's box: O2 (0, 0) to B (0.18, 0)
    np.testing.assert_allclose(mech.coordinate(sol.q, "O4"), cf.theta4, rtol=0, atol=closure(1.0, sol.accuracy.condition))
    np.testing.assert_allclose(sol.v[o4.idx_v], cf.omega4, rtol=closure(1.0, sol.accuracy.condition, 1))
    np.testing.assert_allclose(sol.a[o4.idx_v], cf.alpha4, rtol=closure(1.0, sol.accuracy.condition, 2))
    errors = (abs(sol.v[o4.idx_v] - cf.omega4) / abs(cf.omega4), abs(sol.a[o4.idx_v] - cf.alpha4) / abs(cf.alpha4))
    bounds = sol.accuracy.error_bounds[1:]
    assert errors[0] <= bounds[0] + 1e-15 and errors[1] <= bounds[1] + 1e-15  # rounding of the division itself
    return solver


@pytest.mark.parametrize("x", [1e3, 1e6, 1e12])
def test_a_far_named_point_does_not_loosen_the_closure(tmp_path, x):
    """Before: with a point at 1e12 m the loop stayed open by 36 mm after one Newton step."""
    mech = Mechanism.from_urdf(write(tmp_path, "fb.urdf", _with(four_bar_urdf(A, B, C, D), _far_point(x))))
    assert mech.closures[0].length_scale == pytest.approx(0.18)
    assert mech.length_scale == pytest.approx(0.18)
    _four_bar_against_closed_form(mech)


@pytest.mark.parametrize("x", [1e3, 1e9])
def test_a_far_link_or_a_point_on_a_moving_link_changes_nothing(tmp_path, x):
    text = _with(four_bar_urdf(A, B, C, D), _far_body(x) + _far_point(-x, parent="coupler"))
    mech = Mechanism.from_urdf(write(tmp_path, "fb.urdf", text))
    assert mech.length_scale == pytest.approx(0.18)
    _four_bar_against_closed_form(mech)


def test_a_far_point_does_not_make_a_slide_singular(tmp_path):
    """Before: an R-RTR with a point 1 km away was a false SingularPoseError (the slide's
    column weighed by the size of everything in the file)."""
    text = _with((MODELS / "r_rtr.urdf").read_text(), _far_point(1e3))
    mech = Mechanism.from_urdf(write(tmp_path, "r.urdf", text))
    near = Mechanism.from_urdf(MODELS / "r_rtr.urdf")
    assert mech.velocity_scale().tolist() == near.velocity_scale().tolist()
    solver = LoopSolver(mech, ["A"])
    sol = solver.solve([THETA], [1.0], [0.5], guess=near.neutral())
    assert sol.accuracy.condition == pytest.approx(LoopSolver(near, ["A"]).solve([THETA]).accuracy.condition, rel=1e-9)
    motion = evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=["D"])
    cf = closed_form.r_rtr(THETA, 1.0, 0.5)
    np.testing.assert_allclose(motion.points["D"].velocity[:2], cf.vD, rtol=0, atol=closure(np.abs(cf.vD).max(), sol.accuracy.condition, 1))
    np.testing.assert_allclose(motion.points["D"].acceleration[:2], cf.aD, rtol=0, atol=closure(np.abs(cf.aD).max(), sol.accuracy.condition, 2))


def test_each_loop_closes_to_its_own_size(tmp_path):
    """Two four-bars in one file, 1 m and 40 um: the small one is closed to 1e-13 of its own
    size, not of the large one's (an open gap of 1e-13 m would be 2.5e-9 of it)."""
    big = four_bar_urdf(A, B, C, D)
    tiny = scaled_urdf(four_bar_urdf(A, B, C, D), 4e-5 / 0.18)
    for name in ("O2", "A", "O4", "crank", "coupler", "rocker", '"B"', "point_P", '"P"'):
        bare = name.strip('"')
        tiny = tiny.replace(f'"{bare}"', f'"t{bare}"')
    body = tiny[tiny.index('<link name="tcrank"'):tiny.index("</robot>")]  # its links and joints, on our ground
    text = _with(big, body)
    mech = Mechanism.from_urdf(write(tmp_path, "two.urdf", text))
    sizes = {c.name: c.length_scale for c in mech.closures}
    assert sizes["B"] == pytest.approx(0.18) and sizes["tB"] == pytest.approx(4e-5)
    solver = LoopSolver(mech, ["O2", "tO2"])
    sol = solver.solve([THETA, THETA], [2.0, 2.0], [0.5, 0.5])
    assert _cut_gap(mech, sol.q, "tB") <= 10 * solver.tol * 4e-5
    cf = closed_form.four_bar(THETA, 2.0, 0.5, A, B, C, D)
    for o4 in ("O4", "tO4"):
        j = mech.joint(o4)
        np.testing.assert_allclose([sol.v[j.idx_v], sol.a[j.idx_v]], [cf.omega4, cf.alpha4], rtol=1e-11)


def _planar_coupler_four_bar(a: float = A, b: float = B, c: float = C, d: float = D) -> str:
    """The four-bar with its coupler floating on a planar joint from the ground, held by two
    revolute cuts (at A on the crank and at B on the rocker): 1 + 1 + 3 freedoms, 4 rows."""
    link = ('<link name="{0}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" '
            'iyz="0"/></inertial></link>')
    links = "".join(link.format(n) for n in ("crank", "coupler", "rocker"))
    cut = ('<constraint name="{0}" type="revolute"><parent link="{1}"/><parent_origin xyz="{2} 0 0"/>'
           '<parent_axis xyz="0 0 1"/><child link="coupler"/><child_origin xyz="{3} 0 0"/>'
           '<child_axis xyz="0 0 1"/></constraint>')
    return f"""<?xml version="1.0"?>
<robot name="planar_coupler">
  <link name="ground"/>{links}
  <joint name="O2" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/></joint>
  <joint name="O4" type="continuous"><parent link="ground"/><child link="rocker"/>
    <origin xyz="{d} 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="float" type="planar"><parent link="ground"/><child link="coupler"/><axis xyz="0 0 1"/></joint>
  {cut.format("A", "crank", a, 0)}
  {cut.format("B", "rocker", c, b)}
</robot>
"""


@pytest.mark.parametrize("k", [4e-5 / 0.18, 1.0, 1e3])
def test_a_planar_joint_weighs_its_slides_by_the_loops_size(tmp_path, k):
    """Before: the same four-bar at 40 um was refused as singular (condition 3.9e4 against
    38.7 at its normal size): a planar joint's two slides were weighed in metres. The
    condition number is now the same at every size (to 1e-9: rounding of the scaled rows)."""
    mech = Mechanism.from_urdf(write(tmp_path, "pc.urdf", scaled_urdf(_planar_coupler_four_bar(), k)))
    j = mech.joint("float")
    # the loops: O2-A (0.04 m, the coupler's planar joint sits at O2 when neutral) and O2-O4-B (0.18 m)
    assert mech.velocity_scale()[j.idx_v:j.idx_v + 3] == pytest.approx([0.18 * k, 0.18 * k, 1.0])
    cf = closed_form.four_bar(THETA, 2.0, 0.5, A, B, C, D)
    guess = mech.neutral()
    mech.set_coordinate(guess, "O2", THETA)
    mech.set_coordinate(guess, "O4", float(cf.theta4) + 0.01)
    guess[j.idx_q:j.idx_q + 4] = [A * k * np.cos(THETA), A * k * np.sin(THETA), np.cos(cf.theta3), np.sin(cf.theta3)]
    sol = LoopSolver(mech, ["O2"]).solve([THETA], [2.0], [0.5], guess=guess)
    assert sol.accuracy.condition == pytest.approx(16.864012604477, rel=1e-9)  # its value at k = 1
    o4 = mech.joint("O4")
    np.testing.assert_allclose([sol.v[o4.idx_v], sol.a[o4.idx_v]], [cf.omega4, cf.alpha4], rtol=1e-11)


def test_floating_and_planar_joints_scale_their_translations_only(tmp_path):
    """A free flyer's three translations and a planar joint's two are lengths; their turns are not."""
    mech = Mechanism.from_urdf(write(tmp_path, "pc.urdf", _planar_coupler_four_bar()), root_joint="free_flyer")
    scale = mech.velocity_scale()
    base, floating = mech.joint("root_joint"), mech.joint("float")
    assert scale[base.idx_v:base.idx_v + 6].tolist() == [mech.length_scale] * 3 + [1.0] * 3
    assert scale[floating.idx_v:floating.idx_v + 3].tolist() == [0.18, 0.18, 1.0]


def test_an_arm_ignores_a_far_point_fixed_to_the_ground(tmp_path, models_dir):
    """An open chain's size is that of its joints and what they move: a named point 1e6 m
    away on the ground would weigh the task's x, y rows 1e-6 against its wz row (a false
    singular pose)."""
    from pinmech import RateSolver, Task

    text = _with((models_dir / "planar_arm.urdf").read_text(), _far_point(1e6))
    far = Mechanism.from_urdf(write(tmp_path, "arm.urdf", text))
    near = Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    assert far.length_scale == near.length_scale == pytest.approx(0.77)
    tasks = [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    q = near.neutral()
    for name, angle in (("A", 0.9), ("B", -1.1), ("C", -1.3)):
        near.set_coordinate(q, name, angle)
    a, b = RateSolver(far, tasks).solve(q), RateSolver(near, tasks).solve(q)
    assert a.condition == pytest.approx(b.condition, rel=rounding(1.0, b.condition))
    np.testing.assert_allclose(a.v, b.v, rtol=rounding(1.0, b.condition))
