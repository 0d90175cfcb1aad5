"""Forces on closed loops (pinmech/solve/forces.py) against checks that cannot agree by accident.

- Newton-Euler by hand (scripts/closed_form_forces.py): each link's F = m a_G and
  M_G = I alpha with the kinematics of the vector-loop closed forms, no Pinocchio.
- Virtual power: sum tau q_dot + P_gravity + P_loads = dT/dt at every pose.
- Finite differences of the energies along the motion (kinetic from the mass matrix,
  potential from positions), and statics against virtual work from finite differences of
  the closed positions.
- Scale: lengths times s (micrometres to kilometres), inertias s^2, gravity and loads s:
  torques scale as s^2, forces as s.
"""

from __future__ import annotations

from pathlib import Path

import closed_form_forces as cff
import numpy as np
import pinocchio as pin
import pytest

import pinmech
from pinmech.exceptions import IndeterminateForcesError, ModelError
from pinmech.solve.forces import ForceSolver, Load
from tests.tolerance import closure, rounding

MODELS = Path(__file__).resolve().parents[1] / "models"
G = 9.81
# Forces agree with the hand analysis to rounding: the loop closes to 1e-13 of the size
# (the solver's default tolerance), the force system's condition number is below 1e2 at
# these poses, so the relative error is ~1e-11 at worst; 1e-9 of the largest force keeps a
# margin of a hundred while a wrong sign, lever arm or missing term (1e-3 or more) fails.
RTOL = 1e-9
# Positions of these poses: closed to the solver's tolerance at condition numbers below 1e2.
COND = 1e2


def slider_crank(theta: float, omega: float, alpha: float, path: Path = MODELS / "slider_crank_dynamic.urdf",
                 drivers=("O",)):
    mech = pinmech.Mechanism.from_urdf(path)
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", -theta)  # rod near horizontal: the piston right of the crank
    mech.set_coordinate(guess, "slide", (0.05 * np.cos(theta) + 0.15) * _scale_of(mech))
    sol = pinmech.LoopSolver(mech, ["O"]).solve([theta], [omega], [alpha], guess=guess)
    return mech, sol


def _scale_of(mech) -> float:
    return mech.length_scale / pinmech.Mechanism.from_urdf(MODELS / "slider_crank_dynamic.urdf").length_scale


def four_bar(theta: float, omega: float, alpha: float):
    mech = pinmech.Mechanism.from_urdf(MODELS / "four_bar_dynamic.urdf")
    guess = mech.neutral()
    branch = cff.cf.four_bar(theta, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10)  # the open assembly, as a guess only
    mech.set_coordinate(guess, "A", float(branch.theta3) - theta + 0.05)
    mech.set_coordinate(guess, "O4", float(branch.theta4) - 0.05)
    return mech, pinmech.LoopSolver(mech, ["O2"]).solve([theta], [omega], [alpha], guess=guess)


def assert_vec(actual, expected, scale, label):
    np.testing.assert_allclose(np.asarray(actual)[:2], expected, rtol=0, atol=RTOL * scale, err_msg=label)
    assert abs(np.asarray(actual)[2]) <= RTOL * scale, label


# --------------------------------------------------------------------- closed forms
@pytest.mark.parametrize(("deg", "rpm", "alpha", "gravity", "gas"), [
    (45.0, 3000.0, 0.0, G, -200.0),
    (200.0, -1500.0, 500.0, 0.0, 0.0),
    (300.0, 60.0, -30.0, G, 800.0),
    (91.0, 0.0, 0.0, G, -50.0),          # statics: gravity and a load only
])
def test_slider_crank_matches_newton_euler_by_hand(deg, rpm, alpha, gravity, gas):
    theta, omega = np.radians(deg), rpm * np.pi / 30
    mech, sol = slider_crank(theta, omega, alpha)
    load = Load("gas", mech.frame_id("B_pin"), np.array([gas, 0.0, 0.0]), np.zeros(3))
    f = ForceSolver(mech, ["O"], gravity=(0, -gravity, 0), loads=[load]).solve(sol.q, sol.v, sol.a)
    hand = cff.slider_crank_forces(theta, omega, alpha, 0.05, 0.15, 0.01, *cff.SLIDER_CRANK_BODIES,
                                   gravity=(0.0, -gravity), load_B=(gas, 0.0))
    scale = max(np.abs(np.concatenate([hand.F12, hand.F23, hand.F34])).max(), 1e-300)
    r = f.reactions
    np.testing.assert_allclose(f.effort[0], hand.T, rtol=0, atol=RTOL * scale * 0.2)  # crank 0.2 m scale
    assert_vec(r["O"].force, hand.F12, scale, "F12: ground on crank at O")
    assert_vec(r["A"].force, hand.F23, scale, "F23: crank on rod at A")
    assert_vec(r["B"].force, hand.F34, scale, "F34: rod on piston at B (the cut)")
    assert_vec(r["slide"].force, [0.0, hand.N14], scale, "F14: guide on piston, normal only")
    np.testing.assert_allclose(r["slide"].moment[2], hand.M14, rtol=0, atol=RTOL * scale * 0.2)
    assert (r["O"].by, r["O"].on, r["B"].by, r["B"].on) == ("ground", "crank", "rod", "piston")


