"""Forces on every kind of loop cut (pinmech/solve/forces.py): a prismatic cut's wrench is a
force across the slide and a moment, acting on both bodies at one material point; a
revolute, spherical or fixed cut's likewise, in 3-D as in the plane.

- Newton-Euler by hand (scripts/closed_form_forces.py): the slider-crank cut at its
  slide (either way round) and the crank-and-slotted-lever (R-RTR) cut at its slide,
  link by link, F = m a_G and M_G = I alpha, with the closed-form kinematics.
- Energy: at constant crank speed, tau omega = d/dt (T + V_gravity), T = v^T M v / 2 from
  Pinocchio's CRBA and V from the centres of mass, differenced along the closed motion,
  for every cut type: revolute and spherical cuts of a spatial loop, a prismatic cut of a
  spatial slider-crank, MJCF connect and weld cuts.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import closed_form_forces as cff
import numpy as np
import pinocchio as pin
import pytest

import pinmech
from pinmech.solve.forces import ForceSolver, Load
from pinmech.model.mjcf import load_mjcf
from tests._mechanisms import spatial_rsur_revolute_cut_urdf, spatial_rsur_urdf
from tests.tolerance import closure, rounding

MODELS = Path(__file__).resolve().parents[1] / "models"
G = 9.81
# As tests/test_forces.py: poses close to 1e-13 of the size and the force equations'
# condition numbers are below 1e2, so the forces carry ~1e-11 relative error; 1e-9 of the
# largest force keeps a margin of a hundred, while a force applied at the wrong point of a
# slide (a lever arm of the slide's travel, 1e-1 relative here) fails.
RTOL = 1e-9


def _cross2(r: np.ndarray, f: np.ndarray) -> float:
    return float(r[0] * f[1] - r[1] * f[0])


def _moment_about(reaction, point: np.ndarray) -> float:
    """The reaction's moment about `point` (z) [N m]: M + (where it acts - point) x F."""
    return float(reaction.moment[2]) + _cross2(reaction.point[:2] - point, reaction.force[:2])


# ------------------------------------------------------------- slider-crank cut at its slide
def _slider_crank_cut_at_slide(tmp_path: Path, swapped: bool) -> Path:
    """models/slider_crank_dynamic.urdf with the wrist pin B in the tree and the slide cut
    (the ground the parent, or the piston when `swapped`)."""
    text = (MODELS / "slider_crank_dynamic.urdf").read_text(encoding="utf-8")
    text = re.sub(r'<joint name="slide".*?</joint>', '<joint name="B" type="continuous"><parent link="rod"/>'
                  '<child link="piston"/><origin xyz="0.15 0 0"/><axis xyz="0 0 1"/></joint>', text, flags=re.S)
    ground, piston = ('<parent link="ground"/><parent_origin xyz="0 0.01 0"/><parent_axis xyz="1 0 0"/>',
                      '<child link="piston"/><child_origin xyz="0 0 0"/><child_axis xyz="1 0 0"/>')
    if swapped:
        ground, piston = (ground.replace("parent", "child"), piston.replace("child", "parent"))
        ground, piston = piston, ground
    text = re.sub(r'<constraint name="B".*?</constraint>',
                  f'<constraint name="slide" type="prismatic">{ground}{piston}</constraint>', text, flags=re.S)
    path = tmp_path / f"slider_crank_cut_at_slide{'_swapped' if swapped else ''}.urdf"
    path.write_text(text, encoding="utf-8")
    return path


def _solve_slider_crank(path: Path, theta: float, omega: float, alpha: float):
    mech = pinmech.Mechanism.from_urdf(path)
    k = cff.cf.slider_crank(theta, 0.0, 0.0, 0.05, 0.15, 0.01)  # the piston right of the crank, as a guess only
    guess = mech.neutral()
    mech.set_coordinate(guess, "A", float(k.beta) - theta + 0.05)
    mech.set_coordinate(guess, "B", -float(k.beta) - 0.05)
    sol = pinmech.LoopSolver(mech, ["O"]).solve([theta], [omega], [alpha], guess=guess)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, sol.q)
    np.testing.assert_allclose(data.oMf[mech.frame_id("B_pin")].translation[:2], k.B, atol=closure(0.2, sol.accuracy.condition))  # same branch
    return mech, sol


