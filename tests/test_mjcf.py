"""MJCF loops against MuJoCo itself: placements, MuJoCo's own constraint solve, rates.

MuJoCo (a test dependency) is the independent source: its compiler places every body and
site, its soft constraint solver closes the loops with the driver held by a stiff joint
equality (gravity off, contacts off, light damping), and its kinematics at pinmech's poses
give the points whose finite differences check pinmech's velocities.

Tolerances: placements at qpos0 are the same arithmetic on the same numbers (1e-12 m);
MuJoCo's solve stops at a constraint residual of ~1e-11 m with joint coordinates converged
to ~1e-10, so poses agree to 1e-8 m (a wrong loop, branch or dropped body is off by mm);
central differences with h = 1e-6 rad have truncation ~h^2 |x'''| ~ 1e-13 and round-off
~1e-16 / 1e-6 = 1e-10 m/s, so velocities agree to 1e-7 of their scale.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinmech.cli import main
from pinmech.exceptions import ModelError
from pinmech.model.mjcf import load_mjcf
from pinmech.solve.loops import LoopSolver
from tests.tolerance import closure, residual, rounding

# One placement composed by MuJoCo's compiler and by Pinocchio from the same numbers: the
# rounding of a chain of a few bodies of up to 1 m (rotations: entries up to 1).
PLACED = rounding(1.0)
# Poses solved by pinmech, compared across two models of one mechanism: the closure bound at
# condition numbers below 1e2 (tests/tolerance.py), on sizes up to 0.2 m, angles of up to pi
# and rates of up to 10 rad/s.
COND = 1e2

mujoco = pytest.importorskip("mujoco")

MJCF = Path(__file__).resolve().parents[1] / "models" / "mjcf"
SOLVABLE = {"four_bar": ("O2", [0.3, 0.8, 1.4]), "slider_crank": ("O", [0.4, 1.2, 2.0]),
            "ball_loop": ("O2", [0.2, 0.4]), "leg": ("hip", [-0.1, -0.25])}


def mujoco_model(name: str, driver: str | None = None, value: float = 0.0):
    text = (MJCF / f"{name}.xml").read_text()
    if driver is not None:
        text = text.replace("<worldbody>", '<option gravity="0 0 0" timestep="0.002"><flag contact="disable"/>'
                            '</option><default><joint damping="0.002"/></default><worldbody>', 1)
        text = text.replace("</equality>", f'<joint joint1="{driver}" polycoef="{value!r} 0 0 0 0"/></equality>')
    m = mujoco.MjModel.from_xml_string(text)
    return m, mujoco.MjData(m)


def mujoco_solve(name: str, driver: str, value: float):
    m, d = mujoco_model(name, driver, value)
    for _ in range(8000):
        mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)
    return m, d


def set_qpos(mech, q, m, d) -> None:
    """pinmech's q into MuJoCo's qpos: same joint order (depth first in the file), a ball's
    quaternion x y z w -> w x y z; a body's several hinges are one composite joint in Pinocchio."""
    parts = []
    for joint in sorted(mech.joints.values(), key=lambda j: j.idx_q):
        part = q[joint.idx_q: joint.idx_q + joint.nq]
        parts.append(np.roll(part, 1) if joint.nq == 4 else part)
    assert m.nq == mech.model.nq
    d.qpos[:] = np.concatenate(parts)
    mujoco.mj_forward(m, d)


def sites(mech, data, m, d):
    names = [m.site(i).name for i in range(m.nsite)]
    ours = np.array([data.oMf[mech.model.getFrameId(n)].translation for n in names])
    return ours, np.array(d.site_xpos)


@pytest.mark.parametrize("name", ["four_bar", "slider_crank", "ball_loop", "leg", "leg_ball"])
def test_bodies_and_sites_sit_where_mujoco_puts_them_at_qpos0(name):
    mech = load_mjcf(MJCF / f"{name}.xml")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    m, d = mujoco_model(name)
    mujoco.mj_forward(m, d)
    for i in range(1, m.nbody):
        body = m.body(i).name
        frame = data.oMf[mech.model.getFrameId(body, pin.FrameType.BODY)]
        np.testing.assert_allclose(frame.translation, d.xpos[i], atol=PLACED, err_msg=body)
        np.testing.assert_allclose(frame.rotation, d.xmat[i].reshape(3, 3), atol=PLACED, err_msg=body)
    ours, theirs = sites(mech, data, m, d)
    np.testing.assert_allclose(ours, theirs, atol=PLACED)