@pytest.mark.parametrize(("deg", "rpm", "alpha", "gravity", "torque"), [
    (60.0, 120.0, 0.0, G, 0.0),
    (170.0, 600.0, 40.0, 0.0, 0.3),
    (290.0, -300.0, -10.0, G, -1.2),
])
def test_four_bar_matches_newton_euler_by_hand(deg, rpm, alpha, gravity, torque):
    theta, omega = np.radians(deg), rpm * np.pi / 30
    mech, sol = four_bar(theta, omega, alpha)
    load = Load("brake", mech.links["rocker"], np.zeros(3), np.array([0.0, 0.0, torque]))
    f = ForceSolver(mech, ["O2"], gravity=(0, -gravity, 0), loads=[load]).solve(sol.q, sol.v, sol.a)
    hand = cff.four_bar_forces(theta, omega, alpha, 0.04, 0.12, 0.08, 0.10, *cff.FOUR_BAR_BODIES,
                               gravity=(0.0, -gravity), rocker_torque=torque)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, sol.q)
    b_hand = cff.cf.four_bar(theta, omega, alpha, 0.04, 0.12, 0.08, 0.10).B
    np.testing.assert_allclose(data.oMf[mech.frame_id("B_pin")].translation[:2], b_hand, atol=closure(0.16, COND))  # same branch
    scale = np.abs(np.concatenate([hand.F12, hand.F23, hand.F34, hand.F14])).max()
    r = f.reactions
    np.testing.assert_allclose(f.effort[0], hand.T, rtol=0, atol=RTOL * scale * 0.1)
    assert_vec(r["O2"].force, hand.F12, scale, "F12: ground on crank")
    assert_vec(r["A"].force, hand.F23, scale, "F23: crank on coupler")
    assert_vec(r["B"].force, hand.F34, scale, "F34: coupler on rocker (the cut)")
    assert_vec(r["O4"].force, hand.F14, scale, "F14: ground on rocker")


def test_joint_moments_about_axes_are_the_drivers_and_zero_on_free_pins():
    mech, sol = slider_crank(np.radians(130), 200.0, 10.0)
    f = ForceSolver(mech, ["O"], gravity=(0, -G, 0)).solve(sol.q, sol.v, sol.a)
    r = f.reactions
    scale = abs(f.effort[0])
    assert r["O"].axial_moment == pytest.approx(f.effort[0], rel=rounding(1.0, f.condition))
    assert abs(r["A"].axial_moment) < rounding(scale, f.condition)
    assert abs(r["slide"].axial_force) < rounding(r["slide"].magnitude, f.condition)  # no driving force on the piston
    np.testing.assert_allclose(r["slide"].normal_force, r["slide"].force, atol=rounding(r["slide"].magnitude, f.condition))


# --------------------------------------------------------------------- identities
def _random_loads(mech, rng, names):
    return [Load(n, mech.frame_id(n), rng.normal(size=3) * [50, 50, 0], rng.normal(size=3) * [0, 0, 2])
            for n in names]


