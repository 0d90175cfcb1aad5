"""The compiled core (pinmech/csrc), the one engine, against closed forms and finite
differences (never against another pinmech path). Tolerances:
- closure rows: the Newton Jacobian is the central difference of the residual on the
  configuration manifold and the drift the central difference of J v along v (h = 1e-6:
  truncation h^2 ~ 1e-12, rounding 1e-16 / h ~ 1e-10 of the rows' size; 1e-7 of it);
- sweeps: every pose closed (Closure's own statement of the rows, 1e-12) and its rates
  central differences of the poses (h = 1e-4 rad: truncation h^2 ~ 1e-8; 1e-6 of the
  rates' size);
- against the R-RTR closed form: 1e-13 (issue 13's bar); the four-bar's law of cosines:
  1e-12 of its size at regular poses, 1e-8 where the sweep nears a fold (rounding times a
  condition number up to the accepted 1e4, and more at the fold itself).
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pinmech
import pinmech.solve.core as core
from pinmech.solve.continuation import (BIFURCATION_STEP, CORRECTOR_ITERATIONS, FOLD_TOL, LAND_TOL, MAX_PIVOT_STEPS,
                                        MAX_STEP, MAX_TURN, PIVOT_BELOW, SINGULAR_NODE, TRUST)
from pinmech.solve.loops import DEFAULT_TOL, POLISH
from tests._mechanisms import cut_rows
from pinmech.solve.loops import MAX_STEP as MAX_NEWTON_STEP
from pinmech.io.sweep import Sweep
from tests.tolerance import STATED_R_RTR, closure, residual, rounding, stated

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import benchmark_loops as chain  # noqa: E402
import closed_form  # noqa: E402

LOOP_SCENES = ["r_rtr.toml", "four_bar.toml", "slider_crank.toml", "four_bar_dynamic.toml",
               "slider_crank_dynamic.toml", "jansen.toml", "four_bar_drawn.toml", "rsur_drawn.toml",
               "marghitu_slider_crank.toml", "four_bar_mjcf.toml", "five_bar.toml"]


def _sweep(scenes_dir: Path, name: str) -> Sweep:
    path = scenes_dir / name
    if not path.is_file():
        pytest.skip(f"{name} is not bundled")
    return Sweep.from_scene(pinmech.Scene.load(path))


def test_the_rules_constants_are_the_documented_ones():
    """The continuation's rules as continuation.py and README state them, read from the core."""
    assert (DEFAULT_TOL, POLISH, MAX_NEWTON_STEP) == (1e-13, 1e-15, 1.0)
    assert (MAX_STEP, TRUST, PIVOT_BELOW, BIFURCATION_STEP) == (0.25, 0.25, 1e-4, 1e-3)
    assert (CORRECTOR_ITERATIONS, SINGULAR_NODE, FOLD_TOL, LAND_TOL, MAX_PIVOT_STEPS) == (8, 1e10, 1e-12, 1e-12, 20000)
    assert MAX_TURN == pytest.approx(math.radians(30.0), rel=rounding(1.0))


def test_the_core_is_built_against_the_pinocchio_pin_loads():
    """The core shares pin's Model objects: pyproject.toml pins the build's libpinocchio and
    the run's pin to one version, and this core was compiled against the pin installed."""
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    project = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    built = [r for r in project["build-system"]["requires"] if r.startswith("libpinocchio")]
    loaded = [r for r in project["project"]["dependencies"] if r.startswith("pin")]
    assert built == [f"libpinocchio=={pin.__version__}"] and loaded[0].split("#")[0].strip() == f"pin=={pin.__version__}"
    assert core._core.PINOCCHIO_VERSION == pin.__version__


def test_a_pin_of_another_version_is_refused_in_one_line(tmp_path):
    """pin reporting another version than the core's: `pinmech solve` prints one line that
    names both versions and what to do, exits 2 (a CoreBuildError), no traceback."""
    import subprocess

    (tmp_path / "sitecustomize.py").write_text('import pinocchio\npinocchio.__version__ = "4.0.9"\n')
    root = Path(__file__).resolve().parents[1]
    run = subprocess.run([sys.executable, "-m", "pinmech", "solve", str(root / "models/scenes/r_rtr.toml")],
                         capture_output=True, text=True, env={**os.environ, "PYTHONPATH": f"{tmp_path}:{root}"})
    assert run.returncode == 2 and run.stdout == ""
    assert run.stderr.count("\n") == 1 and "Traceback" not in run.stderr
    assert f"built against Pinocchio {pin.__version__} but pin 4.0.9 is installed" in run.stderr
    with pytest.raises(pinmech.exceptions.CoreBuildError, match="install pin=="):
        core.check_pinocchio(pin.__version__, "4.0.9")


