"""The tables of a scene that set up a pose: `[drivers.NAME]`, `[points.NAME]`, `[report]`,
`[solver]`, `[rates]`, `[[task]]`, each a typed, validated, frozen object.

Values whose unit depends on the joint (a driver's angle or position) stay as written and
are converted once the model is known (`Scene.joint_quantity`); every other quantity is
checked here through `pinmech.units` and kept with its SI value (`Quantity`).
"""

from __future__ import annotations

from typing import Any, ClassVar

from pinmech.io.scene_fields import Quantity, Refused, Table, names, positive_number, quantity, written_value
from pinmech.solve.loops import SOLVER_RANGES  # the accepted [solver] values, the solver's own

#: A driver's keys and the order of the derivative each gives (0 coordinate, 1 rate, 2 acceleration).
DRIVER_KEYS = {"angle": 0, "position": 0, "speed": 1, "velocity": 1, "acceleration": 2}


class DriverSpec(Table):
    """One `[drivers.NAME]` table: coordinate, rate and acceleration as written."""

    unknown_hint: ClassVar[str] = "use angle (or position), speed (or velocity), acceleration"
    angle: Any = None
    position: Any = None
    speed: Any = None
    velocity: Any = None
    acceleration: Any = None

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        return value if value is None else written_value(value, DRIVER_KEYS[name])

    def _after(self) -> None:
        for first, second in (("angle", "position"), ("speed", "velocity")):
            if getattr(self, first) is not None and getattr(self, second) is not None:
                raise Refused(f"{second} repeats another key of the same order")
        if self.angle is None and self.position is None:
            raise Refused("missing its angle (or position)")

    def given(self) -> list[tuple[str, int, Any]]:
        """(key, order, value as written) of each key given, in the order of DRIVER_KEYS."""
        return [(key, order, getattr(self, key)) for key, order in DRIVER_KEYS.items()
                if getattr(self, key) is not None]

    @property
    def rate(self) -> Any:
        """The speed (or velocity) as written; None when absent (at rest)."""
        return self.speed if self.speed is not None else self.velocity

    def key_of(self, order: int) -> str:
        """The key the file used for a derivative order ("angle" or "position", ...)."""
        pairs = {0: ("angle", "position"), 1: ("speed", "velocity"), 2: ("acceleration", "acceleration")}
        first, second = pairs[order]
        return second if getattr(self, second) is not None and getattr(self, first) is None else first


_POINT_NEEDS = ("a point needs exactly at = \"POINT\" (the point of LINK under it) or at = [x, y, z] "
                "(coordinates in LINK's frame, with units), and link = \"LINK\"")


class PointSpec(Table):
    """`[points.NAME]`: a point of `link` under a named point (`at` a name), or fixed on
    `link` at coordinates in its frame (`at` three lengths)."""

    unknown_hint: ClassVar[str] = _POINT_NEEDS
    at: Any
    link: str

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if isinstance(data, dict) and set(data) != {"at", "link"}:
            raise Refused(_POINT_NEEDS)
        return super()._known_keys(data)

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        if name != "at" or isinstance(value, str):
            return value
        if not isinstance(value, list) or len(value) != 3:
            raise Refused(f"at = {value!r} must be three coordinates [x, y, z] with units, or a point's name")
        return tuple(quantity(x, "length") for x in value)

    @property
    def coincident(self) -> bool:
        """True for a point under a named point (at = "B"), False for coordinates."""
        return isinstance(self.at, str)

    @property
    def xyz(self) -> tuple[float, float, float]:
        """The coordinates in the link's frame [m] (coordinates given only)."""
        return tuple(q.si for q in self.at)


class ReportSpec(Table):
    """`[report]`: points and links to list (None: all), and what a joint beyond its limits is."""

    points: Any = None
    links: Any = None
    limits: Any = "warn"

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        if name != "limits":
            return names(value)
        if value not in ("warn", "error"):
            raise Refused(f"limits must be \"warn\" or \"error\", got {value!r}")
        return value


_NAMED_OPTIONS = ("kernel", "certify")  # [solver] keys named by a word, not a number


