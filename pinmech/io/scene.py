"""TOML scene files: which model, which drivers with which values, which branch, what to report.

`Scene.load` reads the file, applies the command line's `--set KEY=VALUE` overrides and
validates every table once (scene_file.py): what it returns holds typed tables
(`scene.file.drivers`, `scene.file.sweep`, ...), never raw TOML. Quantities whose unit the
model decides (a driver's angle or position) are kept as written and converted once the
joint is known (`joint_quantity`). See docs/reference/scene.md for the format.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import msgspec

from pinmech.arguments import file_path
from pinmech.exceptions import PinmechError, SceneError
from pinmech.io.scene_file import MODEL_KEYS, SceneFile
from pinmech.io.scene_implied import implied_scene, is_drawn_linkage
from pinmech.io.scene_tables import DRIVER_KEYS, SOLVER_RANGES, DriverSpec
from pinmech.toml_file import TOMLDecodeError, read_toml, toml_value
from pinmech.units import JOINT_KINDS, to_si

#: Top-level keys a scene may have.
KNOWN_KEYS = frozenset(SceneFile.keys())
#: The tables that turn a scene's force analysis on (forces_scene.py reads them).
FORCE_KEYS = ("forces", "gravity", "load")

__all__ = ["FORCE_KEYS", "KNOWN_KEYS", "MODEL_KEYS", "SOLVER_RANGES", "Scene", "wants_forces"]


def wants_forces(scene: Scene) -> bool:
    """True when the scene has a `[forces]`, `[gravity]` or `[[load]]` table."""
    return scene.file.wants_forces


@dataclass(frozen=True)
class Scene:
    """A scene, validated: its tables typed, plus where they came from.

    Attributes:
        path: the scene file (relative paths inside it are relative to its folder).
        file: the scene's tables after command-line overrides, typed (SceneFile).
        file_drivers: the `[drivers]` as the file has them, before overrides (None when the
            file's own tables do not validate): their values are the reference pose that
            names the assembly (`--angle` asks for another pose of the same assembly,
            reached by continuation).
        implied: None for a scene file; for a drawn linkage's file, the TOML of the
            scene it was read as (its drivers at their drawn values).
    """

    path: Path
    file: SceneFile
    file_drivers: dict[str, DriverSpec] | None = None
    implied: str | None = None  # a drawn linkage's file: the scene it stands for (scene_implied.py), as TOML

    # -------------------------------------------------------------- loading
    @classmethod
    def load(cls, path: str | Path, overrides: list[str] | None = None) -> Scene:
        """Read a scene file, apply `KEY=VALUE` overrides (dotted keys) and validate it.

        Raises:
            SceneError: missing file, malformed TOML, unknown keys, bad override, any value
                of the wrong type or unit (UnitError), naming the file and the key.
        """
        path = file_path(path, "the scene", SceneError)
        written = read_toml(path, "scene", SceneError)
        implied = None
        if is_drawn_linkage(written):  # solved at its drawn pose, as the scene it stands for
            written, implied = implied_scene(path, written)
        tables = copy.deepcopy(written)
        for item in overrides or []:
            _override(tables, item, path)
        scene = cls.from_tables(tables, path)
        if not overrides:
            return cls(path, scene.file, scene.file_drivers, implied)
        try:
            as_written = SceneFile.read(dict(tables, drivers=written.get("drivers", {})), path)
        except PinmechError:
            return cls(path, scene.file, None, implied)
        return cls(path, scene.file, as_written.drivers, implied)

    @classmethod
    def from_tables(cls, tables: dict[str, Any], path: str | Path) -> Scene:
        """A scene from its TOML tables as read (relative paths from `path`'s folder).

        Raises:
            SceneError: as `load`, naming `path` and the key.
        """
        path = Path(path)
        file = SceneFile.read(tables, path)
        return cls(path, file, file.drivers)

    # -------------------------------------------------------------- accessors
    @property
    def title(self) -> str:
        return self.file.title or self.path.stem

    @property
    def urdf(self) -> Path:
        """The URDF file: resolved relative to the scene's folder, or an example-robot-data model's."""
        if self.file.robot is not None:
            from pinmech.model.robots import robot_urdf

            return robot_urdf(self.file.robot, where=str(self.path))
        return (self.path.parent / self.file.urdf).resolve()

    @property
    def model_kind(self) -> str:
        """Which key names the model: "urdf", "robot", "linkage" or "mjcf"."""
        return self.file.model_kind

    @property
    def is_task(self) -> bool:
        """True for an end-effector rate problem (`[[task]]`), False for a driven scene."""
        return self.file.task is not None

    def model_file(self, key: str) -> Path:
        """A file the scene names (`linkage`, `mjcf`, `sidecar`), relative to the scene's folder."""
        return (self.path.parent / getattr(self.file, key)).resolve()

    def quantity(self, value: Any, kind: str, *keys: str) -> float:
        """A quantity of this scene in SI, with file and key in any error."""
        try:
            return to_si(value, kind, where=".".join(keys))
        except SceneError as exc:  # UnitError stays a UnitError, now naming the file
            raise type(exc)(str(exc), path=str(self.path)) from exc

    def joint_quantity(self, value: Any, joint_kind: str, order: int, *keys: str) -> float:
        """A joint coordinate (order 0), rate (1) or acceleration (2) in SI."""
        kinds = JOINT_KINDS["prismatic" if joint_kind == "prismatic" else "revolute"]
        return self.quantity(value, kinds[order], *keys)

    def reference(self) -> Scene:
        """The scene as its file has it, with the overrides of everything but the drivers
        (a `--set guess...` picks the reference's assembly, `--angle` only the pose)."""
        if self.file_drivers is None or self.file_drivers is self.file.drivers:
            return self
        return Scene(self.path, msgspec.structs.replace(self.file, drivers=self.file_drivers), self.file_drivers,
                     self.implied)

    def assembly(self) -> Any:
        """The `assembly` value as written: absent (None), "any", or a table loop -> sign."""
        return self.file.assembly

    @staticmethod
    def driver_order(key: str) -> int:
        return DRIVER_KEYS[key]

    def solver_options(self) -> dict[str, float | int]:
        """`[solver]` settings given: tol, max_iterations, max_condition (numbers)."""
        return self.file.solver.options()


def _override(tables: dict[str, Any], item: str, path: Path) -> None:
    """Apply one `dotted.key=value` override; the value is read as TOML, else as a string."""
    key, sep, text = item.partition("=")
    if not sep or not key.strip():
        raise SceneError(f"override {item!r} is not KEY=VALUE (e.g. drivers.A.angle='45 deg')", path=str(path))
    try:
        value = toml_value(text)
    except TOMLDecodeError:
        value = text.strip().strip("'\"")
    node = tables
    parts = key.strip().split(".")
    for part in parts[:-1]:
        node = node.setdefault(part, {})
        if not isinstance(node, dict):
            raise SceneError(f"cannot set {key}: {part} is not a table", path=str(path), key=key)
    node[parts[-1]] = value