def test_a_core_that_does_not_load_is_named_in_one_line(tmp_path):
    """A compiled core that is there but does not load (here a file that is no library; in
    use, one linked to another pin's libraries): `pinmech solve` says so in one line with
    what to do (a CoreBuildError, exit 2), not a traceback nor "missing"."""
    import shutil
    import subprocess

    source = Path(pinmech.__file__).parent
    shutil.copytree(source, tmp_path / "pinmech", ignore=shutil.ignore_patterns("*.so", "__pycache__", "csrc"))
    (tmp_path / "pinmech" / Path(core._core.__file__).name).write_bytes(b"not a library")
    root = Path(__file__).resolve().parents[1]
    # the copy, not an editable install's redirect to the checkout (scikit-build-core's finder)
    code = ("import runpy, sys; sys.meta_path[:] = [f for f in sys.meta_path if 'ScikitBuild' not in "
            "type(f).__name__]; sys.path.insert(0, sys.argv.pop(1)); runpy.run_module('pinmech', run_name='__main__')")
    run = subprocess.run([sys.executable, "-c", code, str(tmp_path), "solve", str(root / "models/scenes/r_rtr.toml")],
                         capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 2 and run.stderr.count("\n") == 1, run.stderr
    assert "compiled core does not load beside pin" in run.stderr and "pip install --force-reinstall" in run.stderr


@pytest.mark.parametrize("name", LOOP_SCENES)
def test_closure_rows_are_their_finite_differences(scenes_dir, name):
    """Newton Jacobian and drift at random configurations, closed or not, against central
    differences (see the module docstring)."""
    sweep = _sweep(scenes_dir, name)
    _check_by_finite_differences(core.core_for(sweep.solver), sweep.solver.model, seed=7)


def _check_by_finite_differences(compiled, model, seed: int, h: float = 1e-6) -> None:
    """d r / dq = the Newton Jacobian, and d/dt (J v) along q(t) = q (+) t v = the drift, at
    five random configurations; central differences on the manifold (pin.integrate)."""
    rng = np.random.default_rng(seed)
    for _ in range(5):
        q = pin.integrate(model, pin.neutral(model), rng.uniform(-np.pi, np.pi, model.nv))
        v = rng.normal(size=model.nv)
        compiled.residual(q)
        Jn = compiled.jacobian(True)
        drift = compiled.drift(q, v)
        fd = np.empty_like(Jn)
        for i in range(model.nv):
            e = np.zeros(model.nv)
            e[i] = h
            fd[:, i] = (compiled.residual(pin.integrate(model, q, e)) - compiled.residual(pin.integrate(model, q, -e))) / (2 * h)
        ahead, behind = pin.integrate(model, q, h * v), pin.integrate(model, q, -h * v)
        compiled.residual(ahead)
        Jv_ahead = compiled.jacobian(False) @ v
        compiled.residual(behind)
        Jv_behind = compiled.jacobian(False) @ v
        scale = 1.0 + max(np.abs(Jn).max(), np.abs(drift).max())
        np.testing.assert_allclose(Jn, fd, rtol=0, atol=1e-7 * scale)
        np.testing.assert_allclose(drift, (Jv_ahead - Jv_behind) / (2 * h), rtol=0, atol=1e-7 * scale)


def _rows(sweep: Sweep, values: np.ndarray):
    chunks = list(sweep.chunks(values))
    q = np.concatenate([c.solution.q for c in chunks])
    v = np.concatenate([c.solution.v for c in chunks])
    a = np.concatenate([c.solution.a for c in chunks])
    errors = sorted(c.start + j for c in chunks for j in c.errors)
    notes = [(c.start + j, n) for c in chunks for j, n in sorted(c.notes.items())]
    return q, v, a, errors, notes


@pytest.mark.parametrize("name", LOOP_SCENES)
def test_sweeps_close_the_loops_and_their_rates_are_finite_differences(scenes_dir, name):
    """Every bundled loop scene at eight places over its range: each pose closed, as
    the textbook rows on Pinocchio's placements state them (1e-12 of the loop's size), and q' = dq/dx, q'' = d2q/dx2 the
    central differences of the poses at x - h, x, x + h (the module docstring's bounds)."""
    sweep = _sweep(scenes_dir, name)
    model, data = sweep.solver.model, sweep.solver.model.createData()
    h = 1e-4 if sweep.is_angular else 1e-4 * float(sweep.mechanism.velocity_scale()[
        sweep.mechanism.joint(sweep.driver).idx_v])
    span = np.radians(np.arange(0.0, 360.0, 45.0)) if sweep.is_angular else np.linspace(0.0, 0.02, 8)
    values = (sweep.start + span[:, None] + np.array([-h, 0.0, h])).ravel()
    q, v, a, errors, _ = _rows(sweep, values)
    k = sweep.drivers.names.index(sweep.driver)
    w, alpha = float(sweep.drivers.v[k]), float(sweep.drivers.a[k])
    checked = 0
    for i in range(0, len(values), 3):
        if {i, i + 1, i + 2} & set(errors):
            continue
        for qi in q[i:i + 3]:
            pin.computeJointJacobians(model, data, qi)
            pin.updateFramePlacements(model, data)
            assert max(np.abs(cut_rows(model, data, c)).max() for c in sweep.mechanism.closures) <= residual(1.0)
        checked += 1
        if np.count_nonzero(sweep.drivers.v) > 1:  # the others move too: rates are not the path's alone
            continue
        d1 = pin.difference(model, q[i], q[i + 2]) / (2 * h)
        d2 = (pin.difference(model, q[i + 1], q[i + 2]) - pin.difference(model, q[i], q[i + 1])) / h**2
        size = 1.0 + np.abs(v[i + 1] / w).max()
        np.testing.assert_allclose(v[i + 1] / w, d1, rtol=0, atol=1e-6 * size)
        np.testing.assert_allclose((a[i + 1] - v[i + 1] / w * alpha) / w**2, d2, rtol=0,
                                   atol=1e-3 * (1.0 + np.abs(d2).max()))
    assert checked >= 2  # a rocker's range (rsur_drawn) reaches three of the eight places


def test_r_rtr_sweep_meets_the_closed_form(scenes_dir):
    """P1 of issue 13 through the core: link 3's angle, angular velocity and acceleration,
    and D's velocity and acceleration, within 1e-13 of each quantity's largest magnitude
    over the turn, at every degree (Pinocchio's forward kinematics reads them off q, v, a)."""
    sweep = _sweep(scenes_dir, "r_rtr.toml")
    assert core.core_for(sweep.solver) is not None
    phi = np.radians(np.arange(360.0))
    q, v, a, errors, _ = _rows(sweep, phi)
    assert not errors
    model, data = sweep.solver.model, sweep.solver.model.createData()
    link3, point_d = model.getFrameId("link3"), model.getFrameId("D")
    got = {k: [] for k in ("phi3", "omega3", "alpha3", "vD", "aD")}
    for qi, vi, ai in zip(q, v, a):
        pin.forwardKinematics(model, data, qi, vi, ai)
        R = pin.updateFramePlacement(model, data, link3).rotation
        got["phi3"].append(math.atan2(R[1, 0], R[0, 0]))
        lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        got["omega3"].append(pin.getFrameVelocity(model, data, link3, lwa).angular[2])
        got["alpha3"].append(pin.getFrameClassicalAcceleration(model, data, link3, lwa).angular[2])
        got["vD"].append(pin.getFrameVelocity(model, data, point_d, lwa).linear[:2])
        got["aD"].append(pin.getFrameClassicalAcceleration(model, data, point_d, lwa).linear[:2])
    ref = closed_form.r_rtr(phi, float(sweep.drivers.v[0]), float(sweep.drivers.a[0]))
    d = np.remainder(np.array(got["phi3"]) - ref.phi3 + math.pi, 2 * math.pi) - math.pi
    assert np.abs(d).max() < STATED_R_RTR
    for name in ("omega3", "alpha3", "vD", "aD"):
        want = np.asarray(getattr(ref, name))
        assert np.abs(np.array(got[name]) - want).max() <= STATED_R_RTR * np.abs(want).max(), name


def test_every_pose_of_a_turn_is_polished_to_rounding(scenes_dir):
    """The corrector's polish at every degree of the R-RTR's turn (a chord step on the
    factorization of the pose's Newton step, else Newton's at the pose): link 3's angle
    within 2e-15 rad of the closed form (B - C = s u). 2e-15 is 9 ulp of pi, the rounding
    of atan2 and of the closed form; a pose left after its one Newton step, anywhere below
    tol = 1e-13 of the loop's size, is off by up to 1e-13 times the condition number (1-2)."""
    sweep = _sweep(scenes_dir, "r_rtr.toml")
    phi = np.radians(np.arange(360.0))
    q, _, _, errors, _ = _rows(sweep, phi)
    assert not errors
    model, data = sweep.solver.model, sweep.solver.model.createData()
    link3 = model.getFrameId("link3")
    phi3 = []
    for qi in q:
        pin.framesForwardKinematics(model, data, qi)
        R = data.oMf[link3].rotation
        phi3.append(math.atan2(R[1, 0], R[0, 0]))
    ref = closed_form.r_rtr(phi, float(sweep.drivers.v[0]), float(sweep.drivers.a[0]))
    d = np.remainder(np.array(phi3) - ref.phi3 + math.pi, 2 * math.pi) - math.pi
    assert np.abs(d).max() <= rounding(math.pi, steps=8)


def test_path_derivatives_are_finite_differences_of_the_poses(scenes_dir):
    """q' and q'' of the core's poses against central differences of its own positions
    (h = 1e-4 rad: truncation h^2 ~ 1e-8, rounding 1e-13 / h^2 ~ 1e-5 for q'')."""
    sweep = _sweep(scenes_dir, "four_bar.toml")
    solver = sweep.solver
    x = sweep.start + np.radians(37.0)
    h = 1e-4
    q, v, a, _, _ = _rows(sweep, np.array([x - h, x, x + h]))
    w = float(sweep.drivers.v[sweep.drivers.names.index(sweep.driver)])
    dq1 = pin.difference(solver.model, q[0], q[2]) / (2 * h)
    dq2 = (pin.difference(solver.model, q[1], q[2]) - pin.difference(solver.model, q[0], q[1])) / h**2
    np.testing.assert_allclose(v[1] / w, dq1, rtol=0, atol=1e-7)
    alpha = float(sweep.drivers.a[sweep.drivers.names.index(sweep.driver)])
    np.testing.assert_allclose((a[1] - v[1] / w * alpha) / w**2, dq2, rtol=0, atol=1e-4)


def test_a_moved_cut_frame_is_read_by_the_same_core(scenes_dir):
    """A cut's parent frame moved in the user's model (by dp in its joint's axes) after the
    core was built: the same core (nothing rebuilt) reads the new placement at its next
    call. The position rows are rows6[:, :3] R_P^T (p_C - p_P), and p_P moves by R_J dp
    (R_J its joint's rotation, R_P = R_J R_f): the rows change by -rows6[:, :3] R_f^T dp
    exactly (numbers of 1e-5, to rounding: 1e-15)."""
    sweep = _sweep(scenes_dir, "four_bar.toml")
    solver = sweep.solver
    first = core.core_for(solver)
    closure = solver.mechanism.closures[0]
    q = solver.reference.q
    before = first.residual(q)
    placement = solver.model.frames[closure.parent_frame].placement.copy()
    dp = np.array([1e-6, -2e-6, 0.0])
    placement.translation = placement.translation + dp
    solver.model.frames[closure.parent_frame].placement = placement
    assert core.core_for(solver) is first
    want = -closure._rows6[:, :3] @ (placement.rotation.T @ dp)
    np.testing.assert_allclose(first.residual(q) - before, want, rtol=0, atol=rounding(0.1))


def test_a_changed_tree_builds_a_new_core(scenes_dir):
    """A frame added to the model once its core is built: the core (whose Pinocchio Data
    was sized for the old tree) refuses to run, naming both trees, and `core_for` builds a
    new one, whose closure rows are the same at the same q (to rounding)."""
    sweep = _sweep(scenes_dir, "four_bar.toml")
    solver = sweep.solver
    first = core.core_for(solver)
    q = solver.reference.q
    before = first.residual(q)
    solver.model.addFrame(pin.Frame("extra", 1, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    with pytest.raises(ValueError, match="joints or frames changed since its core was built"):
        first.residual(q)
    second = core.core_for(solver)
    assert second is not first and second.same_structure
    np.testing.assert_allclose(second.residual(q), before, rtol=0, atol=rounding(0.1))


def test_dimensions_changed_in_the_model_are_used_without_a_rebuild(tmp_path):
    """A four-bar (a, b, c, d) = (40, 120, 80, 100) mm swept through the core, then its
    crank a, ground d (joint placements) and coupler pin b (the cut frame's placement)
    changed in the model in place, to (50, 110, 80, 105) mm: the same core, swept again,
    meets the law-of-cosines closed form of the new four-bar at every 5 degrees: pin B to
    1e-12 of its size (the closure tolerance, 1e-13 of the loop's size), omega4 to 1e-10
    (the rates carry the condition number, below 20 here)."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    solver.set_reference([0.3], _four_bar_guess(mech, 0.3, a, b, c, d, +1))
    theta = 0.3 + np.radians(np.arange(0.0, 360.0, 5.0))
    _sweep_solver(solver, theta)
    first = core.core_for(solver)
    assert first is not None
    model, (a, b, d) = mech.model, (0.05, 0.11, 0.105)
    for name, length in (("A", a), ("O4", d)):
        M = model.jointPlacements[mech.joint(name).id].copy()
        M.translation = np.array([length, 0.0, 0.0])
        model.jointPlacements[mech.joint(name).id] = M
    cut_frame = mech.closures[0].parent_frame  # on the coupler, at b
    M = model.frames[cut_frame].placement.copy()
    M.translation = np.array([b, 0.0, 0.0])
    model.frames[cut_frame].placement = M
    solver.set_reference([0.3], _four_bar_guess(mech, 0.3, a, b, c, d, +1))
    q, errors, _ = _sweep_solver(solver, theta)
    chunk = next(solve_range(solver, "O2", theta, driver_q=np.zeros(1), driver_v=np.ones(1), driver_a=np.zeros(1)))
    assert core.core_for(solver) is first and not errors
    for i, th in enumerate(theta):
        ref = closed_form.four_bar(th, 1.0, 0.0, a, b, c, d, +1)
        np.testing.assert_allclose(_rocker_tip(mech, q[i], c, d), ref.B, rtol=0, atol=closure(d, chunk.solution.condition[i]))
        omega4 = chunk.solution.v[i][mech.joint("O4").idx_v]
        np.testing.assert_allclose(omega4, float(ref.omega4), rtol=0, atol=1e-10 * (1 + abs(float(ref.omega4))))


def test_a_model_with_a_composite_joint_is_swept_by_the_core(scenes_dir):
    """The MJCF leg hangs its rod on two hinges in one body (a Pinocchio composite joint):
    the core sweeps it, the loops close to the tolerance at every pose, and its rates are
    central differences of its own poses (h = 1e-4 rad: truncation h^2 ~ 1e-8)."""
    sweep = _sweep(scenes_dir, "leg_mjcf.toml")
    solver = sweep.solver
    assert core.core_for(solver) is not None
    assert any(solver.model.joints[j].shortname() == "JointModelComposite" for j in range(1, solver.model.njoints))
    x, h = sweep.start + np.radians(9.0), 1e-4
    q, v, a, errors, _ = _rows(sweep, np.array([x - h, x, x + h]))
    assert not errors
    for qi in q:
        assert np.abs(solver._residual(qi)).max() <= residual(1.0) and solver._full_residual() <= residual(1.0)
    w = float(sweep.drivers.v[sweep.drivers.names.index(sweep.driver)])
    dq1 = pin.difference(solver.model, q[0], q[2]) / (2 * h)
    np.testing.assert_allclose(v[1] / w, dq1, rtol=0, atol=1e-7)


# ---------------------------------------------------------------------- hypothesis
from hypothesis import HealthCheck, assume, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from pinmech import LoopSolver, SingularPoseError  # noqa: E402
from pinmech.solve.cycle import solve_range  # noqa: E402
from tests.test_assembly import _four_bar, _four_bar_guess, _rocker_tip  # noqa: E402
from tests.test_assembly import _sweep as _sweep_solver  # noqa: E402
from tests._mechanisms import write  # noqa: E402


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(a=st.floats(0.02, 0.1), b=st.floats(0.05, 0.15), c=st.floats(0.03, 0.12), d=st.floats(0.05, 0.12),
       start=st.floats(0, 2 * math.pi), step=st.floats(0.5, 50), branch=st.sampled_from([1, -1]))
def test_random_four_bars_meet_the_law_of_cosines(tmp_path_factory, a, b, c, d, start, step, branch):
    """Random dimensions (Grashof or not: folds, limit angles), starts and spacings: every
    pose the sweep gives is the closed form's on the branch it started on (1e-12 of the
    size where the pose is regular, 1e-8 near a fold: see the module docstring), and every
    pose the closed form cannot reach on it is a named failure."""
    lengths = sorted((a, b, c, d))
    assume(abs(lengths[0] + lengths[3] - lengths[1] - lengths[2]) > 1e-3 * lengths[3])
    try:
        closed_form.four_bar(start, 0, 0, a, b, c, d, branch)
    except ValueError:
        return
    mech = _four_bar(tmp_path_factory.mktemp("fb"), a, b, c, d)
    values = start + np.radians(np.arange(0, 370, step))
    solver = LoopSolver(mech, ["O2"])
    try:
        solver.set_reference([start], _four_bar_guess(mech, start, a, b, c, d, branch))
    except (SingularPoseError, pinmech.LoopClosureError):
        return
    q, errors, _ = _sweep_solver(solver, values)
    size = max(a, b, c, d)
    for i, th in enumerate(values):
        try:
            ref = closed_form.four_bar(th, 1.0, 0.0, a, b, c, d, branch)
        except ValueError:
            assert i in errors, i
            continue
        if i not in errors:
            assert np.abs(_rocker_tip(mech, q[i], c, d) - ref.B).max() <= 1e-8 * size, i


@pytest.mark.parametrize("size", [1e-6, 1e-3, 1.0, 1e3, 1e6])
def test_four_bars_from_micrometres_to_kilometres_meet_the_closed_form(tmp_path, size):
    """A crank-rocker scaled from 1e-6 to 1e6 m swept by the core over a turn at 1 degree:
    its pin B within 1e-12 of the size of the law-of-cosines closed form at every pose (the
    closure tolerance is relative to each loop's size, 1e-13), rates within 1e-10 of theirs
    (the closed form's rates carry the condition number, below 20 here)."""
    a, b, c, d = (x * size for x in (0.04, 0.12, 0.08, 0.10))
    mech = _four_bar(tmp_path, a, b, c, d)
    solver = LoopSolver(mech, ["O2"])
    assert core.core_for(solver) is not None
    solver.set_reference([0.3], _four_bar_guess(mech, 0.3, a, b, c, d, +1))
    theta = 0.3 + np.radians(np.arange(360.0))
    q, errors, _ = _sweep_solver(solver, theta)
    chunk = next(solve_range(solver, "O2", theta, driver_q=np.zeros(1), driver_v=np.ones(1), driver_a=np.zeros(1)))
    assert not errors
    for i, th in enumerate(theta):
        ref = closed_form.four_bar(th, 1.0, 0.0, a, b, c, d, +1)
        assert np.abs(_rocker_tip(mech, q[i], c, d) - ref.B).max() <= closure(size, chunk.solution.condition[i]), i
        omega4 = chunk.solution.v[i][mech.joint("O4").idx_v]
        assert abs(omega4 - float(ref.omega4)) <= 1e-10 * (1 + abs(float(ref.omega4))), i


def test_a_new_tolerance_is_set_on_the_same_core(scenes_dir):
    sweep = _sweep(scenes_dir, "four_bar.toml")
    first = core.core_for(sweep.solver)
    sweep.solver.tol = 1e-9
    second = core.core_for(sweep.solver)
    assert second is first and second.tol == 1e-9


def test_a_link_lengthened_in_the_model_after_a_sweep_is_seen(scenes_dir):
    """A joint placement changed in place once the core is built (a link made longer in
    code): the next sweep reads it with the same core (nothing rebuilt): its poses move,
    and they close the loops of the new model as the textbook rows on Pinocchio's placements state them (1e-12)."""
    sweep = _sweep(scenes_dir, "four_bar.toml")
    model = sweep.solver.model
    values = sweep.start + np.radians(np.arange(0.0, 40.0, 5.0))
    before = _rows(sweep, values)[0]
    first = core.core_for(sweep.solver)
    jid = max(range(1, model.njoints), key=lambda j: np.linalg.norm(model.jointPlacements[j].translation))
    M = model.jointPlacements[jid].copy()
    M.translation = M.translation * 1.01
    model.jointPlacements[jid] = M
    sweep.solver.set_reference(sweep.drivers.q, sweep.solver.reference.q)
    after = _rows(sweep, values)[0]
    assert core.core_for(sweep.solver) is first
    data = model.createData()
    for qa, qb in zip(before, after):
        assert sweep.solver.turn_gap(qa, qb) > 1e-6
        pin.computeJointJacobians(model, data, qb)
        pin.updateFramePlacements(model, data)
        assert max(np.abs(cut_rows(model, data, c)).max() for c in sweep.mechanism.closures) <= residual(1.0)


# ---------------------------------------------------------------------- chains and condition numbers
def _carried_chain(tmp_path: Path, k: int):
    """k four-bars in series whose ground pivots sit on a carrier link turning about a
    tilted axis: every cut frame hangs below the carrier's joint, which moves both sides
    of each cut together (the core leaves its column of the relative Jacobians out)."""
    text = chain.chain_urdf(k).replace('<parent link="ground"/><child link="L', '<parent link="base"/><child link="L')
    carrier = ('<link name="base"/><joint name="carrier" type="continuous"><parent link="ground"/>'
               '<child link="base"/><origin xyz="0.3 -0.2 0.1" rpy="0.2 0.1 0"/><axis xyz="0.3 0.4 0.866"/></joint>')
    text = text.replace('<link name="ground"/>', '<link name="ground"/>' + carrier)
    path = tmp_path / f"carried_chain_{k}.urdf"
    path.write_text(text, encoding="utf-8")
    mech = pinmech.Mechanism.from_urdf(path)
    return pinmech.LoopSolver(mech, ["carrier", "O0"])


@pytest.mark.parametrize("carried", [False, True], ids=["ground", "carried"])
def test_chain_closure_rows_are_their_finite_differences(tmp_path, carried):
    """Four loops in series, on the ground or carried by a turning link: the core computes
    each cut's Jacobian over the joints that move one side of the cut and not the other;
    finite differences see every column, where the shared ones cancel."""
    solver = _carried_chain(tmp_path, 4) if carried else chain.chain_solver(4, folder=tmp_path)[1]
    compiled = core.core_for(solver)
    assert compiled is not None
    assert compiled.solve_blocks == 4  # forward substitution over the four loops' blocks
    _check_by_finite_differences(compiled, solver.model, seed=11)
    model = solver.model
    if carried:  # the carrier turns both sides of every cut: its column is exactly zero
        assert not compiled.jacobian(False)[:, model.joints[model.getJointId("carrier")].idx_v].any()


def test_closure_rows_on_a_floating_base_are_their_finite_differences(tmp_path):
    """Three loops in series on a free-flying base (a rate problem's model, as RateSolver
    hands it to the core): the base's six columns move both sides of every cut, so the
    core leaves them exactly zero; the rows are their finite differences."""
    path = tmp_path / "floating_chain.urdf"
    path.write_text(chain.chain_urdf(3), encoding="utf-8")
    mech = pinmech.Mechanism.from_urdf(path, root_joint="free_flyer")
    model = mech.model
    compiled, _ = core.compile_loops(model, mech.closures, mech.velocity_scale())
    base = model.joints[model.getJointId("root_joint")]
    assert base.nv == 6
    _check_by_finite_differences(compiled, model, seed=5)
    rng = np.random.default_rng(5)
    for _ in range(5):
        compiled.residual(pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv)))
        assert not compiled.jacobian(False)[:, base.idx_v:base.idx_v + 6].any()


def _with_singular_values(rng, s: np.ndarray) -> np.ndarray:
    n = len(s)
    U, _ = np.linalg.qr(rng.normal(size=(n, n)))
    V, _ = np.linalg.qr(rng.normal(size=(n, n)))
    return (U * s) @ V.T


@settings(max_examples=200, deadline=None)
@given(n=st.integers(1, 40), log_condition=st.floats(0.0, 12.0), log_size=st.floats(-8.0, 8.0),
       seed=st.integers(0, 2**32 - 1))
def test_condition_numbers_are_the_svds(n, log_condition, log_size, seed):
    """The core's condition number and smallest singular value (closed form at 2x2,
    eigenvalues of fixed-size products at 3x3; above, a bidiagonalization, then Laguerre's
    method on its Golub-Kahan matrix, certified by Sturm counts) and the Python path's
    (solve_loops._condition: closed forms to 2x2, SVD above) against numpy's SVD, square
    matrices 1x1 to 40x40 (dense: the Householder bidiagonalization),
    condition numbers 1 to 1e12, sizes 1e-8 to 1e8. All are exact to rounding: sigma_max
    to a few eps relative, sigma_min to about eps x condition (the SVD's own accuracy, and
    what rounding A itself moves it by), so the bar is 100 n eps kappa. (It found
    the 2x2 closed form losing 1.4e-12 at condition 1.00007, and the 3x3 cofactor inverse
    losing 2e-3 at 1e10.)"""
    rng = np.random.default_rng(seed)
    s = 10.0**log_size * np.geomspace(1.0, 10.0**-log_condition, n)
    A = _with_singular_values(rng, s)
    sigma = np.linalg.svd(A, compute_uv=False)
    want = sigma[0] / sigma[-1]
    bar = rounding(1.0, want, steps=100 * n)
    for condition, sigma_min in (core._core.condition(A),):
        assert condition == pytest.approx(want, rel=bar)
        assert sigma_min == pytest.approx(sigma[-1], rel=bar)


@settings(max_examples=200, deadline=None)
@given(n=st.integers(4, 40), kl=st.integers(0, 5), ku=st.integers(0, 5), log_grade=st.floats(0.0, 8.0),
       seed=st.integers(0, 2**32 - 1))
@example(n=32, kl=2, ku=1, log_grade=0.0, seed=1)  # a chain of 16 four-bars
@example(n=40, kl=2, ku=1, log_grade=6.0, seed=2)
@example(n=300, kl=2, ku=1, log_grade=0.0, seed=3)  # more bulge chases in flight than the core keeps at once (64)
@example(n=200, kl=3, ku=4, log_grade=3.0, seed=4)  # several chases a row, many in flight
def test_condition_numbers_of_band_matrices_are_the_svds(n, kl, ku, log_grade, seed):
    """Band matrices, kl nonzeros below the diagonal and ku above (the dependent Jacobian
    of a chain of loops has 2 and 1), rows graded over up to 8 decades. Where the band is
    narrow (5.5 (kl + ku) <= n + 8) the core bidiagonalizes by plane rotations that keep
    the band, else by reflections: both give the SVD's numbers, to the bar above. (The
    rotations chase several bulges down the band at once: an order that let one chase
    touch what an earlier one has still to touch would give other numbers.)"""
    rng = np.random.default_rng(seed)
    i, j = np.indices((n, n))
    A = np.where((i - j <= kl) & (j - i <= ku), rng.normal(size=(n, n)), 0.0)
    A *= np.geomspace(1.0, 10.0**-log_grade, n)[:, None]
    sigma = np.linalg.svd(A, compute_uv=False)
    assume(sigma[-1] > 0 and sigma[0] / sigma[-1] < 1e12)
    want = sigma[0] / sigma[-1]
    bar = rounding(1.0, want, steps=100 * n)
    condition, sigma_min = core._core.condition(A)
    assert condition == pytest.approx(want, rel=bar)
    assert sigma_min == pytest.approx(sigma[-1], rel=bar)


@pytest.mark.parametrize("n", [3, 4, 9, 32, 40])
@pytest.mark.parametrize("spectrum", ["top cluster", "bottom cluster", "repeated", "graded"])
def test_condition_numbers_of_clustered_singular_values(n, spectrum):
    """Singular values in a cluster act on Laguerre's method like a multiple root: it
    converges slowly there, and the core falls back to bisection on its Sturm counts. Every
    spectrum here gives the SVD's numbers to the same bar as above: all but the smallest
    within 1e-9 of 1 ("top cluster"), all but the largest within 1e-10 of 1e-7 ("bottom
    cluster"), exactly repeated values, and a spectrum spread evenly over 12 decades."""
    rng = np.random.default_rng(n)
    i = np.arange(n)
    s = {"top cluster": np.where(i < n - 1, 1.0 + 1e-9 * i, 1e-6),
         "bottom cluster": np.where(i == 0, 1.0, 1e-7 * (1.0 + 1e-10 * i)),
         "repeated": np.where(i < n // 2, 3.0, 0.5),
         "graded": np.geomspace(1.0, 1e-12, n)}[spectrum]
    for _ in range(5):
        A = _with_singular_values(rng, s)
        sigma = np.linalg.svd(A, compute_uv=False)
        want = sigma[0] / sigma[-1]
        bar = rounding(1.0, want, steps=100 * n)
        condition, sigma_min = core._core.condition(A)
        assert condition == pytest.approx(want, rel=bar)
        assert sigma_min == pytest.approx(sigma[-1], rel=bar)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 9, 32])
def test_singular_matrices_have_infinite_condition(n):
    """A zero row or a repeated column is singular at every size: condition inf, sigma_min
    0 where the factorization meets an exact zero, else beyond 1e15 (rounding's floor)."""
    rng = np.random.default_rng(n)
    A = rng.normal(size=(n, n))
    A[-1] = 0.0
    assert core._core.condition(A) == (math.inf, 0.0)
    if n >= 2:
        B = rng.normal(size=(n, n))
        B[:, -1] = B[:, 0]
        condition, sigma_min = core._core.condition(B)
        assert condition > 1e15 and sigma_min < rounding(np.linalg.norm(B, 2))
    with pytest.raises(ValueError, match="square"):
        core._core.condition(np.zeros((n, n + 1)))


@pytest.mark.parametrize("name", ["r_rtr.toml", "jansen.toml"])
def test_pinocchio_passes_compute_pinocchios_kinematics(scenes_dir, name):
    """Core.pinocchio_passes (the benchmark's measure of Pinocchio's share of a pose) runs
    Pinocchio's own kinematics: the last joint's world position and the linear part of
    its spatial acceleration at a = 0, rotated to world axes, are pin's from Python at
    random q and v, whatever the number of Jacobian passes before. Tolerance 1e-13 of
    the mechanism's size (m) and of |v|^2 times it: the same Pinocchio calls on the
    rebuilt model, rounding apart."""
    sweep = _sweep(scenes_dir, name)
    compiled = core.core_for(sweep.solver)
    model = sweep.mechanism.model
    data = model.createData()
    rng = np.random.default_rng(3)
    Q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) for _ in range(5)])
    V = rng.normal(size=(5, model.nv))
    last = model.njoints - 1
    want = []
    for q, v in zip(Q, V):
        pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
        R = data.oMi[last].rotation
        want.append(np.r_[data.oMi[last].translation, R @ data.a[last].linear])
    size = max(1.0, np.max(np.abs(np.array(want)[:, :3])))
    for jacobians in (0, 1, 2):
        got = compiled.pinocchio_passes(Q, V, jacobians)
        assert got.shape == (5, 6)
        np.testing.assert_allclose(got[:, :3], np.array(want)[:, :3], rtol=0, atol=rounding(size))
        np.testing.assert_allclose(got[:, 3:], np.array(want)[:, 3:], rtol=0,
                                   atol=rounding(size * (1 + np.max(np.abs(V))) ** 2))
    with pytest.raises(ValueError, match="wrong shapes"):
        compiled.pinocchio_passes(Q[:, :-1], V, 1)