class SolverSpec(Table):
    """`[solver]`: closure tolerance, Newton iteration cap, singular limit, kinematic passes
    (kernel: "generic" or "generated"), certification dial (certify: "every-pose",
    "every-K", "ends" or "none"; only those given)."""

    tol: Any = None
    max_iterations: Any = None
    max_condition: Any = None
    kernel: Any = None
    certify: Any = None

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            raise Refused(f"[solver] must be a table, got {data!r}")
        for key in data:
            if key not in SOLVER_RANGES and key not in _NAMED_OPTIONS:
                raise Refused(f"unknown solver option {key}; known: {', '.join((*SOLVER_RANGES, *_NAMED_OPTIONS))}",
                              at=(key,))
        return data

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        key = f"solver.{name}"
        if name == "kernel":
            from pinmech.solve.kernels import KERNELS

            if value not in KERNELS:
                raise Refused(f"{key} = {value!r} must be one of {', '.join(KERNELS)}")
            return value
        if name == "certify":
            from pinmech.exceptions import OptionError
            from pinmech.solve.certify import checked_certify

            try:
                return checked_certify(value)
            except OptionError as exc:
                raise Refused(f"solver.{exc}") from None
        number = positive_number(value, key, *SOLVER_RANGES[name])
        if name == "max_iterations":
            if number != int(number):  # 2.7 was cut to 2 in silence
                raise Refused(f"{key} = {value!r} must be a whole number of iterations")
            return int(number)
        return number

    def options(self) -> dict[str, float | int]:
        """The settings given, as LoopSolver's keyword arguments."""
        return {key: getattr(self, key) for key in (*SOLVER_RANGES, *_NAMED_OPTIONS) if getattr(self, key) is not None}


class RatesSpec(Table):
    """`[rates]`: how a task's rates are solved (method, damping, singular limit)."""

    method: Any = None
    damping: Any = None
    max_condition: Any = None

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        return cls._method(value) if name == "method" else cls._number(name, value)

    @staticmethod
    def _method(value: Any) -> str:
        from pinmech.solve.rates import METHODS

        if not isinstance(value, str):
            raise Refused(f"must be a string, got {value!r}")
        if value not in METHODS:  # a scene's misspelling, not an inconsistent task (8)
            raise Refused(f"must be one of {', '.join(METHODS)}, got {value!r}")
        return value

    @staticmethod
    def _number(name: str, value: Any) -> float:
        from pinmech.solve.rates import DAMPING_RANGE

        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise Refused(f"must be a positive number, got {value!r}")
        low, high = DAMPING_RANGE if name == "damping" else SOLVER_RANGES["max_condition"]
        return positive_number(value, f"rates.{name}", low, high)

    def options(self) -> dict[str, Any]:
        """The settings given, as RateSolver's keyword arguments."""
        return {k: getattr(self, k) for k in ("method", "damping", "max_condition") if getattr(self, k) is not None}


_ORDER_KINDS = {True: ("angular_velocity", "angular_acceleration"), False: ("velocity", "acceleration")}
_TASK_KEYS = {"frame", "components", "velocity", "acceleration", "reference"}


class TaskSpec(Table):
    """One `[[task]]`: a frame's components to move at given rates [SI], world or local axes."""

    frame: str
    components: tuple[str, ...]
    velocity: tuple[float, ...]
    acceleration: tuple[float, ...]
    reference: str = "world"

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        from pinmech.solve.rates import COMPONENTS

        if not isinstance(data, dict):
            raise Refused(f"must be a table, got {data!r}")
        unknown, missing = set(data) - _TASK_KEYS, {"frame", "components", "velocity"} - set(data)
        if unknown or missing:
            raise Refused(f"unknown keys {sorted(unknown)} / missing keys {sorted(missing)}; a task has frame, "
                          "components, velocity, acceleration (optional) and reference (optional)")
        comps = data["components"]
        if not isinstance(comps, list) or not all(c in COMPONENTS for c in comps):
            raise Refused(f"components {comps!r} must be a list of {', '.join(COMPONENTS)}", at=("components",))
        out = dict(data, components=tuple(comps))
        for order, key in enumerate(("velocity", "acceleration")):
            given = data.get(key, [0] * len(comps))
            if not isinstance(given, list) or len(given) != len(comps):
                raise Refused(f"{key} needs one quantity per component ({len(comps)})", at=(key,))
            out[key] = tuple(quantity(x, _ORDER_KINDS[c.startswith("w")][order], at=(key, c)).si
                             for x, c in zip(given, comps))
        reference = data.get("reference", "world")
        if reference not in ("world", "local"):
            raise Refused(f"reference must be \"world\" or \"local\" (the frame's own axes), got {reference!r}",
                          at=("reference",))
        return out


def task_list(value: Any) -> Any:
    """`[[task]]`: a non-empty array of tables."""
    if not isinstance(value, list) or not value:
        raise Refused("task must be an array of tables: [[task]]")
    return value


__all__ = ["DriverSpec", "PointSpec", "Quantity", "RatesSpec", "ReportSpec", "SolverSpec", "TaskSpec"]
