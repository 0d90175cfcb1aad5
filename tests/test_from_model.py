"""`Mechanism.from_model`: a pin.Model and Pinocchio constraint models, as built in code.

The bundled four-bar's tree (its URDF without the <constraint>) closed in code by a
constraint at B must move exactly as the URDF's own revolute cut: in the plane both reduce
to the same two rows, so q, v, a agree to rounding (1e-12 on values of order 1 to 50).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinmech import LoopSolver, Mechanism
from pinmech.exceptions import ModelError
from tests.tolerance import closure


@pytest.fixture
def four_bar_tree(models_dir):
    return pin.buildModelFromUrdf(str(models_dir / "four_bar.urdf"))


def _constraints(model, kind: str):
    A, O4 = model.getJointId("A"), model.getJointId("O4")
    at_B = pin.SE3(np.eye(3), np.array([0.12, 0.0, 0.0]))
    on_rocker = pin.SE3(np.eye(3), np.array([0.08, 0.0, 0.0]))
    if kind == "legacy":
        return [pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, A, at_B, O4, on_rocker,
                                         pin.ReferenceFrame.LOCAL)]
    return [pin.PointAnchorConstraintModel(model, A, at_B, O4, on_rocker)]


@pytest.mark.parametrize("kind", ["legacy", "point_anchor"])
def test_constraints_in_code_move_as_the_urdf_cut(models_dir, four_bar_tree, kind):
    nframes = four_bar_tree.nframes
    mech = Mechanism.from_model(four_bar_tree, _constraints(four_bar_tree, kind), names=["B"],
                                source="four_bar in code")
    assert four_bar_tree.nframes == nframes  # the user's model is left alone
    assert mech.mobility == 1 and mech.constraint_rows == 2 and mech.plane_normal is not None
    urdf = Mechanism.from_urdf(models_dir / "four_bar.urdf")
    guess = urdf.neutral()
    urdf.set_coordinate(guess, "A", np.radians(40))
    urdf.set_coordinate(guess, "O4", np.radians(100))
    ours = LoopSolver(mech, ["O2"]).solve([1.0], [12.0], [3.0], guess=guess)
    theirs = LoopSolver(urdf, ["O2"]).solve([1.0], [12.0], [3.0], guess=guess)
    np.testing.assert_allclose(ours.q, theirs.q, atol=closure(np.pi, theirs.accuracy.condition))
    np.testing.assert_allclose(ours.v, theirs.v, atol=closure(np.abs(theirs.v).max(), theirs.accuracy.condition, 1))
    np.testing.assert_allclose(ours.a, theirs.a, atol=1e-10)


def test_frame_anchor_is_a_fixed_cut(four_bar_tree):
    """Welding the rocker to the coupler at B (6 rows, 3 in the plane) leaves a structure."""
    A, O4 = four_bar_tree.getJointId("A"), four_bar_tree.getJointId("O4")
    weld = pin.FrameAnchorConstraintModel(four_bar_tree, A, pin.SE3(np.eye(3), np.array([0.12, 0, 0])), O4,
                                          pin.SE3(np.eye(3), np.array([0.08, 0, 0])))
    mech = Mechanism.from_model(four_bar_tree, [weld])
    assert mech.closures[0].cut_type == "fixed" and mech.closures[0].name == "loop1"
    assert mech.mobility == 0


def test_unknown_constraints_and_bad_joints_are_named(four_bar_tree):
    friction = pin.JointFrictionConstraintModel(four_bar_tree, [1])
    with pytest.raises(ModelError, match="constraint 1 is a JointFrictionConstraintModel"):
        Mechanism.from_model(four_bar_tree, [friction], source="mine")
    contact = pin.RigidConstraintModel(pin.ContactType.CONTACT_UNDEFINED, four_bar_tree, 1, pin.SE3.Identity(),
                                       2, pin.SE3.Identity(), pin.ReferenceFrame.LOCAL)
    with pytest.raises(ModelError, match="CONTACT_3D or CONTACT_6D"):
        Mechanism.from_model(four_bar_tree, [contact])
    with pytest.raises(ModelError, match="share the name"):
        Mechanism.from_model(four_bar_tree, _constraints(four_bar_tree, "legacy") * 2, names=["B", "B"])