@pytest.mark.parametrize("which", ["slider_crank", "four_bar", "r_rtr"])
def test_virtual_power_holds_at_random_poses(which):
    """sum tau q_dot + P_g + P_loads = dT/dt; the power terms are body-by-body Newton-Euler,
    so this fails if tau, a Jacobian, a load's frame or gravity's sign were wrong. Rounding
    only: 1e-12 of the largest power term."""
    rng = np.random.default_rng(7)
    for _ in range(5):
        theta, omega, alpha = rng.uniform(0, 2 * np.pi), rng.normal() * 100, rng.normal() * 100
        if which == "slider_crank":
            mech, sol = slider_crank(theta, omega, alpha)
            drivers, names = ["O"], ["A_pin", "B_pin"]
        elif which == "four_bar":
            mech, sol = four_bar(theta, omega, alpha)
            drivers, names = ["O2"], ["P", "B_pin"]
        else:
            scene = pinmech.Scene.load(MODELS / "scenes" / "r_rtr.toml",
                                       [f'drivers.A.angle="{np.degrees(theta) / 4 + 10} deg"',
                                        f'drivers.A.speed="{omega} rad/s"', f'drivers.A.acceleration="{alpha} rad/s^2"'])
            analysis = pinmech.analyse(scene)
            mech, sol, drivers, names = analysis.mechanism, analysis.solution, ["A"], ["D", "B"]
        f = ForceSolver(mech, drivers, gravity=rng.normal(size=3) * G,
                        loads=_random_loads(mech, rng, names)).solve(sol.q, sol.v, sol.a)
        assert f.power.velocity == "actual"
        assert f.power.residual < rounding(1.0, f.condition), f.power
        assert f.equation_residual < rounding(1.0, f.condition)
        assert f.is_balanced(rounding(1.0, f.condition))


def test_a_spatial_loop_balances_its_power(tmp_path):
    """The spatial RSUR (spherical cut, 3 rows; a universal joint in the tree), gravity and a
    load in 3-D: virtual power to rounding, and the spherical cut carries no moment."""
    from tests._mechanisms import spatial_rsur_urdf

    path = tmp_path / "rsur.urdf"
    path.write_text(spatial_rsur_urdf())
    mech = pinmech.Mechanism.from_urdf(path)
    rng = np.random.default_rng(3)
    for theta in (0.0, 1.0, 2.0):
        sol = pinmech.LoopSolver(mech, ["R1"]).solve([theta], [2.0], [1.0], guess=mech.neutral())
        load = Load("F", mech.links["coupler"], rng.normal(size=3) * 10, rng.normal(size=3))
        f = ForceSolver(mech, ["R1"], gravity=(0.3, -1.0, -G), loads=[load]).solve(sol.q, sol.v, sol.a)
        assert f.power.residual < rounding(1.0, f.condition) and f.equation_residual < rounding(1.0, f.condition)
        np.testing.assert_array_equal(f.reactions["S"].moment, np.zeros(3))
        assert f.reactions["S"].magnitude > 0


def test_a_driven_slider_gives_the_force_of_equal_power():
    """Same pose and motion driven at the piston instead of the crank: one driver either
    way, so its power is the same, F v_piston = tau omega (1e-10 relative: rounding and the
    closure tolerance)."""
    mech, sol = slider_crank(np.radians(70), 200.0, 30.0)
    by_crank = ForceSolver(mech, ["O"], gravity=(0, -G, 0)).solve(sol.q, sol.v, sol.a)
    by_piston = ForceSolver(mech, ["slide"], gravity=(0, -G, 0)).solve(sol.q, sol.v, sol.a)
    v_piston = sol.v[mech.joint("slide").idx_v]
    assert by_piston.effort[0] * v_piston == pytest.approx(by_crank.effort[0] * 200.0, rel=1e-10)
    assert by_piston.reactions["slide"].axial_force == pytest.approx(by_piston.effort[0], rel=rounding(1.0, by_piston.condition))
    assert abs(by_piston.reactions["O"].axial_moment) < rounding(abs(by_crank.effort[0]), by_piston.condition)
    assert by_piston.power.residual < rounding(1.0, by_piston.condition)


