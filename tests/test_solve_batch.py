"""Many poses at once: the batch gives the pose-by-pose solver's answers, hands back what
it cannot take (a far guess, a singular pose), and the manifold helpers match Pinocchio
row by row."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech import LoopSolver
from pinmech.solve.batch import BatchSolver
from pinmech.solve.manifold import difference_many, integrate_many
from tests.test_solve_loops import MECHANISMS
from tests.tolerance import closure, residual, rounding


def _chain(solver, driver_values, guess):
    """Pose by pose along the driver values, each from the previous (the reference)."""
    out = []
    for x in driver_values:
        guess = solver.solve([x], [1.5], [-0.5], guess=guess).q
        out.append(solver.solve([x], [1.5], [-0.5], guess=guess))
    return out


@pytest.mark.parametrize("build", MECHANISMS, ids=lambda f: f.__name__.strip("_"))
def test_a_batch_gives_the_pose_by_pose_answers(build, models_dir, tmp_path):
    """From guesses 1e-7 off, every pose closes to the tolerance; q, v, a and the condition
    number agree with LoopSolver.solve to rounding (both are converged to ~1e-15)."""
    mech, driver, guess = build(models_dir, tmp_path)
    solver = LoopSolver(mech, [driver])
    xs = np.linspace(0.3, 0.9, 25)
    exact = _chain(solver, xs, guess)
    rng = np.random.default_rng(7)
    guesses = np.array([pin.integrate(mech.model, s.q, 1e-7 * rng.normal(size=mech.model.nv)) for s in exact])
    n = len(xs)
    out = BatchSolver(solver).try_solve(guesses, xs[:, None], np.full((n, 1), 1.5), np.full((n, 1), -0.5))
    assert out is not None and len(out) == n
    dq = np.array([pin.difference(mech.model, s.q, q) for s, q in zip(exact, out.q)])
    np.testing.assert_allclose(dq, 0, atol=closure(np.pi, max(s.accuracy.condition for s in exact)))
    for name in ("v", "a"):
        ref = np.array([getattr(s, name) for s in exact])
        np.testing.assert_allclose(getattr(out, name), ref, rtol=0, atol=1e-11 * np.abs(ref).max())
    np.testing.assert_allclose(out.condition, [s.accuracy.condition for s in exact], rtol=1e-9)
    assert np.all(out.residual <= solver.tol) and np.all(out.iterations >= 1)
    assert out.solution(3).accuracy == out.accuracy(3) and out.solution(3).is_closed(residual(1.0))


def test_a_guess_far_from_its_pose_is_handed_back(models_dir, tmp_path):
    """A Newton step over MAX_BATCH_STEP means the guess was not close: None, not a jump
    to another branch."""
    mech, driver, guess = MECHANISMS[0](models_dir, tmp_path)
    solver = LoopSolver(mech, [driver])
    exact = _chain(solver, [0.5], guess)[0]
    far = pin.integrate(mech.model, exact.q, np.array([0.0, 0.05, 0.01]))
    ones = np.ones((1, 1))
    assert BatchSolver(solver).try_solve(far[None], 0.5 * ones, ones, 0 * ones) is None


def test_a_singular_pose_is_handed_back(tmp_path, models_dir):
    """R-RTR with AB = AC: at phi = 0 the block sits on the pivot C (the guide's direction
    is undefined); the pose-by-pose solver then names it."""
    from pinmech import Mechanism

    text = (models_dir / "r_rtr.urdf").read_text().replace('<parent_origin xyz="0.05 0 0"',
                                                            '<parent_origin xyz="0.10 0 0"')
    path = tmp_path / "ab_ac.urdf"
    path.write_text(text)
    mech = Mechanism.from_urdf(path)
    solver = LoopSolver(mech, ["A"])
    q = mech.neutral()
    mech.set_coordinate(q, "B", np.radians(-90))  # the closed pose at phi = 0
    ones = np.ones((1, 1))
    assert BatchSolver(solver).try_solve(q[None], 0 * ones, ones, 0 * ones) is None


@pytest.mark.parametrize("which", ["r_rtr", "humanoid"])
def test_manifold_helpers_match_pinocchio_row_by_row(which, models_dir):
    """One-dof joints on arrays (continuous as cos/sin, prismatic), anything else through
    Pinocchio: the sample humanoid has a free-flyer root and spherical-free joints."""
    from pinmech import Mechanism

    model = Mechanism.from_urdf(models_dir / "r_rtr.urdf").model if which == "r_rtr" else \
        pin.buildSampleModelHumanoid()
    rng = np.random.default_rng(3)
    q0 = np.array([pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv)) for _ in range(20)])
    dq = rng.normal(size=(20, model.nv))
    q1 = integrate_many(model, q0, dq)
    np.testing.assert_allclose(q1, [pin.integrate(model, a, b) for a, b in zip(q0, dq)], atol=rounding(np.abs(q0).max() + np.abs(dq).max()))
    np.testing.assert_allclose(difference_many(model, q0, q1), [pin.difference(model, a, b) for a, b in zip(q0, q1)],
                               atol=rounding(np.abs(q0).max() + np.abs(q1).max()))
