"""MJCF files read as MuJoCo's compiler reads them: a differential test against MuJoCo.

Each small file below turns or nests bodies and sites in one of the ways MJCF allows
(nested bodies without joints, pos/quat/euler/axisangle/xyaxes/zaxis on bodies and sites,
default classes, joint `ref`, the compiler's angle unit). MuJoCo (mj_kinematics) is the
independent source: at several joint positions (MuJoCo's qpos, `ref` included), every site
must sit where MuJoCo puts it, turned as MuJoCo turns it. Both are the same products of the
same rotations in double precision, so they agree to 1e-12 m (and 1e-12 in the rotation
matrices); a dropped offset or a misread angle is off by millimetres or degrees.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinmech.exceptions import ModelError
from pinmech.model.mjcf import load_mjcf
from tests.tolerance import residual, rounding

mujoco = pytest.importorskip("mujoco")
MJCF_DIR = Path(__file__).resolve().parents[1] / "models" / "mjcf"


def _nested(n: int) -> str:
    """A hinge body with a site n jointless bodies below it, each 1 mm further along x."""
    inner = '<site name="tip"/>'
    for i in range(n):
        inner = f'<body name="b{i}" pos="0.001 0 0">{inner}</body>'
    return (f'<mujoco><compiler angle="radian"/><worldbody><body name="arm" pos="0 0 0.1">'
            f'<joint name="h" axis="0 0 1"/><geom size="0.01"/>{inner}</body></worldbody></mujoco>')


TURNED = """<mujoco>{compiler}{defaults}<worldbody>
  <body name="base" pos="0.05 0.02 0.3" {base_turn}><geom size="0.01"/>
    <body name="mount" pos="0 0.04 0" {mount_turn}>
      <body name="arm" pos="0.02 0 0" {arm_turn}><joint name="h1" {h1}/><geom size="0.01"/>
        <body name="plate" pos="0.1 0 0" {plate_turn}>
          <body name="bracket" pos="0 0.03 0.01" {bracket_turn}><site name="s1" pos="0.01 0.02 0.03" {site_turn}/>
            <body name="fore" pos="0.05 0 0"><joint name="h2" {h2}/><geom size="0.01"/>
              <site name="s2" pos="0.08 0 0" {site_turn}/>
              <body name="slider"><joint name="p" type="slide" {p}/><geom size="0.01"/>
                <site name="s3" pos="0.02 0.01 0"/></body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </body></worldbody></mujoco>"""
PLAIN = dict(compiler='<compiler angle="radian"/>', defaults="", base_turn="", mount_turn="", arm_turn="",
             plate_turn="", bracket_turn="", site_turn="", h1='axis="0 0 1"', h2='axis="0 1 0"', p='axis="1 0 0"')
CASES = {
    "nested 2": _nested(2), "nested 3": _nested(3), "nested 50": _nested(50),
    "plain nesting": PLAIN,
    "quat, unnormalised": dict(mount_turn='quat="2 0.3 -0.4 0.5"', plate_turn='quat="1 1 0 0"',
                               site_turn='quat="0.3 0.1 0.2 0.9"'),
    "axisangle, degrees": dict(compiler="", base_turn='axisangle="0.3 0.5 0.8 40"', bracket_turn='axisangle="1 0 0 -30"',
                               site_turn='axisangle="0 2 1 75"'),
    "axisangle, radians": dict(mount_turn='axisangle="0.3 -0.5 0.8 0.7"', site_turn='axisangle="1 1 1 1"'),
    "xyaxes, not orthogonal": dict(plate_turn='xyaxes="1 1 0 -1 1 0.3"', bracket_turn='xyaxes="0 2 0 -3 1 1"',
                                   site_turn='xyaxes="1 0 0.2 0.3 1 0"'),
    "zaxis": dict(mount_turn='zaxis="0.2 0.4 1"', bracket_turn='zaxis="0 0 -1"', site_turn='zaxis="1 -1 0.1"'),
    "euler, degrees": dict(compiler="", base_turn='euler="10 20 30"', plate_turn='euler="-40 5 90"',
                           site_turn='euler="0 45 0"'),
    "euler XYZ, radians": dict(compiler='<compiler angle="radian" eulerseq="XYZ"/>', mount_turn='euler="0.1 0.2 0.3"',
                               site_turn='euler="0.5 -0.2 1"'),
    "joint ref, degrees": dict(compiler="", arm_turn='euler="0 0 30"', h1='axis="0 0 1" ref="30"',
                               h2='axis="0 1 0" ref="-45"', p='axis="1 0 0" ref="0.02"'),
    "joint ref, radians": dict(h1='axis="0 0 1" ref="0.5"', h2='axis="1 1 0" ref="1.2"', p='axis="0 1 0" ref="-0.03"'),
    "joint pos and axis from defaults": dict(
        defaults='<default><joint axis="0 1 1" pos="0.01 0 0.02"/><default class="k"><site quat="0.9 0.1 0.3 0.2"/>'
                 '</default></default>', h1="", h2='pos="0 0.01 0"', site_turn='class="k"'),
    "every form at once": dict(compiler="", base_turn='quat="0.5 0.5 0.5 0.5"', mount_turn='euler="0 90 0"',
                               arm_turn='axisangle="0 0 1 -60"', plate_turn='xyaxes="0 1 0 0 0 1"',
                               bracket_turn='zaxis="1 1 1"', h1='axis="1 0 1" ref="20"'),
}


def _xml(case) -> str:
    return case if isinstance(case, str) else TURNED.format(**(PLAIN | case))


def _poses(m, count: int = 4) -> list[dict[str, float]]:
    """MuJoCo's qpos0 and a few seeded poses around it (hinges about a radian, slides 5 cm)."""
    rng = np.random.default_rng(7)
    out = []
    for k in range(count):
        pose = {}
        for j in range(m.njnt):
            scale = 1.2 if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE else 0.05
            pose[m.joint(j).name] = float(m.qpos0[m.jnt_qposadr[j]]) + (k > 0) * scale * rng.uniform(-1, 1)
        out.append(pose)
    return out