def test_pinocchio_alone_drops_the_second_top_body_and_pinmech_keeps_it():
    """stack-of-tasks/pinocchio#2364: the rocker (second body of <worldbody>) vanishes."""
    bare = pin.buildModelFromMJCF(str(MJCF / "four_bar.xml"))
    assert "O4" not in list(bare.names)  # the trap, as the installed Pinocchio has it
    assert "O4" in load_mjcf(MJCF / "four_bar.xml").joints


def test_a_fixed_top_body_keeps_its_pos():
    """The leg's pelvis sits at z = 1 m: Pinocchio alone puts it at the origin."""
    bare = pin.buildModelFromMJCF(str(MJCF / "leg.xml"))
    bare_data = bare.createData()
    pin.framesForwardKinematics(bare, bare_data, pin.neutral(bare))
    assert bare_data.oMf[bare.getFrameId("pelvis")].translation[2] == 0.0  # the trap, as installed
    mech = load_mjcf(MJCF / "leg.xml")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    assert data.oMf[mech.model.getFrameId("pelvis", pin.FrameType.BODY)].translation[2] == pytest.approx(1.0, abs=rounding(1.0))


@pytest.mark.parametrize("name", sorted(SOLVABLE))
def test_poses_match_mujocos_own_constraint_solve(name):
    driver, values = SOLVABLE[name]
    mech = load_mjcf(MJCF / f"{name}.xml")
    solver = LoopSolver(mech, [driver])
    q = mech.neutral()
    for value in values:
        sol = solver.solve([value], [0.0], [0.0], guess=q)
        q = sol.q
        pin.framesForwardKinematics(mech.model, solver.data, q)
        m, d = mujoco_solve(name, driver, value)
        eq = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        assert np.max(np.abs(d.efc_pos[eq])) < 1e-9  # MuJoCo did close its loop
        ours, theirs = sites(mech, solver.data, m, d)
        np.testing.assert_allclose(ours, theirs, atol=1e-8)
        np.testing.assert_allclose([solver.data.oMf[mech.links[m.body(i).name]].translation
                                    for i in range(1, m.nbody)], d.xpos[1:], atol=1e-8)
        # and MuJoCo finds pinmech's pose closed: its equality residual at our q
        m0, d0 = mujoco_model(name)
        set_qpos(mech, q, m0, d0)
        eq0 = d0.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        np.testing.assert_allclose(d0.efc_pos[eq0], 0.0, atol=residual(1.0))