# ---------------------------------------------------------------------- every joint Pinocchio has
def _tilted(x: float, y: float, z: float) -> pin.SE3:
    return pin.SE3(pin.rpy.rpyToMatrix(0.1, -0.2, 0.3), np.array([x, y, z]))


def _kind(model: pin.Model, kind: str) -> int:
    """The joint (or joints) of `kind` from the ground; returns the joint the cut's P chain
    goes on from."""
    joints = {
        "helical": lambda: pin.JointModelHelicalUnaligned(np.array([0.0, 0.6, 0.8]), 0.05),
        "helical_z": lambda: pin.JointModelHZ(0.03),
        "universal": lambda: pin.JointModelUniversal(np.array([1.0, 0, 0]), np.array([0, 1.0, 0])),
        "ellipsoid": lambda: pin.JointModelEllipsoid(0.02, 0.03, 0.04),
        "spherical_zyx": pin.JointModelSphericalZYX,
        "spherical": pin.JointModelSpherical,
        "planar": pin.JointModelPlanar,
        "free_flyer": pin.JointModelFreeFlyer,
        "translation": pin.JointModelTranslation,
        "prismatic_unaligned": lambda: pin.JointModelPrismaticUnaligned(np.array([0.6, 0.0, 0.8])),
    }
    if kind == "composite":  # MJCF's several hinges (and a slide) in one body
        composite = pin.JointModelComposite()
        composite.addJoint(pin.JointModelRX(), _tilted(0, 0, 0))
        composite.addJoint(pin.JointModelPY(), _tilted(0.01, 0, 0))
        return model.addJoint(0, composite, _tilted(0.05, 0, 0), "k")
    if kind == "mimic":  # a gear in the chain: the follower turns 2x its leader + 0.1 rad
        leader = model.addJoint(0, pin.JointModelRX(), _tilted(0.05, 0, 0), "leader")
        return model.addJoint(leader, pin.JointModelMimic(model.joints[leader], 2.0, 0.1), _tilted(0.02, 0.03, 0), "k")
    return model.addJoint(0, joints[kind](), _tilted(0.05, 0, 0), "k")


