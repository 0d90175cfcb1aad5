"""Checks of the drawing layer's inputs: shapes, finiteness, models that match; `DrawError`."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.directions import unit_vector, written
from pinmech.exceptions import PinmechError


class DrawError(PinmechError):
    """An input of the drawing layer is malformed: wrong shape, not finite, unreadable.

    Attributes:
        argument: name of the offending argument ("q", "plane_normal", "urdf_path", ...).
        value: the offending value, or its shape.
    """

    exit_code = 9

    def __init__(self, message: str, *, argument: str, value: Any = None):
        super().__init__(message)
        self.argument = argument
        self.value = value



def _configuration(model: pin.Model, q: Any, argument: str) -> np.ndarray:
    return _floats(q, model.nq, argument, " (model.nq)")


def _vector3(value: Any, argument: str) -> np.ndarray:
    return _floats(value, 3, argument)


def _floats(value: Any, n: int, argument: str, why: str = "") -> np.ndarray:
    """value as a vector of n finite floats, else a DrawError naming the argument."""
    message = f"{argument} must be {n} finite numbers{why}, got {np.size(value)}: {value!r}"
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise DrawError(message, argument=argument, value=value) from exc
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise DrawError(message, argument=argument, value=value)
    return v


def _unit(value: Any, argument: str) -> np.ndarray:
    v = _vector3(value, argument)
    unit = unit_vector(v)
    if unit is None:
        raise DrawError(f"{argument} must be a non-zero vector, got {written(v)}", argument=argument, value=v)
    return unit


def _points(points: Mapping[str, Any]) -> dict[str, np.ndarray]:
    return {str(name): _vector3(p, f"points['{name}']") for name, p in points.items()}


def _stack(points: Mapping[str, np.ndarray]) -> np.ndarray:
    return np.array(list(points.values()), dtype=float).reshape(-1, 3)


def _check_visuals(model: pin.Model, visual_model: pin.GeometryModel) -> None:
    for obj in visual_model.geometryObjects:
        if obj.parentJoint >= model.njoints:
            raise DrawError(
                f"visual '{obj.name}' hangs on joint {obj.parentJoint} but the model has "
                f"{model.njoints} joints: the visuals belong to another model",
                argument="visual_model",
                value=obj.name,
            )

