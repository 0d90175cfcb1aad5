"""A scene's `[forces]`, `[gravity]` and `[[load]]` tables, typed and validated once
(quantities in SI, world frame):

    [forces]                          # optional; any of these three tables turns forces on
    massless = ["slider_pin"]         # links meant to have no mass (else: an error naming them)
    static = false                    # true: zero speeds and accelerations (statics)
    minimum_norm = false              # redundant loops: the smallest reactions, not an error
    flywheel = "0.05 kg*m^2"          # sweeps: the coefficient of speed fluctuation with it

    [gravity]                         # default: no gravity (kinematics-only scenes)
    acceleration = "9.81 m/s^2"
    direction = [0, -1, 0]            # world frame, any length

    [[load]]                          # an external load, constant in the world frame
    point = "B_pin"                   # a named point (or link = "piston": its frame origin)
    force = ["-200 N", "0 N"]         # x, y (, z) with units
    torque = "0.5 N*m"                # on the point's link; one value: about the plane normal
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from pinmech.directions import unit_vector, written
from pinmech.io.scene_fields import Refused, Table, names, positive_quantity, quantity
from pinmech.known_keys import unknown_keys

_GRAVITY_NEEDS = "give acceleration = \"9.81 m/s^2\" and direction = [0, -1, 0] (world frame)"


class ForcesSpec(Table):
    """`[forces]`: massless links, statics, minimum-norm reactions, a flywheel [kg m^2]."""

    flywheel: float | None = None
    massless: tuple[str, ...] = ()
    minimum_norm: bool = False
    static: bool = False

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        if name == "massless":
            return tuple(names(value))
        if name == "flywheel":
            return positive_quantity(value, "moment_of_inertia", "positive").si
        if not isinstance(value, bool):  # static, minimum_norm
            raise Refused(f"must be true or false, got {value!r}")
        return value


class GravitySpec(Table):
    """`[gravity]`: the acceleration of gravity as a vector [m/s^2], world frame."""

    unknown_hint: ClassVar[str] = _GRAVITY_NEEDS
    acceleration: float
    direction: tuple[float, float, float]

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if isinstance(data, dict) and set(data) != {"acceleration", "direction"}:
            raise Refused(_GRAVITY_NEEDS)
        return super()._known_keys(data)

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        return quantity(value, "acceleration").si if name == "acceleration" else cls._direction(value)

    @staticmethod
    def _direction(value: Any) -> tuple[float, float, float]:
        ok = isinstance(value, list) and len(value) == 3 and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) for x in value)
        if not ok or not np.all(np.isfinite(value)):
            raise Refused(f"must be three numbers [x, y, z], got {value!r}")
        direction = unit_vector(np.array(value, dtype=float))
        if direction is None:
            raise Refused(f"{written(value)} is not a direction (all zero)")
        return tuple(float(x) for x in direction)

    @property
    def vector(self) -> np.ndarray:
        """Gravity's acceleration [m/s^2], world frame."""
        return self.acceleration * np.array(self.direction)


class LoadSpec(Table):
    """A `[[load]]` entry in SI: where (a point or a link), force [N], torque [N m].

    `torque_about_normal` is a single torque [N m] about the plane normal (None when the
    torque was given as a vector)."""

    unknown_hint: ClassVar[str] = "known: force, link, name, point, torque"
    name: str
    at: str
    key: str
    force: tuple[float, float, float]
    torque: tuple[float, float, float]
    torque_about_normal: float | None = None

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            raise Refused(f"write each load as a [[load]] table, got {data!r}")
        message = unknown_keys(data, ("name", "point", "link", "force", "torque"), cls.unknown_hint)
        if message:
            raise Refused(message)
        places = [k for k in ("point", "link") if k in data]
        if len(places) != 1 or not isinstance(data[places[0]], str):
            raise Refused("say where the load acts: point = \"NAME\" (a named point) or link = \"NAME\"")
        if "force" not in data and "torque" not in data:
            raise Refused("give a force = [\"x N\", \"y N\"] and/or a torque = \"T N*m\"")
        torque = data.get("torque", [0, 0, 0])
        single = isinstance(torque, (str, int, float)) and not isinstance(torque, bool)
        name = data.get("name", data[places[0]])
        if not isinstance(name, str):
            raise Refused(f"must be a string, got {name!r}", at=("name",))
        return {"name": name, "at": data[places[0]], "key": places[0],
                "force": _vector(data.get("force", [0, 0, 0]), "force"),
                "torque": (0.0, 0.0, 0.0) if single else _vector(torque, "torque"),
                "torque_about_normal": quantity(torque, "torque", at=("torque",)).si if single else None}


def _vector(value: Any, kind: str) -> tuple[float, float, float]:
    """Two or three quantities with units ("-200 N", "0 N"), world frame, in SI."""
    if not isinstance(value, list) or len(value) not in (2, 3):
        raise Refused(f"{kind} must be a list of 2 or 3 quantities, e.g. [\"-200 N\", \"0 N\"], got {value!r}",
                      at=(kind,))
    out = [0.0, 0.0, 0.0]
    for i, item in enumerate(value):
        out[i] = quantity(item, kind, at=(f"{kind}[{i}]",)).si
    return tuple(out)


def load_list(value: Any) -> Any:
    """`[[load]]`: an array of tables."""
    if not isinstance(value, list) or not all(isinstance(e, dict) for e in value):
        raise Refused("write each load as a [[load]] table")
    return value
