"""Each synthesis topology's closed-form kinematics, by name: a module with the same
functions (NAMES, pose, folds, ground_angle, point_jacobian, label, lengths, size) for the
four-bar (fourbar), the slider-crank (slider) and the inverted
slider-crank (inverted)."""

from __future__ import annotations

from types import ModuleType

from pinmech.design.synthesis import fourbar, inverted, slider

_BY_TOPOLOGY = {"four-bar": fourbar, "slider-crank": slider,
                "inverted-slider-crank": inverted}


def kinematics(topology: str) -> ModuleType:
    """The kinematics module of a topology ("four-bar", "slider-crank", "inverted-slider-crank")."""
    return _BY_TOPOLOGY[topology]
