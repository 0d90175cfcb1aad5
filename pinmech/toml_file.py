"""The one reader of the TOML files users write (scenes, hand values, drawn linkages,
studies): a missing file or malformed TOML is one named error naming the file."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from pinmech.exceptions import PinmechError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

TOMLDecodeError = tomllib.TOMLDecodeError


def read_toml(path: Path, what: str, error: type[PinmechError]) -> dict[str, Any]:
    """The tables of the TOML file at `path` (`what`: "scene", "hand-value", ... for the
    message).

    Raises:
        error: "no such <what> file", or "malformed TOML: <where>", naming the file.
    """
    if not path.is_file():
        raise error(f"no such {what} file", path=str(path))
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise error(f"malformed TOML: {exc}", path=str(path)) from exc


def toml_value(text: str) -> Any:
    """One TOML value written as text (`"10 deg"`, `[1, 2]`); TOMLDecodeError otherwise."""
    return tomllib.loads(f"v = {text}")["v"]