def test_driver_power_is_the_rate_of_mechanical_energy_by_finite_differences():
    """At constant crank speed, tau omega = d/dt (T + V_gravity + V_load), with T = v^T M v / 2
    (CRBA) and the potentials from positions, all differenced over +-h of crank angle.
    h = 1e-4 rad: truncation h^2/6 E''' ~ 2e-9 of the largest power, rounding
    eps E / h ~ 1e-12; tolerance 1e-7 of the largest term."""
    omega, h, gas = 300.0, 1e-4, np.array([-200.0, 0.0, 0.0])
    g = np.array([0.0, -G, 0.0])

    def energy(theta):
        mech, sol = slider_crank(theta, omega, 0.0)
        model, data = mech.model, mech.model.createData()
        M = pin.crba(model, data, sol.q)
        pin.framesForwardKinematics(model, data, sol.q)
        T = 0.5 * sol.v @ M @ sol.v
        V = -sum(model.inertias[i].mass * g @ (data.oMi[i].act(model.inertias[i].lever)) for i in range(1, model.njoints))
        V -= gas @ data.oMf[mech.frame_id("B_pin")].translation
        return T + V

    for theta in np.radians([20.0, 100.0, 250.0]):
        mech, sol = slider_crank(theta, omega, 0.0)
        load = Load("gas", mech.frame_id("B_pin"), gas, np.zeros(3))
        f = ForceSolver(mech, ["O"], gravity=g, loads=[load]).solve(sol.q, sol.v, sol.a)
        rate = (energy(theta + h) - energy(theta - h)) / (2 * h) * omega
        scale = max(abs(f.power.kinetic_rate), abs(f.power.load_power), abs(f.effort[0] * omega))
        np.testing.assert_allclose(f.effort[0] * omega, rate, rtol=0, atol=1e-7 * scale)


@pytest.mark.parametrize("which", ["slider_crank", "four_bar"])
def test_statics_is_virtual_work_by_finite_differences(which):
    """At rest, tau dtheta + sum F . dp + sum m g . dc = 0 for the closed positions at theta +- h.
    h = 1e-5 rad: truncation ~ h^2 = 1e-10 relative; tolerance 1e-7 of the largest work term."""
    rng = np.random.default_rng(11)
    h = 1e-5
    for theta in rng.uniform(0, 2 * np.pi, 4):
        build, driver, point = (slider_crank, "O", "B_pin") if which == "slider_crank" else (four_bar, "O2", "P")
        mech, sol = build(theta, 0.0, 0.0)
        force, g = rng.normal(size=3) * [100, 100, 0], np.array([0.0, -G, 0.0])
        load = Load("F", mech.frame_id(point), force, np.zeros(3))
        f = ForceSolver(mech, [driver], gravity=g, loads=[load]).solve(sol.q, sol.v, sol.a)
        assert f.power.velocity == "virtual" and f.power.residual < rounding(1.0, f.condition)

        def positions(t, build=build, mech=mech, point=point):
            _, s = build(t, 0.0, 0.0)
            data = mech.model.createData()
            pin.framesForwardKinematics(mech.model, data, s.q)
            coms = [data.oMi[i].act(mech.model.inertias[i].lever) for i in range(1, mech.model.njoints)]
            return data.oMf[mech.frame_id(point)].translation.copy(), coms

        (p_hi, c_hi), (p_lo, c_lo) = positions(theta + h), positions(theta - h)
        work_load = force @ (p_hi - p_lo)
        work_g = sum(mech.model.inertias[i + 1].mass * g @ (c_hi[i] - c_lo[i]) for i in range(len(c_hi)))
        work_drv = f.effort[0] * 2 * h
        scale = max(abs(work_load), abs(work_g), abs(work_drv))
        assert abs(work_drv + work_load + work_g) < 1e-7 * scale


# --------------------------------------------------------------------- scale
def _scaled_slider_crank(tmp_path: Path, s: float) -> Path:
    """slider_crank_dynamic.urdf with every length times s and every inertia times s^2."""
    import re

    text = (MODELS / "slider_crank_dynamic.urdf").read_text()

    def times_s(numbers: str) -> str:
        return " ".join(repr(float(x) * s) for x in numbers.split())

    text = re.sub(r'(<(?:origin|parent_origin|child_origin)\b[^>]*?\bxyz=")([^"]*)"',
                  lambda m: f'{m.group(1)}{times_s(m.group(2))}"', text)
    text = re.sub(r'(i[xyz]{2})="([^"]*)"', lambda m: f'{m.group(1)}="{float(m.group(2)) * s * s!r}"', text)
    text = re.sub(r'size="([^"]*)"', lambda m: f'size="{times_s(m.group(1))}"', text)
    text = text.replace('upper="0.3"', f'upper="{0.3 * s!r}"')
    path = tmp_path / f"slider_crank_{s:g}.urdf"
    path.write_text(text)
    return path