def _two_chains(kind: str):
    """A joint of `kind` and a hinge carrying the cut frame P, and a hinge from the ground
    carrying the cut frame C (with "mimic": the follower of P's leader on C's side too).
    Returns the model and a spherical Closure between P and C."""
    from pinmech.model.closures import Closure

    model = pin.Model()
    k = _kind(model, kind)
    hinge = model.addJoint(k, pin.JointModelRZ(), _tilted(0.1, 0.02, 0.0), "r")
    P = model.addFrame(pin.Frame("P", hinge, pin.SE3(np.eye(3), np.array([0.08, 0.0, 0.01])), pin.FrameType.OP_FRAME))
    if kind == "mimic":  # a follower on C's side as well: P's and C's columns add up in one
        other = model.addJoint(0, pin.JointModelMimic(model.joints[1], -1.5, 0.0), _tilted(0.2, 0.05, 0.03), "m2")
    else:
        other = 0
    hinge2 = model.addJoint(other, pin.JointModelRY(), _tilted(0.2, 0.05, 0.03), "s")
    C = model.addFrame(pin.Frame("C", hinge2, pin.SE3(np.eye(3), np.array([0.0, 0.07, 0.0])), pin.FrameType.OP_FRAME))
    axis = np.array([0.0, 0.0, 1.0])
    return model, Closure("cut", "spherical", P, C, axis, axis)