@pytest.mark.parametrize("name", sorted(SOLVABLE))
def test_point_velocities_are_finite_differences_of_mujoco_positions(name):
    driver, values = SOLVABLE[name]
    mech = load_mjcf(MJCF / f"{name}.xml")
    solver = LoopSolver(mech, [driver])
    m, d = mujoco_model(name)
    h, omega = 1e-6, 2.0
    q = solver.solve([values[0]], guess=mech.neutral()).q
    sol = solver.solve([values[0]], [omega], [0.0], guess=q)
    pin.forwardKinematics(mech.model, solver.data, sol.q, sol.v)
    pin.updateFramePlacements(mech.model, solver.data)
    names = [m.site(i).name for i in range(m.nsite)]
    ours = np.array([pin.getFrameVelocity(mech.model, solver.data, mech.model.getFrameId(n),
                                          pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear for n in names])
    ends = []
    for step in (-h, h):
        q_step = solver.solve([values[0] + step], guess=sol.q).q
        set_qpos(mech, q_step, m, d)
        ends.append(np.array(d.site_xpos))
    fd = (ends[1] - ends[0]) / (2 * h) * omega
    np.testing.assert_allclose(ours, fd, atol=1e-7 * max(1.0, np.max(np.abs(fd))))


def test_cassie_like_rod_spin_is_named(tmp_path, capsys):
    """Hip driven, the rod hangs on a ball: mobility 2, and the ball joint is the idle one."""
    mech = load_mjcf(MJCF / "leg_ball.xml")
    assert mech.mobility == 2 and mech.idle_joints(["hip"]) == ["rod_ball"]
    scene = tmp_path / "leg.toml"
    scene.write_text(f'mjcf = "{MJCF / "leg_ball.xml"}"\n[drivers.hip]\nangle = "10 deg"\n')
    assert main(["solve", str(scene)]) == 5
    err = capsys.readouterr().err
    assert "rod_ball" in err and "universal joint" in err and len(err.strip().splitlines()) == 1


def _variant(tmp_path, old: str, new: str, name: str = "four_bar") -> Path:
    text = (MJCF / f"{name}.xml").read_text()
    assert old in text
    path = tmp_path / "v.xml"
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize("old, new, words", [
    ('<connect name="B"', '<joint name="J" joint1="O2" joint2="O4"/><connect name="B"', ["<joint", "connect and weld"]),
    ('<connect name="B"', '<connect active="false" name="B"', ["active"]),
    ('anchor="0.12 0 0"/>', 'anchor="0.12 0 0"/><weld body1="coupler" body2="rocker" relpose="0 0 0 1 0 0 0"/>',
     ["relpose"]),
    ("</mujoco>", "", ["malformed XML"]),
    ('body2="rocker"', 'body2="rockr"', ["Pinocchio cannot build", "rockr"]),
    # the parser read these as garbage (z = -2e243) or as given: MuJoCo refuses them
    ('<body name="coupler" pos="0.04 0 0"', '<body name="coupler" pos="0.04, 0, 0"', ['<body name="coupler">', "pos="]),
    ('<body name="coupler" pos="0.04 0 0"', '<body name="coupler" pos="0.04 0"', ["not 3 finite numbers"]),
    ('<site name="P" pos="0.06 0.03 0"/>', '<site name="P" pos="0.06 0.03 nan"/>', ['<site name="P">', "nan"]),
    ('anchor="0.12 0 0"/>', 'anchor="0.12 0 0 1"/>', ["anchor=", "not 3 finite numbers"]),
    # a misspelled attribute the kinematics read was skipped: the anchor at the body's origin, another linkage
    ('anchor="0.12 0 0"/>', 'anchr="0.12 0 0"/>', ["<connect name=\"B\">", "anchr=", "did you mean anchor"]),
    ('<site name="P" pos="0.06 0.03 0"/>', '<site name="P" poss="0.06 0.03 0"/>', ["did you mean pos"]),
])
def test_refusals_are_one_line_naming_file_and_element(tmp_path, capsys, old, new, words):
    path = _variant(tmp_path, old, new)
    with pytest.raises(ModelError) as err:
        load_mjcf(path)
    message = str(err.value)
    assert str(path) in message and "\n" not in message
    for word in words:
        assert word in message, message


def test_connect_sites_apart_at_qpos0_are_refused(tmp_path):
    """MuJoCo pulls two sites together; Pinocchio's parser would keep them where they are."""
    path = _variant(tmp_path, '<connect name="B" body1="coupler" body2="rocker" anchor="0.12 0 0"/>',
                    '<connect name="B" site1="P" site2="Q"/>')
    text = path.read_text().replace('<joint name="O4" type="hinge" axis="0 0 1"/>',
                                    '<joint name="O4" type="hinge" axis="0 0 1"/><site name="Q" pos="0.08 0 0"/>')
    path.write_text(text)
    with pytest.raises(ModelError) as err:
        load_mjcf(path)
    message = str(err.value)
    assert str(path) in message and "\n" not in message
    assert "apart at qpos0" in message or "Pinocchio" in message, message


def test_mjcf_scene_solves_like_the_urdf_one(scenes_dir, capsys):
    assert main(["solve", str(scenes_dir / "four_bar_mjcf.toml"), "--json"]) == 0
    import json

    ours = json.loads(capsys.readouterr().out)
    assert main(["solve", str(scenes_dir / "four_bar.toml"), "--json"]) == 0
    theirs = json.loads(capsys.readouterr().out)
    for link in ("coupler", "rocker"):
        np.testing.assert_allclose(ours["links"][link]["angular_velocity"], theirs["links"][link]["angular_velocity"],
                                   atol=closure(10.0, COND))
    np.testing.assert_allclose(ours["points"]["P"]["position"], theirs["points"]["P"]["position"], atol=closure(0.2, COND))


def test_joint_ref_values_make_qpos0_the_reference(tmp_path):
    """A hinge with ref="0.2": the drawn pose is qpos0 = 0.2, not 0, in MuJoCo and in pinmech."""
    path = _variant(tmp_path, '<joint name="O4" type="hinge" axis="0 0 1"/>',
                    '<joint name="O4" type="hinge" axis="0 0 1" ref="0.2"/>')
    mech = load_mjcf(path)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    np.testing.assert_allclose(mech.neutral(), m.qpos0, atol=0)
    solver = LoopSolver(mech, ["O2"])
    sol = solver.solve([0.7], guess=mech.neutral())
    set_qpos(mech, sol.q, m, d)
    eq = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    np.testing.assert_allclose(d.efc_pos[eq], 0.0, atol=residual(1.0))


def test_a_floating_base_is_held_at_qpos0(tmp_path):
    """Cassie's pelvis floats (<freejoint/>): the leg moves relative to it, as with a fixed one."""
    path = _variant(tmp_path, '<geom type="box" size="0.05 0.05 0.03" rgba="0.5 0.5 0.5 1"/>',
                    '<freejoint name="root"/><geom type="box" size="0.05 0.05 0.03" rgba="0.5 0.5 0.5 1"/>',
                    name="leg")
    floating, fixed = load_mjcf(path), load_mjcf(MJCF / "leg.xml")
    assert "root" not in floating.joints and floating.mobility == fixed.mobility == 1
    ours = LoopSolver(floating, ["hip"]).solve([-0.2], [1.0])
    theirs = LoopSolver(fixed, ["hip"]).solve([-0.2], [1.0])
    np.testing.assert_allclose(ours.q, theirs.q, atol=closure(np.pi, COND))
    np.testing.assert_allclose(ours.v, theirs.v, atol=closure(10.0, COND))


@pytest.mark.parametrize("attr", ['axisangle="0.3 0.5 0.8 40"', 'xyaxes="1 1 0 -1 1 0.3"', 'zaxis="0.2 0.4 1"',
                                  'quat="2 0.2 0.6 0.4"', 'euler="10 20 30"'])
def test_every_way_of_turning_a_body_agrees_with_mujoco(tmp_path, attr):
    """Pinocchio's parser takes axisangle's axis unnormalised (0.15 rad off for this one)."""
    xml = f"""<mujoco><worldbody><body name="a" pos="0.1 0.2 0.3" {attr}><joint name="j" type="hinge" axis="0 1 0"/>
      <geom type="sphere" size="0.01"/><body name="b" pos="0.1 0 0" {attr}><joint name="k" type="slide" axis="0 2 1"/>
      <geom type="sphere" size="0.01"/><site name="s" pos="0 0.1 0"/></body></body></worldbody></mujoco>"""
    path = tmp_path / "turned.xml"
    path.write_text(xml)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    q = np.array([0.7, 0.05])
    d.qpos[:] = q
    mujoco.mj_forward(m, d)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    for i in range(1, m.nbody):
        np.testing.assert_allclose(data.oMf[mech.links[m.body(i).name]].rotation, d.xmat[i].reshape(3, 3), atol=PLACED)
    np.testing.assert_allclose(data.oMf[mech.points["s"]].translation, d.site_xpos[0], atol=PLACED)


def test_a_frame_element_is_refused_not_dropped(tmp_path):
    """Pinocchio's parser drops <frame> and every body in it (the model lost body b here)."""
    path = tmp_path / "framed.xml"
    path.write_text("""<mujoco><worldbody><body name="a"><joint name="j" type="hinge" axis="0 0 1"/>
      <geom type="sphere" size="0.01"/><frame pos="0.1 0 0" euler="0 0 30"><body name="b" pos="0.1 0 0">
      <joint name="k" type="hinge" axis="0 1 0"/><geom type="sphere" size="0.01"/></body></frame></body>
      </worldbody></mujoco>""")
    assert "k" not in list(pin.buildModelFromMJCF(str(path)).names)  # the trap, as installed
    with pytest.raises(ModelError, match="<frame>"):
        load_mjcf(path)


def test_a_one_joint_model_loads(tmp_path):
    """A single hinge: Pinocchio returns (6,) Jacobians for one freedom; pinmech keeps (6, 1)."""
    path = tmp_path / "one.xml"
    path.write_text("""<mujoco><worldbody><body name="a"><joint name="j" type="hinge" axis="0 0 1"/>
      <geom type="sphere" size="0.01"/><site name="tip" pos="0.1 0 0"/></body></worldbody></mujoco>""")
    mech = load_mjcf(path)
    assert mech.mobility == 1 and mech.plane_normal is not None


def test_lock_in_an_mjcf_scene(tmp_path):
    """[lock] O2 = 0.5 rad on the MJCF four-bar: nothing left to drive, and the pose is the one
    the unlocked four-bar has with O2 driven to 0.5 rad; a ball joint cannot be locked."""
    locked = load_mjcf(MJCF / "four_bar.xml", locked={"O2": 0.5})
    assert locked.mobility == 0 and locked.locked == {"O2": 0.5}
    q = LoopSolver(locked, []).solve([], guess=locked.neutral()).q
    free = load_mjcf(MJCF / "four_bar.xml")
    q_free = LoopSolver(free, ["O2"]).solve([0.5], guess=free.neutral()).q
    data, data_free = locked.model.createData(), free.model.createData()
    pin.framesForwardKinematics(locked.model, data, q)
    pin.framesForwardKinematics(free.model, data_free, q_free)
    np.testing.assert_allclose(data.oMf[locked.points["P"]].translation, data_free.oMf[free.points["P"]].translation,
                               atol=closure(0.2, COND))
    with pytest.raises(ModelError, match="rod_ball.*3 freedoms"):
        load_mjcf(MJCF / "leg_ball.xml", locked={"rod_ball": 0.0})


# ---------------------------------------------------------------- default classes, euler sequences, fromto sites
CHAIN = """<mujoco>{compiler}{defaults}<worldbody>
  <body name="a" pos="0.1 0.2 0.3" {turn}{childclass}><joint name="ja" {joint}/>
    <geom {geom}/><site name="s" {site}/>
    <body name="b" pos="0.2 0 0.05" {turn}><joint name="jb" axis="0 1 0.5" {joint_b}/>
      <geom type="box" size="0.05 0.02 0.01" mass="0.3"/><site name="t" {site_b}/></body>
  </body></worldbody></mujoco>"""
CHAIN_PLAIN = dict(compiler="", defaults="", turn="", childclass="", joint='axis="0 0 1"', geom='type="sphere" '
                   'size="0.02" pos="0.1 0 0" mass="0.5"', site='pos="0.05 0.1 0"', joint_b="",
                   site_b='pos="0.05 0.02 0"')
CHAIN_CASES = {
    "joint pos from <default>": dict(defaults='<default><joint pos="0 0.1 0"/></default>'),
    "site pos from <default>": dict(defaults='<default><site pos="0.1 0.2 0.3"/></default>', site=""),
    "site quat from a class": dict(defaults='<default><default class="k"><site quat="0.9 0.1 0.3 0.2"/></default>'
                                   '</default>', site='class="k" pos="0.05 0.1 0"'),
    "nested classes, euler over an inherited quat": dict(
        defaults='<default><site quat="0.9 0.1 0.3 0.2"/><default class="k"><site euler="10 20 30"/>'
                 '<joint pos="0.01 0.02 0"/></default></default>', childclass=' childclass="k"'),
    "class main named": dict(defaults='<default><joint pos="0 0.05 0"/></default>', joint='class="main" axis="0 0 1"'),
    "joint type slide from a childclass": dict(defaults='<default><default class="k"><joint type="slide"/></default>'
                                               '</default>', childclass=' childclass="k"'),
    "eulerseq XYZ (fixed axes), degrees": dict(compiler='<compiler eulerseq="XYZ"/>', turn='euler="10 20 30"'),
    "eulerseq ZYX, radians": dict(compiler='<compiler angle="radian" eulerseq="ZYX"/>', turn='euler="0.1 0.2 0.3"'),
    "eulerseq xYz, mixed": dict(compiler='<compiler eulerseq="xYz"/>', turn='euler="10 -20 30"'),
    "site along fromto": dict(site='type="capsule" size="0.01" fromto="0 0 0 0.3 0.2 0.1"'),
    "site along +z fromto": dict(site='type="capsule" size="0.01" fromto="0 0 0 0 0 0.2"',
                                 site_b='type="capsule" size="0.01" fromto="0 0 0.2 0 0 0"'),
}


def _chain(tmp_path, **changes) -> Path:
    path = tmp_path / "chain.xml"
    path.write_text(CHAIN.format(**(CHAIN_PLAIN | changes)))
    return path


@pytest.mark.parametrize("case", sorted(CHAIN_CASES))
def test_defaults_euler_sequences_and_fromto_sites_as_mujoco_compiles_them(tmp_path, case):
    """Every body and site where MuJoCo puts it, axes included, at qpos0 and at a moved
    pose: Pinocchio's parser alone drops a default joint's or site's pos (85 mm off at 50
    degrees), a class's site orientation (45 degrees), reads upper-case eulerseq as
    another rotation (4 degrees) and leaves a fromto site with its body's axes (180
    degrees). Same arithmetic on the same numbers: 1e-12."""
    path = _chain(tmp_path, **CHAIN_CASES[case])
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    data = mech.model.createData()
    for q in (np.zeros(2), np.array([0.87, -0.4])):
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        pin.framesForwardKinematics(mech.model, data, q)
        for i in range(1, m.nbody):
            frame = data.oMf[mech.links[m.body(i).name]]
            np.testing.assert_allclose(frame.translation, d.xpos[i], atol=PLACED, err_msg=m.body(i).name)
            np.testing.assert_allclose(frame.rotation, d.xmat[i].reshape(3, 3), atol=PLACED, err_msg=m.body(i).name)
        for i in range(m.nsite):
            frame = data.oMf[mech.points[m.site(i).name]]
            np.testing.assert_allclose(frame.translation, d.site_xpos[i], atol=PLACED, err_msg=m.site(i).name)
            np.testing.assert_allclose(frame.rotation, d.site_xmat[i].reshape(3, 3), atol=PLACED, err_msg=m.site(i).name)


def test_a_joint_type_from_a_default_class_is_read(tmp_path):
    """The scene reads driver kinds from the file: a slide set by a class is prismatic."""
    from pinmech.model.mjcf import mjcf_joint_types

    path = _chain(tmp_path, **CHAIN_CASES["joint type slide from a childclass"])
    assert mjcf_joint_types(path) == {"ja": "prismatic", "jb": "prismatic"}
    assert load_mjcf(path).joints["ja"].kind == "prismatic"


@pytest.mark.parametrize("geom", [
    '',  # the mass of <default>
    'pos="0.1 0.05 0"',  # the place of the class
    'type="box" size="0.05 0.02 0.01" euler="0 0 40"',  # the turn of the box's inertia
])
def test_masses_from_default_classes_are_mujocos(tmp_path, geom):
    """Each body's mass, centre of mass and inertia as MuJoCo compiles them (Pinocchio's
    parser alone took the default density for a default mass: 0.034 kg for 0.5). Same
    arithmetic: 1e-12 relative."""
    defaults = '<default><geom type="sphere" size="0.02" mass="0.5"/><default class="g"><geom pos="0.2 0 0.1"/>' \
               '</default></default>'
    path = _chain(tmp_path, defaults=defaults, geom=f'class="g" {geom}')
    m = mujoco.MjModel.from_xml_path(str(path))
    mech = load_mjcf(path)
    for i in range(1, m.nbody):
        inertia = mech.model.inertias[mech.model.frames[mech.links[m.body(i).name]].parentJoint]
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, m.body_iquat[i])
        R = R.reshape(3, 3)
        assert inertia.mass == pytest.approx(m.body_mass[i], rel=rounding(1.0))
        np.testing.assert_allclose(inertia.lever, m.body_ipos[i], atol=PLACED)
        np.testing.assert_allclose(inertia.inertia, R @ np.diag(m.body_inertia[i]) @ R.T, atol=PLACED * m.body_mass[i])


