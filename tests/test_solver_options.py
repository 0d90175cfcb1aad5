"""The Python API checks what it is given and stays right when shared (issue 11, items 4
and 7): solver options in their ranges, rates that overflow refused, a ground cut frame
moved after the solver was built, and one solver or sweep shared by two threads.

References: the four-bar's closed form (scripts/closed_form.py) at 1e-12 relative (the
README's accuracy for a closed pose), and for the threads the same poses solved by one
thread (identical numbers: the same operations in the same order).
"""

from __future__ import annotations

import sys
import threading

import closed_form
import numpy as np
import pinocchio as pin
import pytest

from pinmech import (
    LoopSolver,
    Mechanism,
    OptionError,
    RateOverflowError,
    Scene,
    TaskError,
)
from pinmech.solve.batch import BatchSolver
from pinmech.solve.cycle import solve_range
from pinmech.io.sweep import Sweep
from tests._mechanisms import four_bar_urdf, write
from tests.tolerance import closure, residual, rounding

# The R-RTR's rate Jacobian over a turn: condition numbers up to 2.0 (measured), 2.5 allowed.
R_RTR_COND = 2.5

A, B, C, D = 0.04, 0.12, 0.08, 0.10


@pytest.fixture
def four_bar(tmp_path):
    return Mechanism.from_urdf(write(tmp_path, "fb.urdf", four_bar_urdf(A, B, C, D)))


# ------------------------------------------------------------------ options (item 7)
@pytest.mark.parametrize("option, value", [
    ("tol", float("nan")), ("tol", float("inf")), ("tol", 1.0), ("tol", 0.0), ("tol", -1e-13), ("tol", "1e-13"),
    ("max_condition", float("nan")), ("max_condition", 0.5), ("max_condition", -1.0),
    ("max_iterations", 0), ("max_iterations", 2.5), ("max_iterations", float("nan")), ("max_iterations", True),
])
def test_solver_options_out_of_range_are_refused(four_bar, option, value):
    """Before: tol=nan, inf or 1.0 returned the unclosed guess; max_condition=nan turned
    the singular check off."""
    with pytest.raises(OptionError, match=option) as info:
        LoopSolver(four_bar, ["O2"], **{option: value})
    assert info.value.option == option
    solver = LoopSolver(four_bar, ["O2"])
    with pytest.raises(OptionError, match=option):
        setattr(solver, option, value)  # set later, as a user's script may


@pytest.mark.parametrize("option, value", [
    ("tol", float("nan")), ("tol", 1.0), ("max_condition", float("nan")), ("max_condition", 0.5),
    ("kernel", "GENERATED"), ("kernel", "fast"), ("kernel", None), ("certify", "often"), ("certify", 10),
    ("damping", float("nan")), ("damping", -1.0), ("method", "bogus"),
])
def test_a_rate_solvers_options_are_checked_when_set_later_too(option, value):
    """A RateSolver checked its options in its constructor only: `rates.tol = nan` after it
    turned the residual check off, `damping = nan` gave NaN rates, `method = "bogus"` a
    KeyError, and `kernel = "GENERATED"` ran the generic passes in silence (a LoopSolver's
    kernel too). Both now refuse them when set, also later."""
    from pinmech import RateSolver, Task
    from tests.conftest import MODELS

    arm = Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    rates = RateSolver(arm, [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)),
                             Task("CD", ("wz",), np.zeros(1), np.zeros(1))])
    before = getattr(rates, option)
    with pytest.raises(TaskError if option in ("damping", "method") else OptionError, match=option):
        setattr(rates, option, value)  # damping = nan gave NaN rates, method = "bogus" a KeyError
    assert getattr(rates, option) == before
    if option in ("kernel", "certify"):
        loop = LoopSolver(Mechanism.from_urdf(MODELS / "r_rtr.urdf"), ["A"])
        with pytest.raises(OptionError, match=option):
            setattr(loop, option, value)


def test_options_at_the_ends_of_their_ranges_work(four_bar):
    solver = LoopSolver(four_bar, ["O2"], tol=1e-3, max_iterations=1000, max_condition=float("inf"))
    assert solver.solve([1.0]).accuracy.residual <= 1e-3
    assert LoopSolver(four_bar, ["O2"], tol=1e-16).tol == 1e-16