@pytest.mark.parametrize("s", [1e-6, 1e-3, 1e3])
def test_forces_scale_from_micrometres_to_kilometres(tmp_path, s):
    """Same angles and speeds, lengths x s, inertias x s^2, g and loads x s: every force
    scales by s and the crank torque by s^2, to rounding (1e-9 relative, as above)."""
    theta, omega, alpha = np.radians(70), 150.0, 20.0
    results = []
    for k, path in ((1.0, MODELS / "slider_crank_dynamic.urdf"), (s, _scaled_slider_crank(tmp_path, s))):
        mech, sol = slider_crank(theta, omega, alpha, path)
        load = Load("gas", mech.frame_id("B_pin"), np.array([-100.0 * k, 0.0, 0.0]), np.zeros(3))
        results.append(ForceSolver(mech, ["O"], gravity=(0, -G * k, 0), loads=[load]).solve(sol.q, sol.v, sol.a))
    ref, scaled = results
    assert scaled.effort[0] / s**2 == pytest.approx(ref.effort[0], rel=RTOL)
    for name in ("O", "A", "B", "slide"):
        np.testing.assert_allclose(scaled.reactions[name].force / s, ref.reactions[name].force, rtol=0,
                                   atol=RTOL * ref.reactions["O"].magnitude, err_msg=name)
    assert scaled.power.residual < rounding(1.0, scaled.condition)


# --------------------------------------------------------------------- errors
def _urdf_without_rod_mass(tmp_path: Path) -> Path:
    text = (MODELS / "slider_crank_dynamic.urdf").read_text()
    start = text.index('<inertial><origin xyz="0.06 0 0"/>')
    end = text.index("</inertial>", start) + len("</inertial>")
    path = tmp_path / "no_rod_mass.urdf"
    path.write_text(text[:start] + text[end:])
    return path


def test_a_moving_link_without_mass_is_named(tmp_path):
    mech = pinmech.Mechanism.from_urdf(_urdf_without_rod_mass(tmp_path))
    with pytest.raises(ModelError, match=r"rod have no <inertial> mass") as info:
        ForceSolver(mech, ["O"])
    assert "crank" not in str(info.value) and "massless" in str(info.value)


def test_a_link_declared_massless_is_accepted_and_carries_a_two_force_member(tmp_path):
    """A massless rod without gravity is a two-force member: its pin forces are equal,
    opposite and along AB (Newton, no inertia)."""
    mech, sol = slider_crank(np.radians(40), 200.0, 0.0, _urdf_without_rod_mass(tmp_path))
    f = ForceSolver(mech, ["O"], massless=["rod"]).solve(sol.q, sol.v, sol.a)
    F_A, F_B = f.reactions["A"].force, f.reactions["B"].force  # crank on rod, rod on piston
    np.testing.assert_allclose(F_A, F_B, atol=rounding(np.linalg.norm(F_A), f.condition))
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, sol.q)
    AB = data.oMf[mech.frame_id("B_pin")].translation - data.oMf[mech.frame_id("A_pin")].translation
    assert abs(np.cross(AB, F_A)[2]) < rounding(np.linalg.norm(AB) * np.linalg.norm(F_A), f.condition)


def _twice_cut(tmp_path: Path) -> Path:
    text = (MODELS / "slider_crank_dynamic.urdf").read_text()
    start = text.index('<constraint name="B"')
    end = text.index("</constraint>", start) + len("</constraint>")
    path = tmp_path / "twice.urdf"
    path.write_text(text[:end] + text[start:end].replace('name="B"', 'name="B2"') + text[end:])
    return path


def test_redundant_loops_are_named_and_minimum_norm_only_when_asked(tmp_path):
    """The wrist pin cut twice: 5 unknowns for 3 equations. Asked for, the minimum-norm
    answer shares the pin force equally between the two cuts."""
    mech1, sol = slider_crank(np.radians(40), 200.0, 5.0)
    single = ForceSolver(mech1, ["O"], gravity=(0, -G, 0)).solve(sol.q, sol.v, sol.a)
    mech2 = pinmech.Mechanism.from_urdf(_twice_cut(tmp_path))
    with pytest.raises(IndeterminateForcesError, match="redundant") as info:
        ForceSolver(mech2, ["O"], gravity=(0, -G, 0)).solve(sol.q, sol.v, sol.a)
    assert (info.value.unknowns, info.value.equations, info.value.exit_code) == (5, 3, 7)
    both = ForceSolver(mech2, ["O"], gravity=(0, -G, 0), minimum_norm=True).solve(sol.q, sol.v, sol.a)
    assert both.method == "minimum_norm"
    np.testing.assert_allclose(both.effort, single.effort, rtol=rounding(1.0, both.condition))
    for cut in ("B", "B2"):
        np.testing.assert_allclose(both.reactions[cut].force, single.reactions["B"].force / 2, rtol=1e-10)
    assert both.power.residual < rounding(1.0, both.condition)