PENDULUM = """<mujoco><compiler angle="radian"/>{compiler}<asset>{asset}</asset><worldbody>
  <body name="arm" pos="0 0 1"><joint name="hinge" type="hinge" axis="0 1 0" {joint}/>{geom}
  <site name="tip" pos="0.3 0 0"/></body></worldbody></mujoco>"""
BALL = '<geom type="sphere" size="0.02" pos="0.3 0 0" mass="0.5"/>'


def _pendulum(tmp_path, compiler="", asset="", joint="", geom=BALL) -> Path:
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM.format(compiler=compiler, asset=asset, joint=joint, geom=geom))
    return path


@pytest.mark.parametrize("change, words", [
    (dict(asset='<mesh name="m" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/>', geom='<geom type="mesh" mesh="m" mass="0.5"/>'),
     ['<body name="arm">', "mesh geom", "<inertial>"]),
    (dict(compiler='<compiler settotalmass="3"/>'), ['settotalmass="3"']),
    (dict(joint='damping="3"'), ['<joint name="hinge">', 'damping="3"', "ideal joints"]),
    (dict(joint='stiffness="10"'), ['stiffness="10"']),
])
def test_forces_refuse_what_pinocchio_does_not_model_as_mujoco(tmp_path, capsys, change, words):
    """A mesh's inertia (Pinocchio's parser: 1 kg m^2, 24 times MuJoCo's torque here), a
    compiler mass option, passive joint forces: forces refuse, in one line naming the file
    and the element; kinematics still run."""
    from pinmech.solve.forces import ForceSolver

    path = _pendulum(tmp_path, **change)
    mech = load_mjcf(path)
    LoopSolver(mech, ["hinge"]).solve([0.3], [1.0], [0.0])  # kinematics do not need masses
    with pytest.raises(ModelError) as err:
        ForceSolver(mech, ["hinge"])
    message = str(err.value)
    assert str(path) in message and "\n" not in message
    for word in words:
        assert word in message, message
    scene = tmp_path / "pendulum.toml"
    scene.write_text(f'mjcf = "{path}"\n[drivers.hinge]\nangle = "0 deg"\n')
    assert main(["forces", str(scene)]) == 3
    err_text = capsys.readouterr().err
    assert len(err_text.strip().splitlines()) == 1 and words[0] in err_text


