"""A scene file as one typed, validated object: `SceneFile.read(tables, path)`.

Every table is checked here, once, with the location of the mistake: a key of the wrong
type, a list where a table is due, a unit of the wrong dimension, a step below zero, a
NaN, an empty table that means nothing all end in one SceneError (or UnitError) naming
the file and the key (scene_errors.py). Nothing below reads the TOML's raw tables.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import msgspec

from pinmech.io.force_tables import ForcesSpec, GravitySpec, LoadSpec, load_list
from pinmech.io.scene_errors import scene_error
from pinmech.io.scene_fields import Invalid, Refused, Table, names, table_of, written_value
from pinmech.io.scene_tables import DriverSpec, PointSpec, RatesSpec, ReportSpec, SolverSpec, TaskSpec, task_list
from pinmech.io.sweep_table import SweepSpec
from pinmech.known_keys import unknown_keys

#: The keys that name the model file; a scene gives exactly one.
MODEL_KEYS = ("urdf", "robot", "linkage", "mjcf")
_ONE_MODEL = ("give exactly one of urdf = \"path/to/model.urdf\", robot = \"ur5\" (an example-robot-data name), "
              "linkage = \"leg.toml\" (a linkage as drawn) or mjcf = \"leg.xml\"")


class SceneFile(Table):
    """Every table of a scene, typed. Absent tables are empty (or None where their absence
    means something: no `[[task]]`, no `[gravity]`, no `assembly`, no `move`)."""

    title: str | None = None
    urdf: str | None = None
    robot: str | None = None
    linkage: str | None = None
    mjcf: str | None = None
    sidecar: str | None = None
    drivers: dict[str, DriverSpec] = {}
    guess: dict[str, Any] = {}
    pose: dict[str, Any] = {}
    lock: dict[str, Any] = {}
    move: tuple[str, ...] | None = None
    points: dict[str, PointSpec] = {}
    report: ReportSpec = msgspec.field(default_factory=ReportSpec)
    solver: SolverSpec = msgspec.field(default_factory=SolverSpec)
    rates: RatesSpec = msgspec.field(default_factory=RatesSpec)
    task: tuple[TaskSpec, ...] | None = None
    sweep: SweepSpec = msgspec.field(default_factory=SweepSpec)
    assembly: Any = None
    forces: ForcesSpec | None = None
    gravity: GravitySpec | None = None
    load: tuple[LoadSpec, ...] | None = None

    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        message = unknown_keys(data, sorted(cls.keys()))
        if message:
            raise Refused(message)
        for key in ("urdf", "robot", "linkage", "mjcf", "sidecar", "title"):
            if key in data and not isinstance(data[key], str):
                raise Refused(f"must be a string, got {data[key]!r}", at=(key,))
        if sum(key in data for key in MODEL_KEYS) != 1:
            raise Refused(_ONE_MODEL, at=("urdf",))
        if "sidecar" in data and "urdf" not in data:
            raise Refused("sidecar = \"robot.yaml\" goes with urdf = \"robot.urdf\" (Gepetto's extended URDF)",
                          at=("sidecar",))
        for key in ("task", "load"):
            if key in data and isinstance(data[key], list):
                data = dict(data, **{key: tuple(data[key])})
        return data

    @classmethod
    def _field(cls, name: str, value: Any) -> Any:
        if name in ("drivers", "points", "report", "solver", "rates", "sweep", "forces"):
            return table_of(value, name)
        if name in ("guess", "pose", "lock"):
            return cls._joint_values(name, value)
        checks = {"move": cls._move, "task": cls._task, "load": cls._load, "assembly": cls._assembly}
        return checks[name](value) if name in checks else value

    @staticmethod
    def _joint_values(name: str, value: Any) -> dict[str, Any]:
        table = table_of(value, name)
        for joint, item in table.items():
            try:
                written_value(item)
            except Refused as exc:
                raise Refused(exc.message, at=(joint,), error=exc.error) from None
        return table

    @staticmethod
    def _move(value: Any) -> tuple[str, ...]:
        if not isinstance(value, list) or not all(isinstance(n, str) for n in value):
            raise Refused("move must be a list of joint names")
        if not value:
            raise Refused("move = [] leaves no joint to move: name the joints the scene moves")
        return tuple(names(value))

    @staticmethod
    def _task(value: Any) -> Any:
        return tuple(task_list(list(value) if isinstance(value, tuple) else value))

    @staticmethod
    def _load(value: Any) -> Any:
        return tuple(load_list(list(value) if isinstance(value, tuple) else value))

    @staticmethod
    def _assembly(value: Any) -> Any:
        if value != "any" and not isinstance(value, dict):  # its signs: parse_assembly, against the loops
            raise Refused(f'must be "any" or a table such as assembly = {{ B = "+" }}, got {value!r}')
        return value

    @property
    def model_kind(self) -> str:
        """Which key names the model: "urdf", "robot", "linkage" or "mjcf"."""
        return next(key for key in MODEL_KEYS if getattr(self, key) is not None)

    @property
    def wants_forces(self) -> bool:
        """True when the file has a `[forces]`, `[gravity]` or `[[load]]` table."""
        return self.forces is not None or self.gravity is not None or self.load is not None

    @classmethod
    def read(cls, tables: dict[str, Any], path: Path) -> SceneFile:
        """The scene's TOML tables, validated.

        Raises:
            SceneError (UnitError for a quantity): the first mistake, naming the file and key.
        """
        try:
            return cls.validate(tables)
        except Invalid as exc:
            raise scene_error(exc, path) from None