def _relative_position(model: pin.Model, closure, q: np.ndarray) -> np.ndarray:
    """R_P^T (p_C - p_P) from Pinocchio's own frame placements [m]."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    M_P, M_C = data.oMf[closure.parent_frame], data.oMf[closure.child_frame]
    return M_P.rotation.T @ (M_C.translation - M_P.translation)


@pytest.mark.parametrize("kind", ["helical", "helical_z", "universal", "ellipsoid", "spherical_zyx", "spherical",
                                  "planar", "free_flyer", "translation", "prismatic_unaligned", "composite",
                                  "mimic"])
def test_the_core_serves_every_joint_kind(kind):
    """On a model with the joint kind (built in code, tilted placements, a spherical cut),
    at three seeded configurations: the core's closure rows are Pinocchio's R_P^T (p_C - p_P)
    (to 1e-15, rounding of numbers of 0.3); its Jacobian is their central difference on the
    configuration manifold (pin.integrate, h = 1e-6: truncation h^2 ~ 1e-12, rounding
    eps / h ~ 1e-10; atol 1e-8); its drift (J-dot v) is the central difference of J v
    along q + t v (same h, atol 1e-7 for numbers of order 1)."""
    model, closure = _two_chains(kind)
    built = core.compile_loops(model, [closure], np.ones(model.nv))
    assert built is not None
    compiled, rng, h = built[0], np.random.default_rng(11), 1e-6
    for _ in range(3):
        q = pin.integrate(model, pin.neutral(model), rng.uniform(-1.0, 1.0, model.nv))
        np.testing.assert_allclose(compiled.residual(q), _relative_position(model, closure, q), rtol=0, atol=rounding(0.3))
        J = compiled.jacobian(False)
        for k in range(model.nv):
            e = np.zeros(model.nv)
            e[k] = h
            fd = (_relative_position(model, closure, pin.integrate(model, q, e))
                  - _relative_position(model, closure, pin.integrate(model, q, -e))) / (2 * h)
            np.testing.assert_allclose(J[:, k], fd, rtol=0, atol=1e-8, err_msg=f"column {k}")
        v = rng.normal(size=model.nv)
        drift = compiled.drift(q, v)
        compiled.residual(pin.integrate(model, q, h * v))
        Jv_plus = compiled.jacobian(False) @ v
        compiled.residual(pin.integrate(model, q, -h * v))
        Jv_minus = compiled.jacobian(False) @ v
        np.testing.assert_allclose(drift, (Jv_plus - Jv_minus) / (2 * h), rtol=0, atol=1e-7)


GEARED = {"a": 0.04, "a2": 0.05, "d": 0.12, "b": 0.11, "c": 0.12, "offset": 0.5}


def _geared_five_bar_urdf(a, a2, d, b, c, offset) -> str:
    """Two cranks geared 1:-1 (URDF <mimic>: O5 = -O2 + offset), carrying links b and c
    pinned together at C (the cut): a five-bar of one freedom."""
    return f"""<?xml version="1.0"?>