@pytest.mark.parametrize("swapped", [False, True], ids=["ground-piston", "piston-ground"])
@pytest.mark.parametrize(("deg", "rpm", "alpha", "gravity", "gas"), [
    (45.0, 3000.0, 0.0, G, -200.0),
    (200.0, -1500.0, 500.0, 0.0, 0.0),
    (300.0, 60.0, -30.0, G, 800.0),
    (91.0, 0.0, 0.0, G, -50.0),          # statics: gravity and a load only
])
def test_a_slider_crank_cut_at_its_slide_matches_newton_euler_by_hand(tmp_path, swapped, deg, rpm, alpha,
                                                                       gravity, gas):
    """Norton's free bodies of crank, rod and piston: the guide's push on the piston is a
    normal force N14 and a moment M14 about B, at the piston wherever the guide's cut frame
    sits (here 0.2 m along the slide from it)."""
    theta, omega = math.radians(deg), rpm * math.pi / 30
    mech, sol = _solve_slider_crank(_slider_crank_cut_at_slide(tmp_path, swapped), theta, omega, alpha)
    load = Load("gas", mech.frame_id("B_pin"), np.array([gas, 0.0, 0.0]), np.zeros(3))
    f = ForceSolver(mech, ["O"], gravity=(0, -gravity, 0), loads=[load]).solve(sol.q, sol.v, sol.a)
    hand = cff.slider_crank_forces(theta, omega, alpha, 0.05, 0.15, 0.01, *cff.SLIDER_CRANK_BODIES,
                                   gravity=(0.0, -gravity), load_B=(gas, 0.0))
    scale = max(np.abs(np.concatenate([hand.F12, hand.F23, hand.F34])).max(), abs(hand.N14), 1e-300)
    r = f.reactions
    np.testing.assert_allclose(f.effort[0], hand.T, rtol=0, atol=RTOL * scale * 0.2)  # lever arms below 0.2 m
    np.testing.assert_allclose(r["O"].force[:2], hand.F12, rtol=0, atol=RTOL * scale, err_msg="F12 at O")
    np.testing.assert_allclose(r["A"].force[:2], hand.F23, rtol=0, atol=RTOL * scale, err_msg="F23 at A")
    np.testing.assert_allclose(r["B"].force[:2], hand.F34, rtol=0, atol=RTOL * scale, err_msg="F34 at B")
    slide, sign = r["slide"], (-1.0 if swapped else 1.0)  # swapped: the piston's push on the guide
    assert slide.is_cut and (slide.by, slide.on) == (("piston", "ground") if swapped else ("ground", "piston"))
    np.testing.assert_allclose(sign * slide.force[:2], [0.0, hand.N14], rtol=0, atol=RTOL * scale, err_msg="N14")
    B = np.asarray(cff.cf.slider_crank(theta, 0.0, 0.0, 0.05, 0.15, 0.01).B, float)
    np.testing.assert_allclose(sign * _moment_about(slide, B), hand.M14, rtol=0, atol=RTOL * scale * 0.2,
                               err_msg="M14 about B")
    assert f.power.residual < rounding(1.0, f.condition) and f.equation_residual < rounding(1.0, f.condition)


# ------------------------------------------------------------ slotted lever cut at its slide
def _r_rtr_cut_at_slide(tmp_path: Path) -> Path:
    """models/r_rtr.urdf with the pin C in the tree and the slide B_slider cut (block link2
    the parent, guide link3 the child), centres of mass moved off the joints."""
    text = (MODELS / "r_rtr.urdf").read_text(encoding="utf-8")
    text = re.sub(r'<joint name="B_slider".*?</joint>', '<joint name="C" type="continuous"><parent link="ground"/>'
                  '<child link="link3"/><origin xyz="0.05 0 0"/><axis xyz="0 0 1"/></joint>', text, flags=re.S)
    text = re.sub(r'<constraint name="C".*?</constraint>', '<constraint name="B_slider" type="prismatic">'
                  '<parent link="link2"/><parent_origin xyz="0 0 0"/><parent_axis xyz="1 0 0"/>'
                  '<child link="link3"/><child_origin xyz="0 0 0"/><child_axis xyz="1 0 0"/></constraint>',
                  text, flags=re.S)
    for link, com in (("link1", "0.05 0.004"), ("link2", "0.01 0.003"), ("link3", "0.075 -0.002")):
        text = text.replace(f'<link name="{link}">\n    <inertial>', f'<link name="{link}">\n    <inertial>'
                            f'<origin xyz="{com} 0"/>')
    path = tmp_path / "r_rtr_cut_at_slide.urdf"
    path.write_text(text, encoding="utf-8")
    return path


