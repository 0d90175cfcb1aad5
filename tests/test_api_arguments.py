"""Hostile arguments to the public Python API: NaN, infinities, 1e308, subnormals, an int
beyond float64, complex, bool, None, strings, dicts, wrong shapes. Whatever the call, only
a PinmechError (with a message) leaves pinmech: never numpy's ValueError, a TypeError, an
OverflowError, an IndexError or an internal class (issue 22 item 13)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pinmech
from pinmech import LoopSolver, Mechanism
from pinmech.solve.cycle import solve_range
from pinmech.io.sweep import DriverValues
from tests.conftest import MODELS

HOSTILE = [float("nan"), float("inf"), -float("inf"), 1e308, -1e308, 5e-324, 10**400, 1j, True, None, "x", "30 deg",
           [], [1.0, 2.0], [[1.0]], [float("nan")], np.array([np.nan]), np.zeros((2, 2)), {"O2": "a"}, {"nope": 1.0},
           object()]


def _four_bar() -> Mechanism:
    return Mechanism.from_urdf(MODELS / "four_bar.urdf")


def _range(h, what):
    args = {"driver": "O2", "values": [1.0], "driver_q": np.zeros(1), "driver_v": np.ones(1), "driver_a": np.zeros(1)}
    args[what] = h
    return list(solve_range(LoopSolver(_four_bar(), ["O2"]), args.pop("driver"), args.pop("values"), **args))


CALLS = {
    "LoopSolver tol": lambda h: LoopSolver(_four_bar(), ["O2"], tol=h),
    "LoopSolver max_iterations": lambda h: LoopSolver(_four_bar(), ["O2"], max_iterations=h),
    "LoopSolver max_condition": lambda h: LoopSolver(_four_bar(), ["O2"], max_condition=h),
    "LoopSolver drivers": lambda h: LoopSolver(_four_bar(), h),
    "solve driver_q": lambda h: LoopSolver(_four_bar(), ["O2"]).solve(h),
    "solve [driver_q]": lambda h: LoopSolver(_four_bar(), ["O2"]).solve([h]),
    "solve driver_v": lambda h: LoopSolver(_four_bar(), ["O2"]).solve([1.0], [h]),
    "solve driver_a": lambda h: LoopSolver(_four_bar(), ["O2"]).solve([1.0], [1.0], h),
    "solve guess": lambda h: LoopSolver(_four_bar(), ["O2"]).solve([1.0], guess=h),
    "set_reference guess": lambda h: LoopSolver(_four_bar(), ["O2"]).set_reference([1.0], h),
    "rates q": lambda h: LoopSolver(_four_bar(), ["O2"]).rates(h, [1.0], [0.0]),
    "to_si value": lambda h: pinmech.to_si(h, "angle"),
    "to_si kind": lambda h: pinmech.to_si("1 deg", h),
    "evaluate_motion q": lambda h: pinmech.evaluate_motion(_four_bar(), _four_bar().model.createData(), h, h, h),
    "solve_range values": lambda h: _range(h, "values"),
    "solve_range [values]": lambda h: _range([h], "values"),
    "solve_range driver": lambda h: _range(h, "driver"),
    "solve_range driver_q": lambda h: _range(h, "driver_q"),
    "solve_range chunk": lambda h: _range(h, "chunk"),
    "solve_range interpolate": lambda h: _range(h, "interpolate"),
    "BatchSolver.try_solve": lambda h: pinmech.BatchSolver(LoopSolver(_four_bar(), ["O2"])).try_solve(h, h, h, h),
    "DriverValues last": lambda h: DriverValues(0.0, h, 10),
    "DriverValues steps": lambda h: DriverValues(0.0, 1.0, h),
    "Mechanism.from_urdf": lambda h: Mechanism.from_urdf(h),
    "load_linkage": lambda h: pinmech.load_linkage(h),
    "Scene.load": lambda h: pinmech.Scene.load(h),
    "ForceSolver gravity": lambda h: pinmech.ForceSolver(Mechanism.from_urdf(MODELS / "four_bar_dynamic.urdf"),
                                                         ["O2"], gravity=h),
}


@pytest.mark.parametrize("call", sorted(CALLS))
@settings(max_examples=len(HOSTILE), deadline=None)
@given(h=st.sampled_from(HOSTILE))
def test_only_named_errors_leave_the_api(call, h):
    try:
        CALLS[call](h)
    except pinmech.PinmechError as exc:
        assert str(exc), f"{call}({h!r}): {type(exc).__name__} without a message"


@pytest.mark.parametrize("call", ["analyse", "load_mechanism", "to_text", "to_json", "to_dict",
                                  "velocity_polygon", "acceleration_polygon", "Sweep.from_scene"])
@pytest.mark.parametrize("value", ["models/scenes/r_rtr.toml", None, 3, {"drivers": {}}])
def test_a_scene_or_analysis_of_another_type_is_a_named_error(call, value):
    """A path string where a pinmech.Scene is wanted (or a dict where an Analysis is) ended
    in AttributeError ("'str' object has no attribute 'raw'"): one ModelError naming the
    argument and what it got."""
    target = pinmech.Sweep.from_scene if call == "Sweep.from_scene" else getattr(pinmech, call)
    with pytest.raises(pinmech.ModelError, match=r"must be a pinmech\.(Scene|Analysis), got"):
        target(value)
