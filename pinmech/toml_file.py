"""The one reader of the TOML files users write (scenes, hand values, drawn linkages,
studies): a missing, huge, deeply nested or malformed file is one named error naming the
file (file_limits.py); a byte-order mark and CRLF line ends are read as plain UTF-8."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from pinmech.exceptions import PinmechError
from pinmech.file_limits import check_nesting, file_text, nested_too_deep

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

TOMLDecodeError = tomllib.TOMLDecodeError


def read_toml(path: Path, what: str, error: type[PinmechError]) -> dict[str, Any]:
    """The tables of the TOML file at `path` (`what`: "scene", "hand-value", ... for the
    message).

    Raises:
        error: "no such <what> file", a file over file_limits' size or nesting, or
            "malformed TOML: <where>", naming the file.
    """
    try:
        tables = tomllib.loads(file_text(path, what, error))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise error(f"malformed TOML: {exc}", path=str(path)) from exc
    except RecursionError:
        raise nested_too_deep(what, path, error) from None
    check_nesting(tables, what, path, error)
    return tables


def toml_value(text: str) -> Any:
    """One TOML value written as text (`"10 deg"`, `[1, 2]`); TOMLDecodeError otherwise."""
    return tomllib.loads(f"v = {text}")["v"]