R_RTR_BODIES = (cff.Body(0.1, 1e-4, (0.05, 0.004)), cff.Body(0.05, 1e-6, (0.01, 0.003)),
                cff.Body(0.15, 3e-4, (0.075, -0.002)))


def _slotted_lever_pose(tmp_path, phi: float, omega: float, alpha: float):
    """The slotted lever cut at its slide, its closed form at crank angle phi [rad], and the
    pose solved there at crank rate omega [rad/s] and acceleration alpha [rad/s^2], seeded
    near the closed form's branch."""
    mech = pinmech.Mechanism.from_urdf(_r_rtr_cut_at_slide(tmp_path))
    k = cff.cf.r_rtr(phi, 0.0, 0.0)
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", float(k.phi3) - phi + 0.05)
    mech.set_coordinate(guess, "C", float(k.phi3) - 0.05)
    return mech, k, pinmech.LoopSolver(mech, ["A"]).solve([phi], [omega], [alpha], guess=guess)


@pytest.mark.parametrize(("deg", "rpm", "alpha", "gravity"), [
    (30.0, -50.0, 0.0, G),
    (135.0, 300.0, 40.0, 0.0),
    (250.0, 120.0, -15.0, G),
    (320.0, 0.0, 0.0, G),                # statics: gravity only
])
def test_a_slotted_lever_cut_at_its_slide_matches_newton_euler_by_hand(tmp_path, deg, rpm, alpha, gravity):
    """The crank-and-slotted-lever quick return (R-RTR) with the block's slide as the cut:
    the block pushes the turning guide with a normal force N34 and a moment M34 about B,
    where the guide's cut frame (its origin C) is 0.05-0.15 m away."""
    phi, omega = math.radians(deg), rpm * math.pi / 30
    mech, k, sol = _slotted_lever_pose(tmp_path, phi, omega, alpha)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, sol.q)
    np.testing.assert_allclose(data.oMf[mech.frame_id("D")].translation[:2], k.D, atol=closure(0.2, sol.accuracy.condition))  # same branch
    f = ForceSolver(mech, ["A"], gravity=(0, -gravity, 0)).solve(sol.q, sol.v, sol.a)
    hand = cff.r_rtr_forces(phi, omega, alpha, *R_RTR_BODIES, gravity=(0.0, -gravity))
    scale = max(np.abs(np.concatenate([hand.F12, hand.F23, hand.F14])).max(), abs(hand.N34))
    r = f.reactions
    np.testing.assert_allclose(f.effort[0], hand.T, rtol=0, atol=RTOL * scale * 0.2)  # lever arms below 0.2 m
    for joint, expected in (("A", hand.F12), ("B", hand.F23), ("C", hand.F14)):
        np.testing.assert_allclose(r[joint].force[:2], expected, rtol=0, atol=RTOL * scale, err_msg=joint)
    cut = r["B_slider"]
    assert cut.is_cut and (cut.by, cut.on) == ("link2", "link3")
    n = cff.cf.perp(np.asarray(k.u, float))
    np.testing.assert_allclose(cut.force[:2], hand.N34 * n, rtol=0, atol=RTOL * scale, err_msg="N34")
    np.testing.assert_allclose(_moment_about(cut, np.asarray(k.B, float)), hand.M34, rtol=0, atol=RTOL * scale * 0.2,
                               err_msg="M34 about B")
    assert f.power.residual < rounding(1.0, f.condition) and f.equation_residual < rounding(1.0, f.condition)


# ------------------------------------------------------------------- every cut type, by energy
_INERTIAL = '<inertial><mass value="{m}"/><inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>'