@pytest.mark.parametrize("case", sorted(CASES))
def test_sites_sit_and_turn_where_mujoco_puts_them(tmp_path, case):
    path = tmp_path / "model.xml"
    path.write_text(_xml(CASES[case]))
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    data = mech.model.createData()
    for pose in _poses(m):
        q = mech.neutral()
        for name, value in pose.items():
            d.qpos[m.joint(name).qposadr[0]] = value
            mech.set_coordinate(q, name, value)  # pinmech's coordinate is MuJoCo's qpos, ref included
        mujoco.mj_kinematics(m, d)
        pin.framesForwardKinematics(mech.model, data, q)
        for i in range(m.nsite):
            frame = data.oMf[mech.points[m.site(i).name]]
            np.testing.assert_allclose(frame.translation, d.site_xpos[i], atol=rounding(1.0))
            np.testing.assert_allclose(frame.rotation, d.site_xmat[i].reshape(3, 3), atol=rounding(1.0))


def test_qpos0_is_the_reference_with_ref_included(tmp_path):
    path = tmp_path / "model.xml"
    path.write_text(_xml(CASES["joint ref, degrees"]))
    m = mujoco.MjModel.from_xml_path(str(path))
    mech = load_mjcf(path)
    for j in range(m.njnt):  # ref = 30 deg, -45 deg, 0.02 m: MuJoCo's qpos0 in rad and m
        np.testing.assert_allclose(mech.coordinate(mech.neutral(), m.joint(j).name), m.qpos0[m.jnt_qposadr[j]],
                                   atol=rounding(np.pi))


def test_nested_jointless_bodies_keep_mujocos_mass_and_centre(tmp_path):
    """The mass and centre of mass the hinge carries are MuJoCo's subtree mass and centre."""
    text = _nested(3).replace('<site name="tip"/>', '<site name="tip"/><geom type="sphere" size="0.005" pos="0.01 0 0"/>')
    path = tmp_path / "model.xml"
    path.write_text(text)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mech = load_mjcf(path)
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, mech.neutral())
    inertia = mech.model.inertias[mech.joints["h"].id]
    arm = m.body("arm").id
    np.testing.assert_allclose(inertia.mass, m.body_subtreemass[arm], rtol=rounding(1.0))
    np.testing.assert_allclose(data.oMi[mech.joints["h"].id].act(inertia.lever), d.subtree_com[arm], atol=rounding(1.0))


