"""What the page saves: the linkage as a drawn-linkage TOML file (the values a drag changed
rewritten in the user's file, every comment kept, where that reads back as the page's
linkage; else the file written whole, its leading comments kept as its header), a scene that sweeps it from the drawn pose, and the figures
of what is on screen (SVG as the page draws it, PNG as the browser rasterised it). Every
file is written whole, through a temporary file renamed when complete.
"""

from __future__ import annotations

import base64
from pathlib import Path

from pinmech.exceptions import PinmechError
from pinmech.model.linkage_spec import LinkageSpec
from pinmech.model.linkage_write import linkage_toml
from pinmech.outputs import write_whole, write_with


def leading_comments(path: Path) -> str:
    """The comment lines a file opens with, without their "# " (the header written back)."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return ""
    header = []
    for line in lines:
        if not line.startswith("#"):
            break
        header.append(line[1:].removeprefix(" "))
    return "\n".join(header)


def save_linkage(spec: LinkageSpec, path: Path, header: str) -> Path:
    """Write the linkage to `path`, atomically: the file there with the changed values
    rewritten in place (`save_inline`), or, when that cannot be, whole (its header comment
    lines first)."""
    write_whole(path, _kept_text(spec, path) or linkage_toml(spec, header))
    return path


def _kept_text(spec: LinkageSpec, path: Path) -> str | None:
    """The file at `path` with only `spec`'s changes rewritten, or None (no such file, not a
    linkage, or changes that are not line by line)."""
    import tomllib

    from pinmech.draw.design_page.save_inline import rewritten
    from pinmech.model.linkage_spec import linkage_spec

    try:
        text = path.read_text(encoding="utf-8")
        old = linkage_spec(tomllib.loads(text), str(path))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, PinmechError):
        return None
    return rewritten(text, old, spec, str(path))


def save_scene(tables: dict, linkage_path: Path, path: Path) -> Path:
    """Write the scene of `tables` (`frame.scene_tables`) to `path`, naming the linkage by a
    path relative to the scene's folder."""
    import os

    tables = dict(tables, linkage=os.path.relpath(linkage_path.resolve(), path.resolve().parent))
    (name, driver), = tables["drivers"].items()
    lines = [
        f"# A scene of {linkage_path.name}, written by pinmech design: its driver at the drawn pose.",
        f"# pinmech sweep {path.name}",
        f"title = {_string(tables['title'])}",
        f"linkage = {_string(tables['linkage'])}",
        "",
        f"[drivers.{name}]",
        f"angle = {_string(driver['angle'])}",
        f"speed = {_string(driver['speed'])}",
        "",
        "[report]",
        "points = [" + ", ".join(_string(p) for p in tables["report"]["points"]) + "]",
    ]
    write_whole(path, "\n".join(lines) + "\n")
    return path


def figure_contents(svg: object, png_data_url: object) -> dict[str, bytes]:
    """The page's figure checked before anything is saved: {".svg": ..., ".png": ...} (either
    may be absent), so that a bad figure leaves no file of the save written.

    Raises:
        PinmechError: an SVG that is not text, a PNG that is not a base64 data URL of a PNG.
    """
    import binascii

    contents = {}
    if svg is not None and not isinstance(svg, str):
        raise PinmechError(f"the page sent an SVG that is not text (a {type(svg).__name__})")
    if svg:
        contents[".svg"] = svg.encode("utf-8")
    if png_data_url is not None and not isinstance(png_data_url, str):
        raise PinmechError(f"the page sent a PNG that is not a data URL (a {type(png_data_url).__name__})")
    if png_data_url:
        prefix = "data:image/png;base64,"
        if not png_data_url.startswith(prefix):
            raise PinmechError("the page sent a PNG that is not a data:image/png;base64 URL")
        try:
            data = base64.b64decode(png_data_url[len(prefix):], validate=True)
        except binascii.Error as exc:
            raise PinmechError(f"the page sent a PNG whose base64 data is malformed ({exc})") from None
        if not data.startswith(b"\x89PNG"):
            raise PinmechError("the page sent a PNG whose data is not a PNG")
        contents[".png"] = data
    return contents


def save_figure(contents: dict[str, bytes], stem: Path) -> list[Path]:
    """Write `figure_contents` as `stem`.svg and `stem`.png, each whole."""
    return [write_with(stem.with_suffix(suffix), lambda temporary, data=data: Path(temporary).write_bytes(data))
            for suffix, data in contents.items()]


def _string(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's: \\", \\\\, \\uXXXX)."""
    import json

    return json.dumps(text)