def _spatial_slider_crank_urdf() -> str:
    """A crank about z (r 50 mm) driving a block along a line (x, 10 mm, 30 mm) out of its
    plane, through a rod of 150 mm with three hinges at A and a universal joint at B; the
    block's slide is a prismatic cut. Freedoms 1 + 3 + 2 = 6, the cut takes 5: mobility 1.
    Drawn with the crank along x, every frame world-aligned."""
    x_b = 0.05 + math.sqrt(0.15**2 - 0.01**2 - 0.03**2)
    heavy, light = _INERTIAL.format(m=0.3, i=2e-4), _INERTIAL.format(m=0.01, i=1e-7)
    links = "".join(f'<link name="{n}">{heavy if n in ("crank", "rod", "block") else light}</link>'
                    for n in ("crank", "a1", "a2", "rod", "b1", "block"))
    chain = [("O", "ground", "crank", "0 0 0", "0 0 1"), ("Az", "crank", "a1", "0.05 0 0", "0 0 1"),
             ("Ay", "a1", "a2", "0 0 0", "0 1 0"), ("Ax", "a2", "rod", "0 0 0", "1 0 0"),
             ("By", "rod", "b1", f"{x_b - 0.05!r} 0.01 0.03", "0 1 0"), ("Bz", "b1", "block", "0 0 0", "0 0 1")]
    joints = "".join(f'<joint name="{n}" type="continuous"><parent link="{p}"/><child link="{c}"/>'
                     f'<origin xyz="{xyz}"/><axis xyz="{axis}"/></joint>' for n, p, c, xyz, axis in chain)
    return (f'<?xml version="1.0"?><robot name="spatial_slider_crank"><link name="ground"/>{links}{joints}'
            f'<constraint name="slide" type="prismatic"><parent link="ground"/><parent_origin xyz="{x_b!r} 0.01 0.03"/>'
            '<parent_axis xyz="1 0 0"/><child link="block"/><child_origin xyz="0 0 0"/><child_axis xyz="1 0 0"/>'
            '</constraint></robot>')


def _welded_four_bar_mjcf() -> str:
    """models/mjcf/four_bar.xml closed by a weld: the rocker hangs on the coupler at B and
    a base body on the rocker at O4, welded to the ground where it stands at qpos0."""
    k = cff.cf.four_bar(0.0, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10)
    t3, t4 = float(k.theta3), float(k.theta4)
    return f"""<mujoco model="four_bar_weld"><compiler angle="radian"/><worldbody>
  <body name="crank"><joint name="O2" type="hinge" axis="0 0 1"/>
    <geom type="capsule" fromto="0 0 0 0.04 0 0" size="0.004"/>
    <body name="coupler" pos="0.04 0 0" euler="0 0 {t3!r}"><joint name="A" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0.12 0 0" size="0.004"/>
      <body name="rocker" pos="0.12 0 0" euler="0 0 {t4 + math.pi - t3!r}"><joint name="B" type="hinge" axis="0 0 1"/>
        <geom type="capsule" fromto="0 0 0 0.08 0 0" size="0.004"/>
        <body name="base" pos="0.08 0 0"><joint name="O4" type="hinge" axis="0 0 1"/>
          <geom type="box" size="0.01 0.01 0.01"/></body></body></body></body>
</worldbody><equality><weld name="O4_weld" body1="base"/></equality></mujoco>"""


def _load(tmp_path: Path, name: str) -> tuple[pinmech.Mechanism, str]:
    """A mechanism with one cut of each kind, and its driver."""
    if name == "revolute, spatial":
        path = tmp_path / "rsur_r.urdf"
        path.write_text(spatial_rsur_revolute_cut_urdf(), encoding="utf-8")
        return pinmech.Mechanism.from_urdf(path), "R1"
    if name == "spherical, spatial":
        path = tmp_path / "rsur_s.urdf"
        path.write_text(spatial_rsur_urdf(), encoding="utf-8")
        return pinmech.Mechanism.from_urdf(path), "R1"
    if name == "prismatic, spatial":
        path = tmp_path / "spatial_slider_crank.urdf"
        path.write_text(_spatial_slider_crank_urdf(), encoding="utf-8")
        return pinmech.Mechanism.from_urdf(path), "O"
    if name == "fixed, planar (MJCF weld)":
        path = tmp_path / "weld.xml"
        path.write_text(_welded_four_bar_mjcf(), encoding="utf-8")
        return load_mjcf(path), "O2"
    if name == "fixed, spatial (MJCF weld, a ball in the tree)":
        return load_mjcf(MODELS / "mjcf" / "ball_loop.xml"), "O2"
    if name == "spherical, planar (MJCF connect)":
        return load_mjcf(MODELS / "mjcf" / "four_bar.xml"), "O2"
    raise AssertionError(name)