def test_a_connect_on_jointless_bodies_closes_where_mujoco_closes_it(tmp_path):
    """The four-bar's loop named on jointless end bodies of the coupler and the rocker: at
    pinmech's poses MuJoCo's own connect residual is zero (1e-13 m: the loop solver's
    tolerance on a 0.1 m loop), and the pose has moved from qpos0."""
    from pinmech.solve.loops import LoopSolver

    text = (MJCF_DIR / "four_bar.xml").read_text()
    text = text.replace('<site name="P" pos="0.06 0.03 0"/>', '<site name="P" pos="0.06 0.03 0"/><body name="end" '
                        'pos="0.1 0 0"><body name="tip" pos="0.01 0 0"/></body>')
    text = text.replace('<geom type="capsule" fromto="0 0 0 0.08 0 0" size="0.004" rgba="0.15 0.65 0.25 1"/>',
                        '<geom type="capsule" fromto="0 0 0 0.08 0 0" size="0.004"/><body name="stub" pos="0.05 0 0"/>')
    text = text.replace('body1="coupler" body2="rocker" anchor="0.12 0 0"', 'body1="tip" body2="stub" anchor="0.01 0 0"')
    path = tmp_path / "four_bar_ends.xml"
    path.write_text(text)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    solver = LoopSolver(mech, ["O2"])
    q = mech.neutral()
    for value in (0.3, 0.8, 1.4):
        q = solver.solve([value], [0.0], [0.0], guess=q).q
        for name in ("O2", "A", "O4"):
            d.qpos[m.joint(name).qposadr[0]] = mech.coordinate(q, name)
        mujoco.mj_forward(m, d)
        rows = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        assert abs(d.qpos[m.joint("O4").qposadr[0]] - m.qpos0[m.joint("O4").qposadr[0]]) > 0.01
        np.testing.assert_allclose(d.efc_pos[rows], 0.0, atol=residual(1.0))


# ---------------------------------------------------------------- what MuJoCo refuses, pinmech refuses
ARM = ('<mujoco><compiler {compiler}/><worldbody><body name="arm" {body}><joint name="h" {joint}/><geom size="0.01"/>'
       '<site name="s" {site}/></body><body name="b"><joint name="k"/><geom size="0.01"/></body></worldbody>'
       '<equality><connect name="c" body1="b" anchor="0 0 0" {connect}/></equality></mujoco>')
