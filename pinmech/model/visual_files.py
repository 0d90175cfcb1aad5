"""Which mesh files a drawing may embed: those of the model's own package.

An offline page (`pinmech snapshot`, `animate`) carries its meshes inside it and is made
to be mailed, so it must not carry any other file a URDF can name (`../../x`, an absolute
path, `file://`, `package://../..`). A mesh is embedded only when its real path (links
followed) lies in one of:

- the URDF's package: the nearest folder above the URDF holding a `package.xml` (ROS
  layout: pkg/urdf/robot.urdf with pkg/meshes/...), else the URDF's own folder;
- a package the URDF names, `package://NAME/...`, found in the package folders, when
  it is a package (it holds a `package.xml`).

Others are left out of the drawing, and listed so the user is told.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path

import pinocchio as pin

_PACKAGE = re.compile(r"package://([^/\s\"']+)/")


def package_roots(urdf_path: str | Path, package_dirs: Sequence[str | Path]) -> list[Path]:
    """The folders whose files the URDF's drawing may embed (real paths)."""
    urdf = Path(os.path.realpath(urdf_path))
    own = next((d for d in urdf.parents if (d / "package.xml").is_file()), urdf.parent)
    roots = [own]
    names = set(_PACKAGE.findall(urdf.read_text(encoding="utf-8", errors="replace")))
    for name in sorted(names - {".", ".."}):
        for folder in package_dirs:
            candidate = Path(os.path.realpath(Path(folder) / name))
            if (candidate / "package.xml").is_file():
                roots.append(candidate)
                break
    return roots


def drop_outside(visuals: pin.GeometryModel, model: pin.Model, roots: Sequence[Path]) -> list[str]:
    """Remove the visuals whose mesh file lies outside every root; what was removed, as
    "FILE (link NAME)". Primitive shapes (boxes, cylinders: no file) are kept."""
    skipped, names = [], []
    for obj in visuals.geometryObjects:
        mesh = str(obj.meshPath)
        if os.sep not in mesh:  # "BOX", "CYLINDER", ...: no file
            continue
        real = Path(os.path.realpath(mesh))
        if not any(real == root or root in real.parents for root in roots):
            skipped.append(f"{mesh} (link {model.frames[obj.parentFrame].name})")
            names.append(str(obj.name))
    for name in names:  # after the loop: removing invalidates the objects seen
        visuals.removeGeometryObject(name)
    return skipped