@pytest.mark.parametrize("speed, acceleration", [(1e160, 0.0), (-1e160, 1.0), (1e155, 1e300), (1.0, 1e308)])
def test_rates_that_overflow_are_refused(four_bar, speed, acceleration):
    """Before: a driver speed of 1e160 gave NaN accelerations with finite bounds. Either the
    rates are finite or a RateOverflowError names the pose."""
    solver = LoopSolver(four_bar, ["O2"])
    try:
        sol = solver.solve([1.0], [speed], [acceleration])
    except RateOverflowError as exc:
        assert "O2 = 57.29577951 deg" in str(exc)
        assert abs(speed) >= 1e155 or acceleration >= 1e308
    else:
        assert np.all(np.isfinite(sol.v)) and np.all(np.isfinite(sol.a)), sol.a
        assert abs(speed) < 1e155


def test_a_range_whose_rates_overflow_is_refused(r_rtr_scene):
    """Through the API (a scene refuses such a speed when it is read)."""
    sweep = Sweep.from_scene(Scene.load(r_rtr_scene))
    d = sweep.drivers
    for options in ({}, {"batch": False}, {"interpolate": 4}, {"start": "warm"}):
        with pytest.raises(RateOverflowError):
            list(solve_range(LoopSolver(sweep.mechanism, d.names), sweep.driver, sweep.start + np.linspace(0, 1, 200),
                             driver_q=d.q, driver_v=np.array([1e160]), driver_a=d.a, **options))


def test_a_ground_cut_frame_moved_after_the_solver_was_built(tmp_path):
    """Before: the solver kept the cut frame's placement from its construction (residual
    3e-17, real gap 20 mm). Here the rocker's cut frame is on the ground side: the
    four-bar cut at O4 instead of at B, and then O4 moved by 20 mm along x."""
    text = four_bar_urdf(A, B, C, D)
    mech = Mechanism.from_urdf(write(tmp_path, "fb.urdf", _cut_at_o4(text)))
    solver = LoopSolver(mech, ["O2"])
    batch = BatchSolver(solver)
    solver.solve([1.0])
    c = mech.closures[0]
    frame = mech.model.frames[c.parent_frame]
    assert frame.parentJoint == 0  # on the ground
    moved = pin.SE3(frame.placement.rotation, frame.placement.translation + np.array([0.02, 0, 0]))
    mech.model.frames[c.parent_frame].placement = moved
    sol = solver.solve([1.0], [2.0], [0.5])
    theta3 = mech.coordinate(sol.q, "O2") + mech.coordinate(sol.q, "A")  # the coupler's angle
    cf = min((closed_form.four_bar(1.0, 2.0, 0.5, A, B, C, D + 0.02, branch=b) for b in (1, -1)),
             key=lambda f: abs(np.remainder(float(f.theta3) - theta3 + np.pi, 2 * np.pi) - np.pi))
    assert abs(np.remainder(float(cf.theta3) - theta3 + np.pi, 2 * np.pi) - np.pi) < closure(1.0, sol.accuracy.condition)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, sol.q)
    gap = np.linalg.norm(data.oMf[c.parent_frame].translation - data.oMf[c.child_frame].translation)
    assert gap <= residual(0.2)
    rocker = mech.joint("rocker_pin")
    np.testing.assert_allclose(sol.v[rocker.idx_v], cf.omega4 - cf.omega3, rtol=closure(1.0, sol.accuracy.condition, 1))  # relative turn
    out = batch.try_solve(sol.q[None], np.array([[1.0]]), np.array([[2.0]]), np.array([[0.5]]))
    assert out is not None and out.residual[0] <= residual(1.0)
    np.testing.assert_allclose(out.v[0], sol.v, rtol=0, atol=closure(np.abs(sol.v).max(), sol.accuracy.condition, 1))


