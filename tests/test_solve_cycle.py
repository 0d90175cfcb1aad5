"""A driver range solved with each accuracy choice, against the R-RTR's closed form.

Errors are relative: the largest |pinmech - closed form| over the cycle divided by the
largest |closed form| over it, for D's position, velocity and acceleration.
"""

from __future__ import annotations

import itertools

import closed_form
import numpy as np
import pinocchio as pin
import pytest

from pinmech import PinmechError, Scene
from pinmech.solve.batch import BatchSolver
from pinmech.solve.cycle import CHUNK
from pinmech.io.sweep import Sweep
from tests.tolerance import STATED_SWEEP, rounding

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@pytest.fixture
def sweep(r_rtr_scene):
    return Sweep.from_scene(Scene.load(r_rtr_scene))


def _cycle(sweep, poses, **options):
    phis = sweep.start + np.linspace(0, 2 * np.pi, poses, endpoint=False)
    chunks = list(sweep.chunks(phis, **options))
    fields = ("q", "v", "a", "residual", "condition", "velocity_residual", "acceleration_residual")
    arrays = {k: np.concatenate([getattr(c.solution, k) for c in chunks]) for k in fields}
    arrays["interpolated"] = np.concatenate([c.interpolated for c in chunks])
    return phis, arrays


def _errors(sweep, phis, arrays):
    """Relative errors of D's position, velocity, acceleration against the closed form."""
    model, data = sweep.mechanism.model, sweep.mechanism.model.createData()
    fid = sweep.mechanism.frame_id("D")
    ours = np.empty((3, len(phis), 2))
    for i, (q, v, a) in enumerate(zip(arrays["q"], arrays["v"], arrays["a"])):
        pin.forwardKinematics(model, data, q, v, a)
        ours[0, i] = pin.updateFramePlacement(model, data, fid).translation[:2]
        ours[1, i] = pin.getFrameVelocity(model, data, fid, LWA).linear[:2]
        ours[2, i] = pin.getFrameClassicalAcceleration(model, data, fid, LWA).linear[:2]
    cf = closed_form.r_rtr(phis, sweep.drivers.v[0], sweep.drivers.a[0])
    return [float(np.abs(o - c).max() / np.abs(c).max()) for o, c in zip(ours, (cf.D, cf.vD, cf.aD))]


@pytest.mark.parametrize("poses", [37, 361, 3600])
def test_every_pose_is_exact_whatever_the_spacing(sweep, poses):
    """10 deg steps: pose by pose; 1 deg: every 4th pose, the rest batched; 0.1 deg: every
    64th, then 16th, 4th, the rest batched. All of them meet the README's 1e-12."""
    phis, arrays = _cycle(sweep, poses)
    assert max(_errors(sweep, phis, arrays)) < STATED_SWEEP
    assert np.all(arrays["residual"] <= sweep.solver.tol)
    assert not arrays["interpolated"].any()


def test_a_loose_tolerance_is_good_to_about_itself(sweep):
    sweep.solver.tol = 1e-6
    phis, arrays = _cycle(sweep, 3600)
    errors = _errors(sweep, phis, arrays)
    assert max(errors) < 1e-5 and np.all(arrays["residual"] <= 1e-6)


@pytest.mark.parametrize("every, bounds", [(8, (1e-12, 1e-10, 1e-7)), (32, (1e-8, 1e-6, 1e-4))])
def test_interpolation_stays_within_its_stated_errors(sweep, every, bounds):
    """Quintic Hermite between exact poses h apart: errors ~ h^6, h^5, h^4 in position,
    velocity, acceleration; the bounds are the README's figures with a margin of ~30."""
    phis, arrays = _cycle(sweep, 3600, interpolate=every)
    errors = _errors(sweep, phis, arrays)
    assert all(e < b for e, b in zip(errors, bounds)), errors
    solved = 3600 - arrays["interpolated"].sum()
    assert abs(solved - 3600 / every) <= 2  # every n-th pose, and the ends


