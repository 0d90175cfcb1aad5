"""Each synthesis topology's closed-form kinematics, by name: a module with the same
functions (NAMES, pose, folds, ground_angle, point_jacobian, label, lengths, size) for the
four-bar (synthesis_fourbar) and the slider-crank (synthesis_slider)."""

from __future__ import annotations

from types import ModuleType

from pinmech.design import synthesis_fourbar, synthesis_slider

_BY_TOPOLOGY = {"four-bar": synthesis_fourbar, "slider-crank": synthesis_slider}


def kinematics(topology: str) -> ModuleType:
    """The kinematics module of a topology ("four-bar" or "slider-crank")."""
    return _BY_TOPOLOGY[topology]
