"""A table's first mistake (`Invalid`) turned into the one-line SceneError users read: the
file, the key path where the mistake is (`sweep.steps`, `load[0].force[1]`), and what was
expected with the value given."""

from __future__ import annotations

from pathlib import Path

from pinmech.exceptions import SceneError
from pinmech.io.scene_fields import Invalid

#: What each of msgspec's type names expects, as a scene's reader says it.
_EXPECTED = {"str": "a string", "bool": "true or false", "int": "a whole number", "float": "a number",
             "array": "a list", "object": "a table"}


def key_path(loc: tuple[str | int, ...]) -> str:
    """("load", 0, "force") -> "load[0].force"."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def scene_error(exc: Invalid, path: Path) -> SceneError:
    """`exc` as a SceneError (or the UnitError a quantity raised), naming the file and key."""
    refused = exc.refused
    if refused is not None:
        key = refused.key or key_path(exc.loc + refused.at)
        return refused.error(refused.message, path=str(path), key=key or None)
    if exc.wrong is None:
        return SceneError("missing", path=str(path), key=key_path(exc.loc) or None)
    expected = exc.wrong.expected.split(" | ")[0]
    said = f"must be {_EXPECTED[expected]}" if expected in _EXPECTED else f"must be {exc.wrong.expected}"
    return SceneError(f"{said}, got {exc.wrong.given!r}", path=str(path), key=key_path(exc.loc) or None)
