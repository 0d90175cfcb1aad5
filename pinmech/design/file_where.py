"""Reading a design file (study, workspace, synthesis) and checking its keys: errors are
SceneErrors naming the file and the key."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, TypeVar

from pinmech.exceptions import SceneError
from pinmech.known_keys import unknown_keys
from pinmech.toml_file import read_toml

Spec = TypeVar("Spec")


def load_file(path: str | Path, kind: str, parse: Callable[[dict[str, Any], Path], Spec]) -> Spec:
    """parse of the TOML file at path (a `kind` file, named in errors) and its path."""
    path = Path(path)
    return parse(read_toml(path, kind, SceneError), path)


class FileWhere:
    """A design file, for errors naming it and the key. Subclasses set `limits` (a whole
    number key -> (lowest, highest)) and `dotted` (an unknown key named with its table's)."""

    limits: dict[str, tuple[int, int]] = {}
    dotted: bool = False

    def __init__(self, path: Path) -> None:
        self.path = path

    def error(self, key: str, message: str) -> SceneError:
        return SceneError(message, path=str(self.path), key=key)

    def known(self, table: Any, keys: set[str], key: str) -> None:
        """Refuse a table that is not one, or has a key not in keys (key: the table's name)."""
        if not isinstance(table, dict):
            raise self.error((key or "(top)") if self.dotted else key, f"must be a table, got {table!r}")
        message = unknown_keys(table, sorted(keys))
        if message:
            first = min(set(table) - keys)
            named = (f"{key}.{first}" if key else first) if self.dotted else (key or first)
            raise self.error(named, message)

    def whole(self, raw: dict, key: str, default: int) -> int:
        """raw[key] (default if absent), a whole number within limits[key]."""
        value = raw.get(key, default)
        low, high = self.limits[key]
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise self.error(key, f"{key} = {value!r} must be a whole number from {low} to {high}")
        return value
