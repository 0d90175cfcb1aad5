"""Frames of several kinds sharing a name (a joint, a body and a site all called "coupler",
as every MuJoCo Menagerie file names its joints after its bodies): each is looked up by
name and kind, [lock] reduces the model, and points sit where MuJoCo puts them.

The independent source is MuJoCo: at pinmech's solved pose, its kinematics place the sites
(and close the loop: the two ends of the connect meet). Placements are the same arithmetic
on the same numbers, so they agree to 1e-12 m; the loop closes to the solver's 1e-12.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech.cli import main
from pinmech.model.mjcf import load_mjcf
from pinmech.solve.loops import LoopSolver
from tests.tolerance import rounding

mujoco = pytest.importorskip("mujoco")

# The bundled four-bar (40, 120, 80 mm on a 100 mm ground), with a tip arm hinged on the
# coupler: every body, its joint and a site on it share one name.
SHARED = """<mujoco model="shared"><compiler angle="radian"/><worldbody>
  <body name="crank"><joint name="crank" axis="0 0 1"/><geom size="0.004"/><site name="crank" pos="0.02 0 0"/>
    <body name="coupler" pos="0.04 0 0" euler="0 0 0.6341838408240407">
      <joint name="coupler" axis="0 0 1"/><geom size="0.004"/><site name="coupler" pos="0.12 0 0"/>
      <body name="tip" pos="0.06 0 0"><joint name="tip" axis="0 0 1"/><geom size="0.004"/>
        <site name="tip" pos="0.03 0.01 0"/></body>
    </body>
  </body>
  <body name="rocker" pos="0.1 0 0" euler="0 0 1.0946772658831">
    <joint name="rocker" axis="0 0 1"/><geom size="0.004"/><site name="rocker" pos="0.08 0 0"/>
  </body></worldbody>
  <equality><connect name="B" body1="coupler" body2="rocker" anchor="0.12 0 0"/></equality></mujoco>"""


@pytest.fixture
def shared(tmp_path):
    path = tmp_path / "shared.xml"
    path.write_text(SHARED)
    return path


def mujoco_sites(path, mech, q):
    """Site positions MuJoCo computes at pinmech's q (the same joints, in file order)."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    for name in ("crank", "coupler", "tip", "rocker"):
        d.qpos[m.joint(name).qposadr[0]] = (mech.coordinate(q, name) if name in mech.joints
                                            else mech.locked[name])
    mujoco.mj_kinematics(m, d)
    return {m.site(i).name: d.site_xpos[i].copy() for i in range(m.nsite)}


def test_lock_and_points_when_joints_bodies_and_sites_share_names(shared):
    mech = load_mjcf(shared, locked={"tip": 0.4})
    assert sorted(mech.points) == ["coupler", "crank", "rocker", "tip"]
    assert sorted(mech.links)[:4] == ["coupler", "crank", "pinmech_world", "rocker"]
    solver = LoopSolver(mech, ["crank"])
    q = solver.solve([1.0], [0.0], [0.0], guess=mech.neutral()).q
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    theirs = mujoco_sites(shared, mech, q)
    for name in theirs:  # the site, not the body or the joint of that name
        np.testing.assert_allclose(data.oMf[mech.frame_id(name)].translation, theirs[name], atol=rounding(1.0))
    # MuJoCo's own check of the pose: the connect's two ends (sites at B) meet
    np.testing.assert_allclose(theirs["coupler"], theirs["rocker"], atol=rounding(1.0))


def test_a_scene_locks_and_reports_shared_names(shared, tmp_path, capsys):
    scene = tmp_path / "shared.toml"
    scene.write_text('mjcf = "shared.xml"\n[lock]\ntip = "20 deg"\n[drivers.crank]\nangle = "60 deg"\n'
                     '[report]\npoints = ["tip", "coupler"]\nlinks = ["tip", "rocker"]\n')
    assert main(["solve", str(scene)]) == 0
    out = capsys.readouterr().out
    assert "tip" in out and "coupler" in out


def _two_link_arm() -> pin.Model:
    """Two links of 0.1 m turning about z, each with its joint, body and point named alike."""
    model = pin.Model()
    parent, placement = 0, pin.SE3.Identity()
    for name in ("arm", "tip"):
        jid = model.addJoint(parent, pin.JointModelRZ(), placement, name)
        model.addJointFrame(jid)
        model.appendBodyToJoint(jid, pin.Inertia.FromSphere(1.0, 0.01), pin.SE3.Identity())
        body = model.addBodyFrame(name, jid, pin.SE3.Identity(), -1)
        model.addFrame(pin.Frame(name, jid, body, pin.SE3(np.eye(3), np.array([0.1, 0, 0])),
                                 pin.FrameType.OP_FRAME))
        parent, placement = jid, pin.SE3(np.eye(3), np.array([0.1, 0, 0]))
    return model


def test_a_model_built_in_code_with_shared_names_locks_and_reports_its_points():
    from pinmech.model.mechanism import Mechanism

    mech = Mechanism.from_model(_two_link_arm(), locked={"tip": 0.3})
    q = np.array([0.5])
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    assert all(mech.model.frames[fid].type == pin.FrameType.OP_FRAME for fid in mech.points.values())
    # the points by the closed form of a two-link arm: 0.1 (cos a, sin a) and that plus 0.1 (cos(a+t), sin(a+t))
    arm = 0.1 * np.array([np.cos(0.5), np.sin(0.5), 0])
    np.testing.assert_allclose(data.oMf[mech.frame_id("arm")].translation, arm, atol=rounding(0.2))
    np.testing.assert_allclose(data.oMf[mech.frame_id("tip")].translation,
                               arm + 0.1 * np.array([np.cos(0.8), np.sin(0.8), 0]), atol=rounding(0.2))