def test_armature_is_in_the_torque_and_the_power_balance(tmp_path):
    """Rotor inertia (armature 0.2 kg m^2) at 2 rad/s and 10 rad/s^2, no gravity: the
    driver torque is MuJoCo's inverse dynamics (rigid body 0.4508 + armature 2 N m), and
    the power balance holds (it left the armature out: residual 0.82). 1e-12: the same
    arithmetic."""
    from pinmech.solve.forces import ForceSolver

    path = _pendulum(tmp_path, joint='armature="0.2"')
    mech = load_mjcf(path)
    sol = LoopSolver(mech, ["hinge"]).solve([0.4], [2.0], [10.0])
    forces = ForceSolver(mech, ["hinge"]).solve(sol.q, sol.v, sol.a)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    m.opt.gravity[:] = 0
    d.qpos[0], d.qvel[0], d.qacc[0] = 0.4, 2.0, 10.0
    mujoco.mj_inverse(m, d)
    assert forces.effort[0] == pytest.approx(d.qfrc_inverse[0], rel=rounding(1.0, forces.condition))
    assert forces.power.residual < rounding(1.0, forces.condition)


def test_forces_that_fail_their_power_balance_are_an_error(tmp_path, monkeypatch, capsys):
    """The guard behind the armature mend: a power balance that leaves a term out (here
    the armature again, patched back out of it) is a BalanceError naming the pose, exit
    13 in one line, never a printed answer."""
    from pinmech.exceptions import BalanceError
    from pinmech.solve.forces import ForceSolver

    original = ForceSolver._power_terms

    def without_armature(self, q, v, a, virtual):
        gravity, loads, kinetic = original(self, q, v, a, virtual)
        return gravity, loads, kinetic - float(virtual @ (self.model.armature * a))

    monkeypatch.setattr(ForceSolver, "_power_terms", without_armature)
    path = _pendulum(tmp_path, joint='armature="0.2"')
    mech = load_mjcf(path)
    sol = LoopSolver(mech, ["hinge"]).solve([0.4], [2.0], [10.0])
    with pytest.raises(BalanceError, match=r"hinge = 22\.9\d* deg.*power balance off by 0\.8"):
        ForceSolver(mech, ["hinge"]).solve(sol.q, sol.v, sol.a)
    scene = tmp_path / "pendulum.toml"
    scene.write_text(f'mjcf = "{path}"\n[drivers.hinge]\nangle = "0.4 rad"\nspeed = "2 rad/s"\n'
                     'acceleration = "10 rad/s^2"\n')
    assert main(["forces", str(scene)]) == 13
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "fail their own check" in err


