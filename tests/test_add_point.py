"""`Mechanism.add_point`: a point is where it is asked, on the link asked, or a named error.

The four-bar of models/four_bar.urdf (crank 40 mm, coupler 120, rocker 80, ground 100);
references from the closed-form four-bar (Norton, Design of Machinery, §4.5), derived apart
from Pinocchio. Tolerance: loops closed to 1e-13 of a 0.1 m mechanism, so 1e-12 m.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from closed_form import four_bar

import pinmech
from pinmech import FrameNotFound, LoopSolver, Mechanism, ModelError
from tests.conftest import MODELS
from tests.tolerance import REGULAR, closure

PLACE_TOL_M = closure(0.1, REGULAR)


def test_a_second_point_of_one_name_is_refused():
    """Pinocchio's addFrame hands back the existing frame for a repeated name: a point 'Q' asked
    on the rocker was the crank's 'Q' in silence."""
    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    mech.add_point("Q", "crank", [0.01, 0.0, 0.0])
    with pytest.raises(ModelError, match="already has a point called 'Q'"):
        mech.add_point("Q", "rocker", [0.02, 0.0, 0.0])
    with pytest.raises(ModelError, match="already has a point called 'P'"):  # the URDF's own coupler point
        mech.add_point("P", "crank", [0.01, 0.0, 0.0])
    with pytest.raises(ModelError, match="already has a link called 'coupler'"):
        mech.add_point("coupler", "crank", [0.01, 0.0, 0.0])


@pytest.mark.parametrize("xyz", [[math.nan, 0, 0], [0, 0], [1j, 0, 0], "abc", None, [math.inf, 0, 0]])
def test_coordinates_that_are_no_point_are_refused(xyz):
    """NaN gave a point at NaN in silence; the rest leaked ArgumentError, TypeError, ValueError."""
    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    with pytest.raises(ModelError, match="coordinates of point 'Z'"):
        mech.add_point("Z", "coupler", xyz)


@pytest.mark.parametrize("name, link, error", [(None, "crank", ModelError), (3, "crank", ModelError),
                                               ("Z", "shaft", FrameNotFound), ("Z", ["crank"], FrameNotFound)])
def test_a_name_or_link_that_is_no_name_is_refused(name, link, error):
    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    with pytest.raises(error):
        mech.add_point(name, link, [0.0, 0.0, 0.0])


def test_a_point_on_the_rocker_is_where_the_closed_form_puts_it():
    """A point 20 mm along the rocker from O4, at crank 30 deg: O4 + 20 mm (cos, sin) theta4."""
    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    fid = mech.add_point("R", "rocker", [0.02, 0.0, 0.0])
    q = LoopSolver(mech, drivers=["O2"]).solve([math.radians(30)]).q
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    fb = four_bar(np.radians([30.0]), 0.0, 0.0, 0.04, 0.12, 0.08, 0.10)
    expected = [0.10 + 0.02 * math.cos(fb.theta4[0]), 0.02 * math.sin(fb.theta4[0]), 0.0]
    np.testing.assert_allclose(data.oMf[fid].translation, expected, rtol=0, atol=PLACE_TOL_M)


@pytest.mark.parametrize("call", [
    lambda m: Mechanism.from_urdf(MODELS / "four_bar.urdf", locked={"O2": 10**400}),   # OverflowError
    lambda m: Mechanism.from_urdf(MODELS / "four_bar.urdf", locked={3: 0.1}),          # ArgumentError
    lambda m: m.joint(["O2"]),                                                         # TypeError: unhashable
    lambda m: m.frame_id({"P": 1}),
    lambda m: pinmech.ForceSolver(m, 0.5),                                             # TypeError: not iterable
    lambda m: pinmech.RateSolver(m, "P"),                                              # AttributeError
    lambda m: pinmech.RateSolver(m, [1, 2]),
])
def test_hostile_arguments_end_in_a_named_error(call):
    """Only a PinmechError with a message leaves pinmech (README, Errors and exit codes)."""
    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    with pytest.raises(pinmech.PinmechError) as caught:
        call(mech)
    assert str(caught.value).strip()