<robot name="geared_five_bar">
  <link name="ground"/> <link name="crank1"/> <link name="link1"/> <link name="crank2"/> <link name="link2"/>
  <joint name="O2" type="revolute"><parent link="ground"/><child link="crank1"/><axis xyz="0 0 1"/>
    <limit lower="-10" upper="10" effort="1" velocity="1"/></joint>
  <joint name="A" type="continuous"><parent link="crank1"/><child link="link1"/>
    <origin xyz="{a} 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="O5" type="revolute"><parent link="ground"/><child link="crank2"/>
    <origin xyz="{d} 0 0"/><axis xyz="0 0 1"/><limit lower="-10" upper="10" effort="1" velocity="1"/>
    <mimic joint="O2" multiplier="-1" offset="{offset}"/></joint>
  <joint name="E" type="continuous"><parent link="crank2"/><child link="link2"/>
    <origin xyz="{a2} 0 0"/><axis xyz="0 0 1"/></joint>
  <constraint name="C" type="revolute">
    <parent link="link1"/> <parent_origin xyz="{b} 0 0"/> <parent_axis xyz="0 0 1"/>
    <child link="link2"/> <child_origin xyz="{c} 0 0"/> <child_axis xyz="0 0 1"/>
  </constraint>
</robot>
"""


def _geared_c(theta: float, a, a2, d, b, c, offset) -> tuple[np.ndarray, float, float]:
    """The closed form: A = a e(theta), E = (d, 0) + a2 e(offset - theta), C the crossing of
    the circles (A, b) and (E, c) left of A -> E; returns C and the angles of b and c."""
    A = a * np.array([math.cos(theta), math.sin(theta)])
    E = np.array([d, 0.0]) + a2 * np.array([math.cos(offset - theta), math.sin(offset - theta)])
    w = E - A
    L = math.hypot(*w)
    x = (L * L + b * b - c * c) / (2 * L)
    C = A + x * w / L + math.sqrt(b * b - x * x) * np.array([-w[1], w[0]]) / L
    return C, math.atan2(*(C - A)[::-1]), math.atan2(*(C - E)[::-1])


def test_a_geared_five_bar_with_a_mimic_joint_meets_its_closed_form(tmp_path):
    """Two cranks geared by a URDF <mimic> (a Pinocchio mimic joint, no freedom of its own)
    swept by the core every 10 degrees: pin C within 1e-12 of its size of the two-circle
    closed form, and C's velocity within 1e-8 of the closed form's central difference in
    theta (h = 1e-6: truncation h^2 ~ 1e-12, rounding eps / h ~ 1e-10 of 0.1 m); the
    follower's link, read by the core's frame_paths, where the gear puts it."""
    g = GEARED
    mech = pinmech.Mechanism.from_urdf(write(tmp_path, "geared.urdf", _geared_five_bar_urdf(**g)))
    assert any(mech.model.joints[j].shortname() == "JointModelMimic" for j in range(1, mech.model.njoints))
    solver = LoopSolver(mech, ["O2"])
    assert core.core_for(solver) is not None
    theta0 = 0.2
    C, phi_b, phi_c = _geared_c(theta0, **g)
    guess = mech.neutral()
    mech.set_coordinate(guess, "O2", theta0)
    mech.set_coordinate(guess, "A", phi_b - theta0)
    mech.set_coordinate(guess, "E", phi_c - (g["offset"] - theta0))
    solver.set_reference([theta0], guess)
    theta = theta0 + np.radians(np.arange(0.0, 360.0, 10.0))
    chunk = next(solve_range(solver, "O2", theta, driver_q=np.zeros(1), driver_v=np.ones(1), driver_a=np.zeros(1)))
    assert not chunk.errors
    model, data, h = mech.model, mech.model.createData(), 1e-6
    cut = mech.closures[0].parent_frame
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    for i, th in enumerate(theta):
        pin.forwardKinematics(model, data, chunk.solution.q[i], chunk.solution.v[i])
        got = pin.updateFramePlacement(model, data, cut).translation[:2]
        np.testing.assert_allclose(got, _geared_c(th, **g)[0], rtol=0, atol=stated(chunk.solution.residual[i], chunk.solution.condition[i], g["d"]))
        want_v = (_geared_c(th + h, **g)[0] - _geared_c(th - h, **g)[0]) / (2 * h)
        np.testing.assert_allclose(pin.getFrameVelocity(model, data, cut, lwa).linear[:2], want_v, rtol=0, atol=1e-8)
    # the follower's link through the core's frame_paths: E = (d, 0) + a2 e(offset - theta),
    # E' = a2 e_perp(offset - theta) * (-1) at theta' = 1 (exact to rounding: 1e-15 of 0.1 m)
    paths = pinmech.frame_paths(mech, ["link2"], chunk.solution.q, chunk.solution.v, chunk.solution.a)
    psi = g["offset"] - theta
    E = np.stack([g["d"] + g["a2"] * np.cos(psi), g["a2"] * np.sin(psi)], axis=1)
    np.testing.assert_allclose(paths.position[:, 0, :2], E, rtol=0, atol=rounding(g["d"] + g["a2"]))
    np.testing.assert_allclose(paths.velocity[:, 0, :2], -g["a2"] * np.stack([-np.sin(psi), np.cos(psi)], axis=1),
                               rtol=0, atol=rounding(g["a2"]))