def _cut_at_o4(text: str) -> str:
    """The four-bar with B a joint of the tree (coupler -> rocker) and the loop cut at the
    ground pivot O4 (a ground cut frame)."""
    text = text.replace("""  <joint name="O4" type="continuous"><parent link="ground"/><child link="rocker"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 0 1"/></joint>""", f"""  <joint name="rocker_pin" type="continuous"><parent link="coupler"/><child link="rocker"/>
    <origin xyz="{B} 0 0" rpy="0 0 3.141592653589793"/><axis xyz="0 0 1"/></joint>""")
    start, end = text.index('  <constraint name="B"'), text.index("</constraint>") + len("</constraint>")
    cut = f"""  <constraint name="O4" type="revolute">
    <parent link="ground"/> <parent_origin xyz="{D} 0 0"/> <parent_axis xyz="0 0 1"/>
    <child link="rocker"/> <child_origin xyz="{C} 0 0"/> <child_axis xyz="0 0 1"/>
  </constraint>"""
    return text[:start] + cut + text[end:]


# ------------------------------------------------------------------ threads (item 4)
@pytest.fixture
def fast_switching():
    """Threads switch every microsecond (the default 5 ms hides most interleavings)."""
    before = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    yield
    sys.setswitchinterval(before)


def _in_threads(work, count: int = 2) -> list:
    results, errors = [None] * count, []

    def run(i):
        try:
            results[i] = work(i)
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(count)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    return results


def test_one_solver_shared_by_two_threads(four_bar, fast_switching):
    """Before: 42-300 wrong answers in 7,200 solves, each with residual 1e-16."""
    solver = LoopSolver(four_bar, ["O2"])
    solver.set_reference([1.0])  # each solve follows the reference's assembly to its angle
    angles = [np.linspace(-2.0, 4.0, 400), np.linspace(4.0, -2.0, 400)]

    def work(i):
        return [solver.solve([x], [2.0], [0.5]) for x in angles[i]]

    shared = _in_threads(work)
    alone = LoopSolver(four_bar, ["O2"])
    alone.set_reference([1.0])
    for i in range(2):
        for x, sol in zip(angles[i], shared[i]):
            ref = alone.solve([x], [2.0], [0.5])
            np.testing.assert_allclose(np.r_[sol.q, sol.v, sol.a], np.r_[ref.q, ref.v, ref.a], rtol=0,
                                       atol=closure(np.abs(np.r_[ref.q, ref.v, ref.a]).max(), ref.accuracy.condition, 2))


def test_one_sweep_shared_by_two_threads(r_rtr_scene, fast_switching):
    sweep = Sweep.from_scene(Scene.load(r_rtr_scene))
    values = sweep.start + np.linspace(0.0, 2 * np.pi, 361)

    def work(i):
        options = ({}, {"batch": False})[i]
        return [(p.motion.points["D"].velocity.copy(), p.motion.points["D"].acceleration.copy())
                for p in sweep.poses(values, **options)]

    shared = _in_threads(work)
    cf = closed_form.r_rtr(values, sweep.drivers.v[0], sweep.drivers.a[0])
    for rows in shared:
        v = np.array([r[0][:2] for r in rows])
        a = np.array([r[1][:2] for r in rows])
        assert np.abs(v - cf.vD).max() <= closure(np.abs(cf.vD).max(), R_RTR_COND, 1)
        assert np.abs(a - cf.aD).max() <= closure(np.abs(cf.aD).max(), R_RTR_COND, 2)


# ------------------------------------------------------------------ more of the same kind
@pytest.mark.parametrize("values", [[0.1, float("nan"), 0.3], [0.1, float("inf")], [float("-inf")]])
def test_a_range_with_a_value_that_is_not_finite_is_refused(r_rtr_scene, values):
    """Before: an infinite value hung the continuation; NaN read as an assembly change.
    Through `solve_range` an OptionError; `Sweep.poses` and `chunks` check first and say
    ModelError."""
    from pinmech import ModelError

    sweep = Sweep.from_scene(Scene.load(r_rtr_scene))
    d = sweep.drivers
    with pytest.raises(OptionError, match="must be a finite number") as info:
        list(solve_range(sweep.solver, sweep.driver, values, driver_q=d.q, driver_v=d.v, driver_a=d.a))
    assert info.value.option == "values"
    with pytest.raises((OptionError, ModelError), match="finite"):
        list(sweep.poses(values))