def test_interpolated_poses_report_the_worst_accuracy_of_their_interval(sweep):
    """Each interpolated pose carries the residuals measured where the interpolation error
    peaks in its interval; measured at the pose itself they are no larger (to 50 %,
    the two velocity peaks being equal only to leading order)."""
    _, arrays = _cycle(sweep, 720, interpolate=16)
    at_pose = BatchSolver(sweep.solver).measure(arrays["q"], arrays["v"] / sweep.drivers.v[0],
                                                arrays["a"] / sweep.drivers.v[0] ** 2)
    inner = arrays["interpolated"]
    assert inner.sum() > 600
    np.testing.assert_array_less(at_pose.residual[inner], 1.5 * arrays["residual"][inner] + 1e-16)
    w = abs(sweep.drivers.v[0])
    np.testing.assert_array_less(w * at_pose.velocity_residual[inner],
                                 1.5 * arrays["velocity_residual"][inner] + 1e-16)
    np.testing.assert_array_less(w * w * at_pose.acceleration_residual[inner],
                                 1.5 * arrays["acceleration_residual"][inner] + 1e-15)
    assert np.all(arrays["residual"][inner] > 0)  # measured, not assumed


def test_a_long_range_is_read_one_chunk_at_a_time(sweep):
    """Three poses of a million: the sweep has read at most one chunk of the values."""
    read = itertools.count()

    def values():
        for i in range(1_000_000):
            next(read)
            yield sweep.start + 1e-3 * i

    taken = list(itertools.islice(sweep.poses(values()), 3))
    assert [p.index for p in taken] == [0, 1, 2]
    assert next(read) <= CHUNK + 1


def test_a_failure_in_a_dense_batched_sweep_is_named_by_its_angle(tmp_path, models_dir):
    """0.1 deg steps through the singular pose of an R-RTR with AB = AC: the batch hands
    the chunk back, and the pose-by-pose solver names phi = 0 (and only it)."""
    from tests.test_sweep import _singular_scene

    sweep = Sweep.from_scene(_singular_scene(tmp_path, models_dir))
    values = np.radians(np.linspace(-20.0, 20.0, 401))
    poses = list(sweep.poses(values, skip_failures=True))
    failed = [p.value for p in poses if p.motion is None]
    np.testing.assert_allclose(failed, [0.0], atol=rounding(np.radians(20.0)))


def test_options_that_cannot_hold_are_errors(sweep):
    values = sweep.default_values(10)
    with pytest.raises(PinmechError, match="start must be one of"):
        list(sweep.chunks(values, start="lukewarm"))
    with pytest.raises(PinmechError, match="at least 1"):
        list(sweep.chunks(values, interpolate=0))
    with pytest.raises(PinmechError, match="predictor start"):
        list(sweep.chunks(values, start="cold", interpolate=4))


def test_a_sweeps_first_row_at_the_scenes_pose_states_that_poses_own_accuracy(scenes_dir):
    """The first row, at the scene's pose, came from the compiled core with placeholder
    numbers (residual 0, sigma_min 1): with tol = 1e-3 its stated position bound was 2e-15
    where the pose is 2e-5 rad off. Now its residual, condition and sigma_min are those
    of the pose, as `analyse` gives them (the same arithmetic: equal to 1e-12)."""
    import pinmech

    scene = pinmech.Scene.load(scenes_dir / "four_bar.toml", ["solver.tol=1e-3"])
    sweep = pinmech.Sweep.from_scene(scene)
    first = next(iter(sweep.chunks([sweep.start, sweep.start + 0.5])))
    accuracy = first.solution.solution(0).accuracy
    alone = pinmech.analyse(scene).solution.accuracy
    assert accuracy.residual == pytest.approx(alone.residual, rel=rounding(1.0)) and accuracy.residual > 1e-7
    assert accuracy.sigma_min == pytest.approx(alone.sigma_min, rel=rounding(1.0, alone.condition))
    assert accuracy.condition == pytest.approx(alone.condition, rel=rounding(1.0, alone.condition))
