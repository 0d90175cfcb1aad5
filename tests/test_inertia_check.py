"""Impossible masses and inertias are named, wherever they enter; possible ones pass.

Physics is the source: a rotational inertia about the centre of mass is positive
semi-definite and its principal moments satisfy A + B >= C (MuJoCo's compiler refuses a
tensor breaking either, with "inertia must satisfy A + B >= C"). Kinematics do not need
masses, so a URDF's impossible inertia leaves `solve` working and makes `forces` a named
error; an MJCF `<inertial>` MuJoCo refuses is refused when read.

A thin rod (m L^2/12 about two axes, 0 about its own) and a flat plate (A + B = C exactly)
sit on the boundary: printed to six digits they must still pass.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech.cli import main
from pinmech.exceptions import ModelError
from pinmech.solve.forces import ForceSolver
from pinmech.model.inertia_check import inertia_problem
from pinmech.model.mechanism import Mechanism
from pinmech.solve.loops import LoopSolver
from tests.conftest import MODELS, SCENES

ROD = 'ixx="1e-5" iyy="2e-4" izz="2e-4"'  # the crank's line of models/slider_crank_dynamic.urdf
BAD_URDF = {
    "triangle inequality": ('ixx="1e-5" iyy="1e-5" izz="2e-4"', "triangle inequality"),
    "a negative moment": ('ixx="-1e-5" iyy="2e-4" izz="2e-4"', "negative moment"),
    "indefinite off-diagonal": ('ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="2e-4" ixz="0" iyz="0"', "negative moment"),
}


def _scene(tmp_path, inertia: str):
    text = (MODELS / "slider_crank_dynamic.urdf").read_text()
    assert ROD + ' ixy="0" ixz="0" iyz="0"' in text
    (tmp_path / "sc.urdf").write_text(text.replace(ROD + ' ixy="0" ixz="0" iyz="0"', inertia if "ixy" in inertia
                                                   else inertia + ' ixy="0" ixz="0" iyz="0"'))
    scene = tmp_path / "sc.toml"
    scene.write_text((SCENES / "slider_crank_dynamic.toml").read_text().replace(
        'urdf = "../slider_crank_dynamic.urdf"', 'urdf = "sc.urdf"'))
    return scene


@pytest.mark.parametrize("case", sorted(BAD_URDF))
def test_an_impossible_urdf_inertia_refuses_forces_not_kinematics(tmp_path, capsys, case):
    inertia, words = BAD_URDF[case]
    scene = _scene(tmp_path, inertia)
    mech = Mechanism.from_urdf(scene.parent / "sc.urdf")  # kinematics use no mass: they solve
    assert LoopSolver(mech, ["O"]).solve([0.8], guess=mech.neutral()).is_closed()
    assert main(["forces", str(scene)]) == 3
    err = capsys.readouterr().err
    assert words in err and '<link name="crank"> <inertial>' in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_principal_moments_are_named_with_their_numbers():
    """diag(1, 1, 3): 1 + 1 < 3; [[1, 2, 0], [2, 1, 0], [0, 0, 1]] has eigenvalues -1, 1, 3."""
    assert "1 + 1 < 3" in inertia_problem(1.0, np.diag([1.0, 1.0, 3.0]))
    said = inertia_problem(1.0, np.array([[1.0, 2.0, 0], [2.0, 1.0, 0], [0, 0, 1.0]]))
    assert "(-1, 1, 3)" in said and "negative moment" in said


@pytest.mark.parametrize("moments", [
    (0.0, 2.5e-4 / 12, 2.5e-4 / 12),                  # a thin rod, 0.5 kg, 0.5 m... m L^2 / 12
    (1.23457e-05, 2.34568e-05, 3.58025e-05),          # a flat plate printed to six digits (A + B = C + 1e-10)
    (1e-4, 1e-4, 1e-4),                               # a sphere
])
def test_possible_inertias_pass(moments):
    assert inertia_problem(0.5, np.diag(moments)) is None


def test_a_model_built_in_code_with_an_impossible_inertia_refuses_forces():
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "hinge")
    model.addJointFrame(jid)
    model.appendBodyToJoint(jid, pin.Inertia(1.0, np.array([0.1, 0, 0]), np.diag([1e-3, 1e-3, 3e-3])),
                            pin.SE3.Identity())
    model.addBodyFrame("bar", jid, pin.SE3.Identity(), -1)
    mech = Mechanism.from_model(model)
    with pytest.raises(ModelError, match=r"body bar .*triangle inequality: 0.001 \+ 0.001 < 0.003"):
        ForceSolver(mech, ["hinge"])


MJCF_BODY = ('<mujoco><worldbody><body name="bar"><joint name="h"/><inertial pos="0 0 0" mass="1" {inertial}/>'
             '</body></worldbody></mujoco>')


@pytest.mark.parametrize("inertial, words", [
    ('diaginertia="1 1 3"', "triangle inequality"),
    ('diaginertia="-1 1 1"', "negative moment"),
    ('fullinertia="1 1 1 2 0 0"', "negative moment"),
    ('mass="-1" diaginertia="1 1 1"', "mass of -1 kg"),
])
def test_an_mjcf_inertia_mujoco_refuses_is_refused(tmp_path, inertial, words):
    mujoco = pytest.importorskip("mujoco")
    text = MJCF_BODY.format(inertial=inertial).replace('mass="1" mass="-1"', 'mass="-1"')
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
    path = tmp_path / "bar.xml"
    path.write_text(text)
    from pinmech.model.mjcf import load_mjcf

    with pytest.raises(ModelError, match=words) as error:
        load_mjcf(path)
    assert '<body name="bar"> <inertial>' in str(error.value)
