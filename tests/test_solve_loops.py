"""Closing loops and solving rates, checked against finite differences and each other.

The velocity of every joint must be the time derivative of the closed configuration as
the driver moves, and the acceleration the derivative of the velocity. Differences are
taken on the configuration manifold (`pin.difference`), central, with h = 1e-6 s:
truncation ~ h^2 |q'''| ~ 1e-12 and rounding ~ eps |q| / h ~ 1e-10, so rtol = 1e-7.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech import (
    FrameNotFound,
    LoopClosureError,
    LoopSolver,
    Mechanism,
    MobilityError,
    ModelError,
    SingularPoseError,
)
from tests._mechanisms import (
    four_bar_urdf,
    slider_crank_prismatic_cut_urdf,
    spatial_rsur_revolute_cut_urdf,
    spatial_rsur_urdf,
    write,
)
from tests.tolerance import closure, residual, rounding

H = 1e-6
RTOL = 1e-7


def _r_rtr(models_dir, tmp_path):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", np.radians(20))
    mech.set_coordinate(guess, "B_slider", -0.06)
    return mech, "A", guess


def _four_bar(models_dir, tmp_path):
    mech = Mechanism.from_urdf(write(tmp_path, "four_bar.urdf", four_bar_urdf()))
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", np.radians(60))
    mech.set_coordinate(guess, "O4", np.radians(100))
    return mech, "O2", guess


def _slider_crank(models_dir, tmp_path):
    mech = Mechanism.from_urdf(write(tmp_path, "sc.urdf", slider_crank_prismatic_cut_urdf()))
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", -0.3)
    mech.set_coordinate(guess, "B", 0.3)
    return mech, "O", guess


def _rsur(models_dir, tmp_path):
    return Mechanism.from_urdf(write(tmp_path, "rsur.urdf", spatial_rsur_urdf())), "R1", None


def _rsur_cut_at_r4(models_dir, tmp_path):
    return Mechanism.from_urdf(write(tmp_path, "rsur4.urdf", spatial_rsur_revolute_cut_urdf())), "R1", None


MECHANISMS = [_r_rtr, _four_bar, _slider_crank, _rsur, _rsur_cut_at_r4]


@pytest.mark.parametrize("build", MECHANISMS, ids=lambda f: f.__name__.strip("_"))
def test_rates_are_time_derivatives_of_the_closed_pose(build, models_dir, tmp_path):
    mech, driver, guess = build(models_dir, tmp_path)
    solver = LoopSolver(mech, [driver])
    phi0, omega, alpha = 0.4, -2.0, 3.0

    def at(t):
        phi = phi0 + omega * t + 0.5 * alpha * t**2
        return solver.solve([phi], [omega + alpha * t], [alpha], guess=centre.q)

    centre = solver.solve([phi0], [omega], [alpha], guess=guess)
    before, after = at(-H), at(H)
    v_fd = pin.difference(mech.model, before.q, after.q) / (2 * H)
    a_fd = (after.v - before.v) / (2 * H)
    np.testing.assert_allclose(centre.v, v_fd, rtol=RTOL, atol=RTOL * np.abs(centre.v).max())
    np.testing.assert_allclose(centre.a, a_fd, rtol=RTOL, atol=RTOL * np.abs(centre.a).max())


@pytest.mark.parametrize("build", MECHANISMS, ids=lambda f: f.__name__.strip("_"))
def test_solution_vouches_for_itself(build, models_dir, tmp_path):
    mech, driver, guess = build(models_dir, tmp_path)
    solution = LoopSolver(mech, [driver]).solve([0.4], [1.0], [0.0], guess=guess)
    assert solution.is_closed(residual(1.0))
    assert solution.accuracy.velocity_residual < rounding(np.abs(solution.v).max())
    assert solution.accuracy.acceleration_residual < rounding(np.abs(solution.a).max() + np.abs(solution.v).max() ** 2)
    assert 1 <= solution.accuracy.condition < 1e3


def test_a_planar_prismatic_cut_gives_two_rows(tmp_path):
    mech = Mechanism.from_urdf(write(tmp_path, "sc.urdf", slider_crank_prismatic_cut_urdf()))
    assert mech.closures[0].rows == 2 and mech.mobility == 1


def test_slider_crank_slider_position_matches_the_triangle(tmp_path):
    """x_B = r cos(theta) + sqrt(l^2 - (e - r sin(theta))^2) for the offset slider-crank."""
    r, l, e, theta = 0.05, 0.15, 0.01, 0.7
    mech, driver, guess = _slider_crank(None, tmp_path)
    sol = LoopSolver(mech, [driver]).solve([theta], guess=guess)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, sol.q)
    block = data.oMf[mech.links["block"]].translation
    np.testing.assert_allclose(block[:2], [r * np.cos(theta) + np.sqrt(l**2 - (e - r * np.sin(theta)) ** 2), e],
                               rtol=0, atol=closure(r + l, sol.accuracy.condition))


def test_where_the_loop_is_cut_does_not_change_the_motion(tmp_path):
    """The RSUR cut at its spherical joint and at its rocker pivot: same crank -> same coupler."""
    sph = Mechanism.from_urdf(write(tmp_path, "a.urdf", spatial_rsur_urdf()))
    rev = Mechanism.from_urdf(write(tmp_path, "b.urdf", spatial_rsur_revolute_cut_urdf()))
    a = LoopSolver(sph, ["R1"]).solve([0.3], [1.0], [0.5])
    guess = rev.neutral()  # on a's branch: the neutral pose is singular, its branch a matter of rounding
    for name in ("U1", "U2"):
        rev.set_coordinate(guess, name, sph.coordinate(a.q, name))
    b = LoopSolver(rev, ["R1"]).solve([0.3], [1.0], [0.5], guess=guess)
    for name in ("U1", "U2"):
        j_a, j_b = sph.joint(name), rev.joint(name)
        np.testing.assert_allclose(
            [a.q[j_a.idx_q], a.v[j_a.idx_v], a.a[j_a.idx_v]],
            [b.q[j_b.idx_q], b.v[j_b.idx_v], b.a[j_b.idx_v]],
            rtol=0, atol=closure(1.0, max(a.accuracy.condition, b.accuracy.condition), 2),
        )


def test_solver_reuses_its_data_across_poses(models_dir, tmp_path):
    mech, driver, guess = _r_rtr(models_dir, tmp_path)
    solver = LoopSolver(mech, [driver])
    data = solver.data
    first = solver.solve([0.1], [1.0], [0.0], guess=guess)
    solver.solve([0.2], [1.0], [0.0], guess=first.q)
    assert solver.data is data


# ---------------------------------------------------------------------- errors
def test_too_few_drivers_is_a_mobility_error(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    with pytest.raises(MobilityError, match=r"mobility 1; 0 driver") as info:
        LoopSolver(mech, [])
    assert (info.value.mobility, info.value.drivers) == (1, 0)


def test_too_many_drivers_is_a_mobility_error(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    with pytest.raises(MobilityError, match=r"2 driver\(s\) given \(A, B\)"):
        LoopSolver(mech, ["A", "B"])


def test_a_driver_that_is_not_a_joint(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    with pytest.raises(FrameNotFound, match=r"unknown joint 'crank' \(the model has: A, B, B_slider\)"):
        LoopSolver(mech, ["crank"])


def test_a_four_bar_whose_links_cannot_reach_does_not_close(tmp_path):
    """Crank 0.2 m, coupler and rocker 0.05 m, ground 0.1 m: at 90 deg the coupler end
    is 0.22 m from the rocker pivot, beyond the 0.1 m the two links span."""
    mech = Mechanism.from_urdf(write(tmp_path, "bad.urdf", four_bar_urdf(a=0.2, b=0.05, c=0.05, d=0.1)))
    with pytest.raises(LoopClosureError, match=r"loop\(s\) B cannot be closed at O2 = 90 deg") as info:
        LoopSolver(mech, ["O2"]).solve([np.pi / 2])
    assert info.value.residual > 0.1
    assert info.value.partial.shape == (mech.model.nq,)


def test_guide_through_its_own_pivot_is_singular(models_dir, tmp_path):
    """R-RTR with AB = AC at phi = 0: B sits on C and the guide direction is undefined."""
    text = (models_dir / "r_rtr.urdf").read_text().replace('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="0.10 0 0"')
    mech = Mechanism.from_urdf(write(tmp_path, "r_rtr_ab_ac.urdf", text))
    guess = mech.neutral()
    mech.set_coordinate(guess, "B_slider", -0.01)
    with pytest.raises(SingularPoseError, match="condition number") as info:
        LoopSolver(mech, ["A"]).solve([0.0], [1.0], [0.0], guess=guess)
    assert info.value.condition > 1e10


def test_driver_values_must_be_finite(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    with pytest.raises(MobilityError, match="finite"):
        LoopSolver(mech, ["A"]).solve([float("nan")])


def test_guess_of_the_wrong_size(models_dir):
    mech = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    with pytest.raises(ModelError, match="guess must be 5 finite numbers"):
        LoopSolver(mech, ["A"]).solve([0.3], guess=np.zeros(3))