CUT_KINDS = ["revolute, spatial", "spherical, spatial", "prismatic, spatial", "fixed, planar (MJCF weld)",
             "fixed, spatial (MJCF weld, a ball in the tree)", "spherical, planar (MJCF connect)"]


@pytest.mark.parametrize("name", CUT_KINDS)
def test_every_cut_type_gives_the_torque_of_the_energy_rate(tmp_path, name):
    """tau omega = d/dt (T + V_gravity) at constant crank speed, T = v^T M v / 2 (CRBA) and
    V = -sum m g . c, differenced over +-h of crank angle along the closed motion (each pose
    continued from the last). h = 1e-4 rad: truncation h^2/6 E''' ~ 1e-9 of the largest
    power, rounding eps E / h ~ 1e-12; tolerance 1e-7 of the largest power term."""
    mech, driver = _load(tmp_path, name)
    omega, h, g = 3.0, 1e-4, np.array([0.3, -G, -1.2])
    solver = pinmech.LoopSolver(mech, [driver])
    guess = mech.reference if mech.reference is not None else mech.neutral()  # the file's assembly
    start = mech.coordinate(guess, driver)
    theta = start + 0.2
    poses = {}
    for t in (start, start + 0.1, theta - h, theta, theta + h):  # continuation from the reference assembly
        poses[t] = solver.solve([t], [omega], [0.0], guess=guess)
        guess = poses[t].q

    def energy(sol) -> float:
        model, data = mech.model, mech.model.createData()
        T = 0.5 * sol.v @ pin.crba(model, data, sol.q) @ sol.v
        pin.forwardKinematics(model, data, sol.q)
        V = -sum(model.inertias[i].mass * g @ data.oMi[i].act(model.inertias[i].lever) for i in range(1, model.njoints))
        return T + V

    sol = poses[theta]
    f = ForceSolver(mech, [driver], gravity=g).solve(sol.q, sol.v, sol.a)
    rate = (energy(poses[theta + h]) - energy(poses[theta - h])) / (2 * h) * omega
    scale = max(abs(f.power.kinetic_rate), abs(f.power.gravity_power), abs(f.effort[0] * omega))
    np.testing.assert_allclose(f.effort[0] * omega, rate, rtol=0, atol=1e-7 * scale)
    assert f.power.residual < rounding(1.0, f.condition) and f.equation_residual < 1e-11
    assert any(r.is_cut for r in f.reactions.values())


def test_gravity_and_max_condition_set_later_are_the_solvers_own(tmp_path):
    """A ForceSolver built without gravity and given it afterwards (`f.gravity = ...`): the
    slotted lever's driver torque and pin forces are Newton-Euler's by hand with that gravity
    (the set gravity reached the loads' part of the solve and not the model's), and a bad
    gravity or max_condition set later is refused as at construction."""
    phi, omega, alpha = math.radians(250.0), 120.0 * math.pi / 30, -15.0
    mech, _, sol = _slotted_lever_pose(tmp_path, phi, omega, alpha)
    solver = ForceSolver(mech, ["A"])
    solver.gravity = (0, -G, 0)
    f = solver.solve(sol.q, sol.v, sol.a)
    hand = cff.r_rtr_forces(phi, omega, alpha, *R_RTR_BODIES, gravity=(0.0, -G))
    scale = max(np.abs(np.concatenate([hand.F12, hand.F23, hand.F14])).max(), abs(hand.N34))
    np.testing.assert_allclose(f.effort[0], hand.T, rtol=0, atol=RTOL * scale * 0.2)  # lever arms below 0.2 m
    np.testing.assert_allclose(f.reactions["A"].force[:2], hand.F12, rtol=0, atol=RTOL * scale)
    for option, value in (("gravity", (0, float("nan"), 0)), ("gravity", (1, 2)), ("max_condition", float("nan"))):
        with pytest.raises(pinmech.OptionError, match=option):
            setattr(solver, option, value)
    assert solver.gravity.tolist() == [0.0, -G, 0.0]