ARM_PLAIN = dict(compiler='angle="radian"', body="", joint="", site="", connect="")
REFUSED = {
    "parallel xyaxes": (dict(body='xyaxes="1 0 0 2 0 0"'), "parallel"),
    "zero quat": (dict(body='quat="0 0 0 0"'), "zero quaternion"),
    "zero zaxis": (dict(site='zaxis="0 0 0"'), "no length"),
    "zero axisangle axis": (dict(body='axisangle="0 0 0 1"'), "no length"),
    "angle DEGREE": (dict(compiler='angle="DEGREE"'), "DEGREE"),
    "active 0": (dict(connect='active="0"'), 'active="0"'),
    "euler and quat": (dict(body='euler="0 0 1" quat="1 0 0 0"'), "both orient"),
    "site pos and fromto": (dict(site='type="capsule" size="0.01" pos="1 0 0" fromto="0 0 0 1 0 0"'), "fromto"),
    "joint type Hinge": (dict(joint='type="Hinge"'), "Hinge"),
    "coordinate global": (dict(compiler='angle="radian" coordinate="global"'), "global"),
    "ball range from 10": (dict(joint='type="ball" range="0.1 0.5"'), "0 max"),
    "range without limited, autolimits off": (dict(compiler='angle="radian" autolimits="false"',
                                                   joint='range="0 1"'), "autolimits"),
    # repeated names: [drivers.k] or a point named s would pick one of two in silence
    "repeated joint name": (dict(joint='/><joint name="k"'), "repeated name 'k'"),
    "repeated site name": (dict(site='/><site name="s" pos="0.1 0 0"'), "repeated name 's'"),
    "repeated body name": (dict(body='><body name="b"/'), "repeated name 'b'"),
    "ball followed by a hinge": (dict(joint='type="ball"/><joint name="h2"'), "ball joint followed"),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_what_mujoco_refuses_is_refused_naming_the_element(tmp_path, case):
    change, words = REFUSED[case]
    text = ARM.format(**(ARM_PLAIN | change))
    with pytest.raises(ValueError):  # MuJoCo's compiler refuses the file
        mujoco.MjModel.from_xml_string(text)
    path = tmp_path / "arm.xml"
    path.write_text(text)
    with pytest.raises(ModelError, match=words) as error:
        load_mjcf(path)
    assert str(path) in str(error.value) and "\n" not in str(error.value)


def test_nesting_deeper_than_mujoco_reads_is_refused(tmp_path):
    inner = '<site name="tip"/>'
    for i in range(1100):
        inner = f'<body name="b{i}" pos="0.001 0 0"><joint name="j{i}"/><geom size="0.001"/>{inner}</body>'
    text = f"<mujoco><worldbody>{inner}</worldbody></mujoco>"
    with pytest.raises(ValueError, match="too deep"):
        mujoco.MjModel.from_xml_string(text)
    path = tmp_path / "deep.xml"
    path.write_text(text)
    with pytest.raises(ModelError, match="too deep"):
        load_mjcf(path)


# ---------------------------------------------------------------- several joints in one body (a composite)
COMPOSITE = """<mujoco><compiler angle="{angle}"/><worldbody>
  <body name="arm" pos="0.1 0 0.02" euler="{turn}"><geom size="0.01"/>{joints}
    <site name="s" pos="0.1 0.05 0.02" euler="{turn}"/>
    <body name="fore" pos="0.1 0 0"><joint name="k" axis="0 1 0" ref="{ref}"/><geom size="0.01"/>
      <site name="tip" pos="0.05 0 0.01"/></body>
  </body></worldbody></mujoco>"""
COMPOSITE_CASES = {
    "hinge with ref, then a hinge": dict(angle="degree", turn="10 20 30", ref="15", joints=(
        '<joint name="a" axis="0 0 1" pos="0.01 0.02 0" ref="30"/><joint name="b" axis="1 0 0"/>')),
    "slide with ref, then a hinge": dict(angle="radian", turn="0.1 0.2 0.3", ref="0", joints=(
        '<joint name="a" type="slide" axis="1 1 0" ref="0.02"/><joint name="b" axis="0 0 1" ref="0.4"/>')),
    "three joints, every ref": dict(angle="radian", turn="0 0 0", ref="-0.3", joints=(
        '<joint name="a" axis="1 0 1" ref="-0.7"/><joint name="b" type="slide" axis="0 1 0" ref="0.01"/>'
        '<joint name="c" axis="0 0 1" pos="0 0.01 0" ref="1.1"/>')),
}


def _composite_q(mech, m, qpos: np.ndarray) -> np.ndarray:
    """Pinocchio's q of MuJoCo's qpos: a body's joints are the parts of `Composite_<first>`, in
    file order (a hinge or slide is one coordinate in both)."""
    q = mech.neutral()
    for j in range(m.njnt):
        body = m.jnt_bodyid[j]
        first = m.body_jntadr[body]
        name = m.joint(j).name if m.body_jntnum[body] == 1 else f"Composite_{m.joint(first).name}"
        q[mech.model.joints[mech.model.getJointId(name)].idx_q + (j - first)] = qpos[m.jnt_qposadr[j]]
    return q


@pytest.mark.parametrize("case", sorted(COMPOSITE_CASES))
def test_a_composites_sites_sit_where_mujoco_puts_them_ref_included(tmp_path, case):
    """MuJoCo draws a body at qpos0 (every `ref`) where the file places it; Pinocchio's parser
    left the first joint's `ref` of a composite in the placement (a site 0.02 m off at qpos0)."""
    path = tmp_path / "model.xml"
    path.write_text(COMPOSITE.format(**COMPOSITE_CASES[case]))
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    data = mech.model.createData()
    np.testing.assert_allclose(mech.neutral(), _composite_q(mech, m, m.qpos0), atol=rounding(np.pi))  # qpos0 is the reference
    rng = np.random.default_rng(3)
    for k in range(4):
        d.qpos[:] = m.qpos0 + (k > 0) * rng.uniform(-0.8, 0.8, m.nq)
        mujoco.mj_kinematics(m, d)
        pin.framesForwardKinematics(mech.model, data, _composite_q(mech, m, d.qpos))
        for i in range(m.nsite):  # same products of rotations in double precision: 1e-12
            frame = data.oMf[mech.points[m.site(i).name]]
            np.testing.assert_allclose(frame.translation, d.site_xpos[i], atol=rounding(1.0))
            np.testing.assert_allclose(frame.rotation, d.site_xmat[i].reshape(3, 3), atol=rounding(1.0))


def test_a_loop_on_a_composite_with_ref_closes_where_mujoco_closes_it(tmp_path):
    """The leg's rod (pitch and roll hinges in one body) given `ref`s, its connect anchored in
    the rod: at the poses pinmech solves, MuJoCo's own connect residual is zero (1e-13 m: the
    loop solver's tolerance on a 0.5 m leg). The parser had taken the rod's side of the cut
    from the rod turned by its first `ref` (MuJoCo's residual 1-3 mm)."""
    from pinmech.solve.loops import LoopSolver

    text = (MJCF_DIR / "leg.xml").read_text()
    text = text.replace('name="rod_pitch" type="hinge" axis="0 1 0"', 'name="rod_pitch" type="hinge" axis="0 1 0" ref="0.3"')
    text = text.replace('name="rod_roll" type="hinge" axis="1 0 0"', 'name="rod_roll" type="hinge" axis="1 0 0" ref="0.2"')
    path = tmp_path / "leg_ref.xml"
    path.write_text(text)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    solver = LoopSolver(mech, ["hip"])
    q = mech.neutral()
    for value in (0.02, 0.04, 0.06):
        q = solver.solve([value], [0.0], [0.0], guess=q).q
        d.qpos[:] = [q[mech.model.joints[mech.model.getJointId(n)].idx_q] for n in ("hip", "knee")] + list(
            q[mech.model.joints[mech.model.getJointId("Composite_rod_pitch")].idx_q:][:2])
        mujoco.mj_forward(m, d)
        rows = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        assert abs(d.qpos[m.joint("knee").qposadr[0]]) > 0.01  # the leg has moved from qpos0
        np.testing.assert_allclose(d.efc_pos[rows], 0.0, atol=residual(1.0))


def test_sites_that_never_move_are_points_where_mujoco_puts_them(tmp_path):
    """A site of <worldbody> itself and one on jointless bodies hung from the world: Pinocchio's
    parser dropped both (a scene naming them was told "unknown point"); they are points that
    stay where MuJoCo puts them (1e-12 m: the same products of rotations)."""
    path = tmp_path / "model.xml"
    path.write_text('<mujoco><compiler angle="degree"/><worldbody><site name="mark" pos="0.3 0 0.1" euler="0 0 30"/>'
                    '<body name="base" pos="0 0.02 0.1" euler="10 0 45"><geom size="0.01"/>'
                    '<body name="plate" pos="0.05 0 0" axisangle="0 1 0 20"><site name="corner" pos="0.01 0.02 0"/>'
                    '</body><body name="arm"><joint name="h" axis="0 0 1"/><geom size="0.01"/>'
                    '<site name="tip" pos="0.1 0 0"/></body></body></worldbody></mujoco>')
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mech = load_mjcf(path)
    data = mech.model.createData()
    for value in (0.0, 0.7):
        d.qpos[0] = value
        mujoco.mj_kinematics(m, d)
        q = mech.neutral()
        mech.set_coordinate(q, "h", value)
        pin.framesForwardKinematics(mech.model, data, q)
        for name in ("mark", "corner", "tip"):
            frame = data.oMf[mech.points[name]]
            np.testing.assert_allclose(frame.translation, d.site(name).xpos, atol=rounding(1.0))
            np.testing.assert_allclose(frame.rotation, d.site(name).xmat.reshape(3, 3), atol=rounding(1.0))


def test_a_body_with_joints_but_no_name_is_named_as_the_cause(tmp_path):
    """MuJoCo takes it; Pinocchio's parser leaves its joints out. The error said only that the
    file's joints have 1 freedom and the model 0; it now says which body and what to do."""
    text = ('<mujoco><worldbody><body><joint name="h" axis="0 0 1"/><geom size="0.01"/><site name="tip" '
            'pos="0.1 0 0"/></body></worldbody></mujoco>')
    mujoco.MjModel.from_xml_string(text)  # MuJoCo's compiler takes it
    path = tmp_path / "arm.xml"
    path.write_text(text)
    with pytest.raises(ModelError, match='<joint name="h">.*has no name'):
        load_mjcf(path)
