"""Each synthesis topology's closed-form kinematics, by name: a module with the same
functions (NAMES, pose, folds, ground_angle, point_jacobian, label, lengths, size) for the
four-bar (synthesis_fourbar), the slider-crank (synthesis_slider) and the inverted
slider-crank (synthesis_inverted)."""

from __future__ import annotations

from types import ModuleType

from pinmech.design import synthesis_fourbar, synthesis_inverted, synthesis_slider

_BY_TOPOLOGY = {"four-bar": synthesis_fourbar, "slider-crank": synthesis_slider,
                "inverted-slider-crank": synthesis_inverted}


def kinematics(topology: str) -> ModuleType:
    """The kinematics module of a topology ("four-bar", "slider-crank", "inverted-slider-crank")."""
    return _BY_TOPOLOGY[topology]
