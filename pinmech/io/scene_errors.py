"""pydantic's ValidationError turned into the one-line SceneError users read: the file, the
key path where the first mistake is (`sweep.steps`, `load[0].force[1]`), and what was
expected with the value given."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import ValidationError

from pinmech.exceptions import SceneError
from pinmech.io.scene_fields import Refused

#: What each of pydantic's type errors expected, as a scene's reader says it.
_EXPECTED = {
    "string_type": "a string", "bool_type": "true or false", "int_type": "a whole number",
    "float_type": "a number", "list_type": "a list", "tuple_type": "a list", "dict_type": "a table",
    "model_type": "a table", "int_from_float": "a whole number", "finite_number": "a finite number",
}


def key_path(loc: tuple[str | int, ...]) -> str:
    """("load", 0, "force") -> "load[0].force"."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def scene_error(exc: ValidationError, path: Path) -> SceneError:
    """The first of `exc`'s errors as a SceneError (or the UnitError a quantity raised)."""
    error = exc.errors(include_url=False)[0]
    loc = tuple(error["loc"])
    refused = (error.get("ctx") or {}).get("error")
    if isinstance(refused, Refused):
        key = refused.key or key_path(loc + refused.at)
        return refused.error(refused.message, path=str(path), key=key or None)
    return SceneError(_message(error), path=str(path), key=key_path(loc) or None)


def _message(error: dict[str, Any]) -> str:
    kind = error["type"]
    if kind == "missing":
        return "missing"
    if kind == "extra_forbidden":
        return "unknown key"
    if kind in _EXPECTED:
        return f"must be {_EXPECTED[kind]}, got {error.get('input')!r}"
    return f"{error['msg']}, got {error.get('input')!r}"
