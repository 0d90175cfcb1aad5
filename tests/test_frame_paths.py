"""Points and links along a sweep, as arrays (sweep_frames.py), against `evaluate_motion`
at every pose: the same Pinocchio quantities read pose by pose, so they agree to rounding
(1e-13 of each quantity's size), with the compiled core and without it."""

from __future__ import annotations

import numpy as np
import pytest

import pinmech
from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.solve.sweep_frames import frame_paths
from tests.tolerance import rounding


@pytest.fixture
def r_rtr_rows(scenes_dir):
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scenes_dir / "r_rtr.toml"))
    chunk = next(sweep.chunks(np.radians(np.arange(0.0, 360.0, 7.0))))
    return sweep.mechanism, chunk.solution


def test_frames_equal_evaluate_motion(r_rtr_rows):
    mechanism, s = r_rtr_rows
    paths = frame_paths(mechanism, ["D", "B", "link3"], s.q, s.v, s.a)
    assert paths.position.shape == (len(s.q), 3, 3) and paths.rotation.shape == (len(s.q), 3, 3, 3)
    data = mechanism.model.createData()
    d, link3 = paths.index("D"), paths.index("link3")
    for i, (q, v, a) in enumerate(zip(s.q, s.v, s.a)):
        m = pinmech.evaluate_motion(mechanism, data, q, v, a, points=["D", "B"], links=["link3"])
        for name in ("D", "B"):
            k = paths.index(name)
            np.testing.assert_allclose(paths.position[i, k], m.points[name].position, rtol=0, atol=rounding(0.3))
            np.testing.assert_allclose(paths.velocity[i, k], m.points[name].velocity, rtol=0, atol=rounding(np.abs(m.points[name].velocity).max()))
            np.testing.assert_allclose(paths.acceleration[i, k], m.points[name].acceleration, rtol=0, atol=rounding(np.abs(m.points[name].acceleration).max()))
        link = m.links["link3"]
        np.testing.assert_allclose(paths.rotation[i, link3], link.rotation, rtol=0, atol=rounding(1.0))
        np.testing.assert_allclose(paths.angular_velocity[i, link3], link.angular_velocity, rtol=0, atol=rounding(np.abs(link.angular_velocity).max()))
        np.testing.assert_allclose(paths.angular_acceleration[i, link3], link.angular_acceleration, rtol=0,
                                   atol=rounding(np.abs(link.angular_acceleration).max()))
        assert d == 0


def test_bad_names_and_shapes_are_named_errors(r_rtr_rows):
    mechanism, s = r_rtr_rows
    with pytest.raises(FrameNotFound):
        frame_paths(mechanism, ["no_such_point"], s.q, s.v, s.a)
    with pytest.raises(ModelError, match="list of names"):
        frame_paths(mechanism, "D", s.q, s.v, s.a)
    with pytest.raises(ModelError, match="arrays"):
        frame_paths(mechanism, ["D"], s.q[:, :2], s.v, s.a)


def test_threads_sharing_a_mechanism_get_their_own_answers(scenes_dir):
    """Two threads reading frames of one mechanism at once (one compiled model, its work
    buffers shared): each gets what it gets alone."""
    import threading

    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scenes_dir / "r_rtr.toml"))
    chunk = next(sweep.chunks(np.radians(np.arange(0.0, 360.0, 1.0))))
    s = chunk.solution
    alone = [frame_paths(sweep.mechanism, ["D"], s.q[i::2], s.v[i::2], s.a[i::2]).acceleration for i in (0, 1)]
    got = [[], []]

    def work(i):
        for _ in range(50):
            got[i].append(frame_paths(sweep.mechanism, ["D"], s.q[i::2], s.v[i::2], s.a[i::2]).acceleration)

    threads = [threading.Thread(target=work, args=(i,)) for i in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for i in (0, 1):
        for out in got[i]:
            np.testing.assert_array_equal(out, alone[i])
