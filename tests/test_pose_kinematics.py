"""One pose's kinematics from the compiled core (csrc/kinematics.cpp) through
`evaluate_motion` and `frame_paths`, against the R-RTR's closed form (scripts/closed_form.py,
derived from the loop B - C = s u by hand, not from Pinocchio): link 3's rates, D's
velocity and acceleration, the block's relative motion and Coriolis term 2 w3 x v_rel, and
the velocity of B3, the point of link 3 under the block (w3 x CB).

Tolerances: pinmech's own bound on each pose (tests/tolerance.py `stated`: its residual and
condition number, times the size of each quantity over the turn), plus the closed form's
rounding; the rates reach 37 rad/s^2 and 3.5 m/s^2 here."""

from __future__ import annotations

import math

import numpy as np
import pytest

import closed_form
import pinmech
from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.solve.motion import CoincidentPoint
from pinmech.solve.sweep_frames import frame_paths
from tests.tolerance import stated

OMEGA1 = -50.0 * math.pi / 30.0  # the scene's crank speed [rad/s]
ANGLES = np.radians([0.0, 30.0, 97.0, 200.0, 301.0])


@pytest.fixture(scope="module")
def r_rtr():
    from tests.conftest import SCENES

    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(SCENES / "r_rtr.toml"))
    solution = next(iter(sweep.chunks(ANGLES))).solution
    return sweep.mechanism, solution, closed_form.r_rtr(ANGLES, OMEGA1, 0.0)


def _bar(s, ref, i, name: str, order: int) -> float:
    """pinmech's stated bound on pose i (all poses for i = None) for the quantity `name` of the
    closed form, of the order (0 position, 1 rate, 2 acceleration) it is."""
    pick = slice(None) if i is None else i
    return stated(s.residual[pick], s.condition[pick], np.abs(getattr(ref, name)).max(), order)


def test_link3_d_and_the_block_meet_the_closed_form(r_rtr):
    mechanism, s, ref = r_rtr
    data = mechanism.model.createData()
    for i in range(len(ANGLES)):
        m = pinmech.evaluate_motion(mechanism, data, s.q[i], s.v[i], s.a[i], points=["D"], links=["link3"],
                                    coincident=[CoincidentPoint("B3", "B", "link3")])
        link3, d, block = m.links["link3"], m.points["D"], m.sliders["B_slider"]
        assert link3.angle == pytest.approx(ref.phi3[i], abs=_bar(s, ref, i, 'phi3', 0))
        assert link3.angular_velocity[2] == pytest.approx(ref.omega3[i], abs=_bar(s, ref, i, 'omega3', 1))
        assert link3.angular_acceleration[2] == pytest.approx(ref.alpha3[i], abs=_bar(s, ref, i, 'alpha3', 2))
        np.testing.assert_allclose(d.position[:2], ref.D[i], rtol=0, atol=_bar(s, ref, i, 'D', 0))
        np.testing.assert_allclose(d.velocity[:2], ref.vD[i], rtol=0, atol=_bar(s, ref, i, 'vD', 1))
        np.testing.assert_allclose(d.acceleration[:2], ref.aD[i], rtol=0, atol=_bar(s, ref, i, 'aD', 2))
        # the block slides along link 3: its coordinate is -s (it points from B towards C)
        assert block.s_dot == pytest.approx(-ref.s_dot[i], abs=_bar(s, ref, i, 's_dot', 1))
        np.testing.assert_allclose(block.relative_velocity[:2], ref.v_rel[i], rtol=0, atol=_bar(s, ref, i, 'v_rel', 1))
        np.testing.assert_allclose(block.coriolis_acceleration[:2], ref.coriolis[i], rtol=0, atol=_bar(s, ref, i, 'coriolis', 2))
        np.testing.assert_allclose(m.points["B3"].velocity[:2], ref.vB3[i], rtol=0, atol=_bar(s, ref, i, 'vB3', 1))
        np.testing.assert_allclose(m.points["B3"].acceleration[:2], ref.aB3[i], rtol=0, atol=_bar(s, ref, i, 'aB3', 2))


def test_a_motion_keeps_its_pose_when_the_data_moves_on(r_rtr):
    """The Motion's dicts are built when first read: from the numbers of its own pose, not
    from the Data (or q) the caller reuses for the next one."""
    mechanism, s, ref = r_rtr
    data = mechanism.model.createData()
    q = s.q[1].copy()
    first = pinmech.evaluate_motion(mechanism, data, q, s.v[1], s.a[1], points=["D"], links=["link3"])
    q[:] = s.q[3]
    pinmech.evaluate_motion(mechanism, data, q, s.v[3], s.a[3], points=["D"], links=["link3"])
    assert first.links["link3"].angular_velocity[2] == pytest.approx(ref.omega3[1], abs=_bar(s, ref, 1, 'omega3', 1))
    np.testing.assert_allclose(first.points["D"].velocity[:2], ref.vD[1], rtol=0, atol=_bar(s, ref, 1, 'vD', 1))
    assert first.joints["B_slider"].q == pytest.approx(-ref.s[1], abs=_bar(s, ref, 1, 's', 0))


def test_frame_paths_meet_the_closed_form_at_every_pose(r_rtr):
    mechanism, s, ref = r_rtr
    paths = frame_paths(mechanism, ["link3", "D"], s.q, s.v, s.a)
    np.testing.assert_allclose(paths.angular_velocity[:, 0, 2], ref.omega3, rtol=0, atol=_bar(s, ref, None, 'omega3', 1))
    np.testing.assert_allclose(paths.angular_acceleration[:, 0, 2], ref.alpha3, rtol=0, atol=_bar(s, ref, None, 'alpha3', 2))
    np.testing.assert_allclose(paths.velocity[:, 1, :2], ref.vD, rtol=0, atol=_bar(s, ref, None, 'vD', 1))
    np.testing.assert_allclose(paths.acceleration[:, 1, :2], ref.aD, rtol=0, atol=_bar(s, ref, None, 'aD', 2))


def test_a_data_of_another_model_or_no_data_is_a_model_error(r_rtr, models_dir):
    mechanism, s, _ = r_rtr
    other = pinmech.Mechanism.from_urdf(models_dir / "planar_arm.urdf").model.createData()
    for data in (other, "data", None):
        with pytest.raises(ModelError, match=r"data must be a pin.Data of the mechanism's model"):
            pinmech.evaluate_motion(mechanism, data, s.q[0], s.v[0], s.a[0])


def test_unknown_names_are_named_before_anything_is_computed(r_rtr):
    mechanism, s, _ = r_rtr
    data = mechanism.model.createData()
    with pytest.raises(FrameNotFound, match="nowhere"):
        pinmech.evaluate_motion(mechanism, data, s.q[0], s.v[0], s.a[0], points=["nowhere"])
    with pytest.raises(FrameNotFound, match="link9"):
        pinmech.evaluate_motion(mechanism, data, s.q[0], s.v[0], s.a[0], links=["link9"])
