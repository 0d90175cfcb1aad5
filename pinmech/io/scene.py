"""TOML scene files: which URDF, which drivers with which values, which branch, what to report.

A scene keeps quantities as the user wrote them ("30 deg", "-50 rpm", "150 mm") and
converts them to SI only once the model is known (a driver's unit depends on its joint
type). See the docs page docs/reference/scene.md for the format.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pinmech.arguments import file_path
from pinmech.exceptions import SceneError
from pinmech.units import JOINT_KINDS, to_si

from pinmech.toml_file import TOMLDecodeError, read_toml, toml_value

#: Top-level keys a scene may have; other modules (tasks, sweeps) register theirs here.
KNOWN_KEYS = {
    "title", "urdf", "robot", "linkage", "mjcf", "sidecar", "drivers", "guess", "pose", "move", "lock", "points",
    "report", "solver", "task", "rates", "sweep", "draw", "assembly",
    "forces", "gravity", "load",  # forces_scene.py
}
#: Accepted `[solver]` values. A closure tolerance (relative to the mechanism's size)
#: below 1e-16 is tighter than rounding allows; above 1e-3 a "closed" loop is visibly
#: open. A singular limit below 1 would refuse every pose.
SOLVER_RANGES = {"tol": (1e-16, 1e-3), "max_iterations": (1, 1000), "max_condition": (1.0, float("inf"))}
#: The keys that name the model file; a scene gives exactly one.
MODEL_KEYS = ("urdf", "robot", "linkage", "mjcf")
_DRIVER_KEYS = {"angle": 0, "position": 0, "speed": 1, "velocity": 1, "acceleration": 2}
#: The tables that turn a scene's force analysis on (forces_scene.py reads them).
FORCE_KEYS = ("forces", "gravity", "load")


def wants_forces(scene: Scene) -> bool:
    """True when the scene has a `[forces]`, `[gravity]` or `[[load]]` table."""
    return any(key in scene.raw for key in FORCE_KEYS)


@dataclass
class Scene:
    """A parsed scene: raw values as written, plus where they came from.

    Attributes:
        path: the scene file (relative paths inside it are relative to its folder).
        raw: the TOML content, after command-line overrides.
        base: the TOML content as the file has it, before overrides: its drivers' values
            are the reference pose that names the assembly (`--angle` asks for another
            pose of the same assembly, reached by continuation).
    """

    path: Path
    raw: dict[str, Any] = field(default_factory=dict)
    base: dict[str, Any] | None = None

    # -------------------------------------------------------------- loading
    @classmethod
    def load(cls, path: str | Path, overrides: list[str] | None = None) -> Scene:
        """Read a scene file and apply `KEY=VALUE` overrides (dotted keys).

        Raises:
            SceneError: missing file, malformed TOML, unknown keys, bad override.
        """
        path = file_path(path, "the scene", SceneError)
        raw = read_toml(path, "scene", SceneError)
        scene = cls(path=path, raw=raw, base=copy.deepcopy(raw))
        for item in overrides or []:
            scene.override(item)
        scene._validate()
        return scene

    def override(self, item: str) -> None:
        """Apply one `dotted.key=value` override; the value is read as TOML, else as a string."""
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise SceneError(f"override {item!r} is not KEY=VALUE (e.g. drivers.A.angle='45 deg')", path=str(self.path))
        try:
            value = toml_value(text)
        except TOMLDecodeError:
            value = text.strip().strip("'\"")
        node = self.raw
        parts = key.strip().split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise SceneError(f"cannot set {key}: {part} is not a table", path=str(self.path), key=key)
        node[parts[-1]] = value

    def _validate(self) -> None:
        unknown = set(self.raw) - KNOWN_KEYS
        if unknown:
            raise SceneError(f"unknown key(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(KNOWN_KEYS))}",
                             path=str(self.path))
        for key in ("urdf", "robot", "linkage", "mjcf", "sidecar", "title"):
            if key in self.raw and not isinstance(self.raw[key], str):
                raise SceneError(f"must be a string, got {self.raw[key]!r}", path=str(self.path), key=key)
        given = [key for key in MODEL_KEYS if key in self.raw]
        if len(given) != 1:
            raise SceneError("give exactly one of urdf = \"path/to/model.urdf\", robot = \"ur5\" "
                             "(an example-robot-data name), linkage = \"leg.toml\" (a linkage as drawn) or "
                             "mjcf = \"leg.xml\"", path=str(self.path), key="urdf")
        if "sidecar" in self.raw and "urdf" not in self.raw:
            raise SceneError("sidecar = \"robot.yaml\" goes with urdf = \"robot.urdf\" (Gepetto's extended URDF)",
                             path=str(self.path), key="sidecar")
        for name in ("drivers", "guess", "pose", "lock", "points", "report", "solver", "rates"):
            if name in self.raw and not isinstance(self.raw[name], dict):
                raise SceneError(f"[{name}] must be a table", path=str(self.path), key=name)

    # -------------------------------------------------------------- accessors
    @property
    def title(self) -> str:
        return str(self.raw.get("title", self.path.stem))

    @property
    def urdf(self) -> Path:
        """The URDF file: resolved relative to the scene's folder, or an example-robot-data model's."""
        if "robot" in self.raw:
            from pinmech.model.robots import robot_urdf

            return robot_urdf(self.raw["robot"], where=str(self.path))
        return (self.path.parent / self.raw["urdf"]).resolve()

    @property
    def model_kind(self) -> str:
        """Which key names the model: "urdf", "robot", "linkage" or "mjcf"."""
        return next(key for key in MODEL_KEYS if key in self.raw)

    def model_file(self, key: str) -> Path:
        """A file the scene names (`linkage`, `mjcf`, `sidecar`), relative to the scene's folder."""
        return (self.path.parent / self.raw[key]).resolve()

    def where(self, *keys: str) -> str:
        return ".".join(keys)

    def section(self, name: str) -> dict[str, Any]:
        value = self.raw.get(name, {})
        if not isinstance(value, dict):
            raise SceneError(f"[{name}] must be a table", path=str(self.path), key=name)
        return value

    def names(self, section: str, key: str) -> list[str] | None:
        """A list of names under `[section] key = [...]` (None when absent)."""
        value = self.section(section).get(key)
        if value is None:
            return None
        if not isinstance(value, list) or not all(isinstance(n, str) for n in value):
            raise SceneError(f"must be a list of names, e.g. [\"D\"], got {value!r}", path=str(self.path),
                             key=f"{section}.{key}")
        return value

    def quantity(self, value: Any, kind: str, *keys: str) -> float:
        """A quantity of this scene in SI, with file and key in any error."""
        try:
            return to_si(value, kind, where=self.where(*keys))
        except SceneError as exc:  # UnitError stays a UnitError, now naming the file
            raise type(exc)(str(exc), path=str(self.path)) from exc

    def joint_quantity(self, value: Any, joint_kind: str, order: int, *keys: str) -> float:
        """A joint coordinate (order 0), rate (1) or acceleration (2) in SI."""
        kinds = JOINT_KINDS["prismatic" if joint_kind == "prismatic" else "revolute"]
        return self.quantity(value, kinds[order], *keys)

    def driver_table(self) -> dict[str, dict[str, Any]]:
        """name -> {"angle"/"position", "speed"/"velocity", "acceleration"} as written."""
        drivers = self.section("drivers")
        for name, spec in drivers.items():
            if not isinstance(spec, dict):
                raise SceneError(f"[drivers.{name}] must be a table with angle/speed/acceleration",
                                 path=str(self.path), key=f"drivers.{name}")
            unknown = set(spec) - set(_DRIVER_KEYS)
            if unknown:
                raise SceneError(f"unknown key(s) {', '.join(sorted(unknown))}; use angle (or position), "
                                 "speed (or velocity), acceleration", path=str(self.path), key=f"drivers.{name}")
        return drivers

    def reference(self) -> Scene:
        """The scene as its file has it, with the overrides of everything but the drivers
        (a `--set guess...` picks the reference's assembly, `--angle` only the pose)."""
        if self.base is None:
            return self
        raw = copy.deepcopy(self.raw)
        raw["drivers"] = copy.deepcopy(self.base.get("drivers", {}))
        return Scene(self.path, raw, self.base)

    def assembly(self) -> Any:
        """The `assembly` value as written: absent (None), "any", or a table loop -> sign."""
        value = self.raw.get("assembly")
        if value is not None and value != "any" and not isinstance(value, dict):
            raise SceneError(f'must be "any" or a table such as assembly = {{ B = "+" }}, got {value!r}',
                             path=str(self.path), key="assembly")
        return value

    @staticmethod
    def driver_order(key: str) -> int:
        return _DRIVER_KEYS[key]

    def solver_options(self) -> dict[str, float | int]:
        """`[solver]` settings: tol, max_iterations, max_condition (numbers)."""
        options = self.section("solver")
        allowed = {"tol": float, "max_iterations": int, "max_condition": float}
        out: dict[str, float | int] = {}
        for key, value in options.items():
            if key not in allowed:
                raise SceneError(f"unknown solver option {key}; known: {', '.join(allowed)}",
                                 path=str(self.path), key=f"solver.{key}")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
                raise SceneError(f"solver.{key} must be a positive number, got {value!r}",
                                 path=str(self.path), key=f"solver.{key}")
            low, high = SOLVER_RANGES[key]
            if not low <= value <= high:
                raise SceneError(f"solver.{key} = {value!r} is outside [{low:g}, {high:g}]",
                                 path=str(self.path), key=f"solver.{key}")
            if allowed[key] is int and value != int(value):  # 2.7 was cut to 2 in silence
                raise SceneError(f"solver.{key} = {value!r} must be a whole number of iterations",
                                 path=str(self.path), key=f"solver.{key}")
            out[key] = allowed[key](value)
        return out
