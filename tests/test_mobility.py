"""Mobility from the rank of the closure rows on closed poses, and idle freedoms named.

Expected mobilities are Gruebler-Kutzbach counts corrected by hand for the special
geometry (a parallelogram's third crank adds a loop that removes nothing): independent
of the code, which takes singular values of the constraint Jacobian.
"""

from __future__ import annotations

import numpy as np
import pytest

from pinmech import LoopSolver, Mechanism, Scene, analyse
from pinmech.cli import main
from pinmech.exceptions import ModelError
from pinmech.model.linkage_model import load_linkage

from ._mechanisms import four_bar_urdf, write
from tests.tolerance import rounding

DOUBLE_PARALLELOGRAM = """ground = ["O1", "O2", "O3"]
[joints]
O1 = ["0 mm", "0 mm"]
O2 = ["50 mm", "0 mm"]
O3 = ["100 mm", "0 mm"]
A1 = ["0 mm", "40 mm"]
A2 = ["50 mm", "40 mm"]
A3 = ["100 mm", "40 mm"]
[links]
crank1 = ["O1", "A1"]
crank2 = ["O2", "A2"]
crank3 = ["O3", "A3"]
coupler = ["A1", "A2", "A3"]
"""


def test_double_parallelogram_has_mobility_one_and_is_refused_by_name(tmp_path):
    path = tmp_path / "dp.toml"
    path.write_text(DOUBLE_PARALLELOGRAM)
    mech = load_linkage(path)  # it loads (forces can use it), but the loop solver cannot:
    assert mech.model.nv - mech.rank_report().rank == 1
    with pytest.raises(ModelError) as err:
        LoopSolver(mech, ["O1"])
    message = str(err.value)
    # 4 pins in the tree, 2 cuts of 2 rows: rows say 0, the rank (3) says 1
    assert "mobility is 1, not 0" in message and "rank 3" in message and str(path) in message


def test_a_skewed_third_crank_is_a_structure(tmp_path):
    """Move O3 by 10 mm: no longer a parallelogram, rows are independent and mobility is 0."""
    path = tmp_path / "s.toml"
    path.write_text(DOUBLE_PARALLELOGRAM.replace('O3 = ["100 mm", "0 mm"]', 'O3 = ["110 mm", "0 mm"]'))
    mech = load_linkage(path)
    assert mech.mobility == 0 and mech.constraint_rows == 4 and mech.model.nv == 4


def test_a_locking_spherical_cut_does_not_make_mobility_negative(tmp_path):
    """A spherical cut at B repeating the revolute cut B: rows say -1, the truth is 1."""
    text = four_bar_urdf().replace("</robot>", """<constraint name="B_again" type="spherical">
    <parent link="coupler"/> <parent_origin xyz="0.12 0 0"/> <child link="rocker"/> <child_origin xyz="0.08 0 0"/>
  </constraint></robot>""")
    path = write(tmp_path, "fb.urdf", text)
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{path}"\n[drivers.O2]\nangle = "10 deg"\n')
    assert main(["solve", str(scene)]) == 3
    with pytest.raises(ModelError, match=r"B, B_again.*mobility is 1, not -1"):
        _ = Mechanism.from_urdf(path).mobility


def test_mobility_of_plain_loops_is_unchanged(models_dir):
    for name, mobility in (("four_bar", 1), ("slider_crank", 1), ("r_rtr", 1), ("planar_arm", 3)):
        mech = Mechanism.from_urdf(models_dir / f"{name}.urdf")
        assert mech.mobility == mobility, name
        assert mech.rank_report().rank == mech.constraint_rows


RSSR = """<?xml version="1.0"?>
<robot name="rssr">
  <link name="ground"/>
  <link name="crank"/><link name="ball1"/><link name="ball2"/><link name="rod"/><link name="rocker"/>
  <joint name="O2" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/></joint>
  <joint name="rod_x" type="continuous"><parent link="crank"/><child link="ball1"/><origin xyz="0.05 0 0"/><axis xyz="1 0 0"/></joint>
  <joint name="rod_y" type="continuous"><parent link="ball1"/><child link="ball2"/><axis xyz="0 1 0"/></joint>
  <joint name="rod_z" type="continuous"><parent link="ball2"/><child link="rod"/><axis xyz="0 0 1"/></joint>
  <joint name="O4" type="continuous"><parent link="ground"/><child link="rocker"/><origin xyz="0.1 0 0"/><axis xyz="0 1 0"/></joint>
  <constraint name="B" type="spherical">
    <parent link="rod"/> <parent_origin xyz="0.05 0 0.08"/> <child link="rocker"/> <child_origin xyz="0 0 0.08"/>
  </constraint>
</robot>
"""


def test_a_spinning_rod_is_named_with_the_advice_to_lock_it(tmp_path, capsys):
    """RSSR with a ball at each end of the rod: 5 freedoms - 3 rows = 2, the rod's spin idle."""
    urdf = write(tmp_path, "rssr.urdf", RSSR)
    mech = Mechanism.from_urdf(urdf)
    assert mech.mobility == 2
    idle = mech.idle_joints(["O2"])
    assert len(idle) == 1 and idle[0] in ("rod_x", "rod_y", "rod_z")
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{urdf}"\n[drivers.O2]\nangle = "10 deg"\n')
    assert main(["solve", str(scene)]) == 5
    err = capsys.readouterr().err
    assert idle[0] in err and "lock it" in err and "mobility 2" in err
    # locking the named joint leaves one freedom: the crank drives the rocker
    scene.write_text(f'urdf = "{urdf}"\n[drivers.O2]\nangle = "10 deg"\n[lock]\n{idle[0]} = "0 deg"\n')
    assert main(["solve", str(scene)]) == 0


def test_a_one_joint_urdf_loads_and_solves(tmp_path, capsys):
    """Pinocchio returns a (6,) Jacobian for a one-dof model: main crashed with LinAlgError."""
    urdf = write(tmp_path, "one.urdf", """<robot name="one"><link name="base"/>
      <link name="arm"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
      <link name="tip"/><joint name="point_tip" type="fixed"><parent link="arm"/><child link="tip"/>
      <origin xyz="0.1 0 0"/></joint></robot>""")
    mech = Mechanism.from_urdf(urdf)
    assert mech.mobility == 1 and list(mech.plane_normal) == [0.0, 0.0, 1.0]
    scene = tmp_path / "one.toml"
    scene.write_text(f'urdf = "{urdf}"\n[drivers.j]\nangle = "90 deg"\n')
    assert main(["solve", str(scene)]) == 0
    tip = analyse(Scene.load(scene)).motion.points["tip"].position
    np.testing.assert_allclose(tip, [0.0, 0.1, 0.0], atol=rounding(0.1))  # 0.1 m arm at 90 deg