RUSR = """<mujoco model="rusr"><compiler angle="radian"/>
  <default><geom type="sphere" size="0.01" mass="0.5"/></default>
  <worldbody>
    <body name="crank"><joint name="crank" type="hinge" axis="0 0 1"/><geom/>
      <body name="coupler" pos="0.1 0 0">
        <joint name="u1" type="hinge" axis="0 0 1"/><joint name="u2" type="hinge" axis="0.3 -0.2 0.9"/>
        <geom pos="0.1 0.05 0.03"/><site name="E" pos="0.25 0.12 0.08"/></body></body>
    <body name="rocker" pos="0.3 0.25 -0.05"><joint name="rock" type="hinge" axis="1 0.2 0.1"/>
      <geom pos="0.05 -0.05 0.02"/></body>
  </worldbody>
  <equality><connect name="S" body1="coupler" body2="rocker" anchor="0.25 0.12 0.08"/></equality>
</mujoco>"""


def test_a_fold_followed_through_a_composite_joint_is_a_driver_limit(tmp_path):
    """A spatial RUSR whose universal joint is two hinges in one body (one composite joint
    in Pinocchio). Its crank's limit near -14.44 deg was an AssemblyError naming -14.32 deg:
    near the fold only the composite's hinges move fast enough to follow the curve by, and
    they were not allowed as its parameter. Now the limit is named (DriverLimitError), between
    the crank values where MuJoCo's own equality closes (-14.43 deg) and cannot (-14.44 deg);
    0.006 deg inside it pinmech's pose closes MuJoCo's equality to 1e-12 m."""
    from pinmech.exceptions import DriverLimitError

    path = tmp_path / "rusr.xml"
    path.write_text(RUSR)
    mech = load_mjcf(path)
    solver = LoopSolver(mech, ["crank"])
    solver.set_reference([0.0], mech.neutral())
    with pytest.raises(DriverLimitError) as err:
        solver.solve([np.radians(-20.0)])
    limit = err.value.limit[0]
    assert np.radians(-14.44) < limit < np.radians(-14.43)
    q = solver.solve([limit + 1e-4]).q  # 0.006 deg inside: condition number about 2e3
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    set_qpos(mech, q, m, d)
    eq = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    np.testing.assert_allclose(d.efc_pos[eq], 0.0, atol=residual(1.0))


def test_two_top_level_defaults_both_apply(tmp_path):
    """MuJoCo reads several top-level <default> elements as one class "main": a joint pos
    from the first and a site pos from the second both count (positions at a moved pose
    as MuJoCo's, 1e-12 m)."""
    path = _chain(tmp_path, defaults='<default><joint pos="0 0.1 0"/></default><default><site pos="0.1 0.2 0.3"/>'
                                     '</default>', site="")
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    data = mech.model.createData()
    q = np.array([0.87, -0.4])
    d.qpos[:] = q
    mujoco.mj_forward(m, d)
    pin.framesForwardKinematics(mech.model, data, q)
    for i in range(m.nsite):
        np.testing.assert_allclose(data.oMf[mech.points[m.site(i).name]].translation, d.site_xpos[i], atol=PLACED)