def test_a_dead_centre_of_the_driver_is_not_determined():
    """Driving the piston of a centred slider-crank with crank and rod in line: no finite
    torque balance exists, a named error, even with minimum_norm."""
    mech = pinmech.Mechanism.from_urdf(MODELS / "slider_crank_dynamic.urdf")
    q = mech.neutral()
    mech.set_coordinate(q, "O", np.arcsin(0.01 / 0.2))  # crank and rod along the line to B, offset e
    mech.set_coordinate(q, "A", 0.0)
    mech.set_coordinate(q, "slide", np.sqrt(0.2**2 - 0.01**2))
    zero = np.zeros(mech.model.nv)
    for minimum_norm in (False, True):
        with pytest.raises(IndeterminateForcesError, match="dead centre"):
            ForceSolver(mech, ["slide"], gravity=(0, -G, 0), minimum_norm=minimum_norm).solve(q, zero, zero)


def test_the_users_model_keeps_its_gravity():
    mech, sol = slider_crank(0.3, 10.0, 0.0)
    before = mech.model.gravity.linear.copy()
    ForceSolver(mech, ["O"], gravity=(1.0, 2.0, 3.0)).solve(sol.q, sol.v, sol.a)
    np.testing.assert_array_equal(mech.model.gravity.linear, before)


def test_the_speed_fluctuation_of_a_heavy_flywheel_is_that_of_the_energy_equation():
    """With a flywheel I_f and no net work over the turn, energy conservation gives the
    crank speed exactly: (I_f + J(theta)) omega^2 / 2 + V(theta) = const, J = v*^T M v*
    (CRBA, v* the motion at unit crank speed), V from the positions (gravity and the constant
    gas load). Its (omega_max - omega_min) / omega_avg must equal Delta E / (I_f omega^2) from
    the constant-speed torque curve, up to the neglected terms, of relative order J / I_f and
    C_s itself (~1e-4 here; measured 1.3e-4): tolerance 2e-3 relative."""
    omega, flywheel, gas = 3000 * np.pi / 30, 10.0, np.array([-200.0, 0.0, 0.0])
    g = np.array([0.0, -G, 0.0])
    thetas = np.radians(np.linspace(0.0, 360.0, 361))
    mech, sol = slider_crank(thetas[0], omega, 0.0)
    model, data = mech.model, mech.model.createData()
    loops = pinmech.LoopSolver(mech, ["O"])
    forces = ForceSolver(mech, ["O"], gravity=g, loads=[Load("gas", mech.frame_id("B_pin"), gas, np.zeros(3))])
    efforts, inertia, potential = [], [], []
    for theta in thetas:
        sol = loops.solve([theta], [omega], [0.0], guess=sol.q)
        efforts.append(forces.solve(sol.q, sol.v, sol.a).effort[0])
        unit_v = sol.v / omega
        inertia.append(unit_v @ pin.crba(model, data, sol.q) @ unit_v)
        pin.framesForwardKinematics(model, data, sol.q)
        V = -sum(model.inertias[i].mass * g @ data.oMi[i].act(model.inertias[i].lever) for i in range(1, model.njoints))
        potential.append(V - gas @ data.oMf[mech.frame_id("B_pin")].translation)
    predicted = pinmech.energy_fluctuation(thetas, np.array(efforts)).speed_fluctuation(flywheel, omega)
    inertia, potential = np.array(inertia), np.array(potential)
    energy = 0.5 * (flywheel + inertia[0]) * omega**2 + potential[0]
    speed = np.sqrt(2 * (energy - potential) / (flywheel + inertia))
    exact = (speed.max() - speed.min()) / (0.5 * (speed.max() + speed.min()))
    assert predicted == pytest.approx(exact, rel=2e-3)


def test_a_negative_mass_is_named_as_such(tmp_path, models_dir):
    """link3 at -0.15 kg was reported as having no <inertial> mass."""
    text = (models_dir / "r_rtr.urdf").read_text().replace('<mass value="0.15"/>', '<mass value="-0.15"/>')
    path = tmp_path / "r_rtr.urdf"
    path.write_text(text)
    with pytest.raises(ModelError, match=r"mass of -0\.15 kg: a mass must be a positive number"):
        ForceSolver(pinmech.Mechanism.from_urdf(path), ["A"])