@pytest.mark.parametrize("chunk", [0, -1, 2.5, True])
def test_a_chunk_size_that_holds_no_pose_is_refused(r_rtr_scene, chunk):
    """Before: chunk=0 returned no pose at all, silently."""
    sweep = Sweep.from_scene(Scene.load(r_rtr_scene))
    d = sweep.drivers
    with pytest.raises(OptionError, match="chunk"):
        list(solve_range(sweep.solver, sweep.driver, [0.1, 0.2], driver_q=d.q, driver_v=d.v, driver_a=d.a,
                         chunk=chunk))


def test_rate_and_force_solvers_check_their_options(models_dir, four_bar):
    from pinmech import ForceSolver, RateSolver, Task

    arm = Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    tasks = [Task("D", ("x", "y"), np.ones(2), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    with pytest.raises(OptionError, match="max_condition"):
        RateSolver(arm, tasks, max_condition=float("nan"))  # before: the singular check was off
    with pytest.raises(OptionError, match="max_condition"):
        ForceSolver(four_bar, ["O2"], max_condition=float("nan"))
    with pytest.raises(OptionError, match="gravity"):
        ForceSolver(four_bar, ["O2"], gravity=(0.0, float("nan"), 0.0))  # before: NaN efforts


def test_a_joint_locked_at_nan_is_named(models_dir):
    from pinmech import ModelError

    with pytest.raises(ModelError, match="locked joint 'O4' must be held at a finite number"):
        Mechanism.from_urdf(models_dir / "four_bar.urdf", locked={"O4": float("nan")})


def test_a_rate_solver_shared_by_two_threads(models_dir, fast_switching):
    """The arm's rate problem (text 17.110's arm) from two threads at once, against one thread."""
    from pinmech import RateSolver, Task

    arm = Mechanism.from_urdf(models_dir / "planar_arm.urdf")
    tasks = [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2)), Task("CD", ("wz",), np.zeros(1), np.zeros(1))]
    solver = RateSolver(arm, tasks)

    def pose(x):
        q = arm.neutral()
        for name, angle in (("A", 0.9 + x), ("B", -1.1 - x), ("C", -1.3 + 0.5 * x)):
            arm.set_coordinate(q, name, angle)
        return q

    xs = [np.linspace(0.0, 0.5, 400), np.linspace(0.5, 0.0, 400)]
    shared = _in_threads(lambda i: [solver.solve(pose(x)) for x in xs[i]])
    alone = RateSolver(arm, tasks)
    for i in range(2):
        for x, sol in zip(xs[i], shared[i]):
            ref = alone.solve(pose(x))
            np.testing.assert_allclose(np.r_[sol.v, sol.a], np.r_[ref.v, ref.a], rtol=0, atol=rounding(np.abs(np.r_[ref.v, ref.a]).max(), ref.condition))


def test_a_closure_in_use_cannot_change_under_its_solver(four_bar):
    """What a solver's rows are built from (axes, scale, basis) is fixed once it is in use:
    changing it would leave the solver with rows of the old cut, in silence."""
    solver = LoopSolver(four_bar, ["O2"])
    c = four_bar.closures[0]
    with pytest.raises(AttributeError, match="in use by a solver"):
        c.length_scale = 1.0
    with pytest.raises(AttributeError, match="in use by a solver"):
        c.axis = np.array([1.0, 0.0, 0.0])
    with pytest.raises(ValueError):
        c.axis[0] = 1.0  # read-only
    assert solver.solve([1.0]).accuracy.residual <= residual(1.0)


@pytest.mark.parametrize("force, torque", [((0.0, float("nan"), 0.0), (0.0, 0.0, 0.0)),
                                           ((0.0, 0.0, 0.0), (0.0, 0.0, float("inf"))), ((1.0, 2.0), (0.0, 0.0, 0.0))])
def test_a_load_that_is_not_three_finite_numbers_is_refused(four_bar, force, torque):
    from pinmech import ForceSolver, Load

    load = Load("push", four_bar.frame_id("P"), np.array(force), np.array(torque))
    with pytest.raises(OptionError, match="load 'push'"):
        ForceSolver(four_bar, ["O2"], loads=[load])
