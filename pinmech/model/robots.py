"""Robots from example-robot-data, by name, as URDF paths: no meshes, no RobotWrapper.

The loaders package (`pip install "pinmech[robots]"`) knows where each robot's URDF lies;
pinmech then builds a kinematic model only (no visual or collision geometry) and locks
every joint a scene does not move.
"""

from __future__ import annotations

import difflib
from os.path import join
from pathlib import Path
from typing import Any

from pinmech.exceptions import SceneError


def _loader(name: str, where: str) -> Any:
    """example-robot-data's loader class of a robot (ImportError naming the extra if absent)."""
    try:
        import example_robot_data as erd
    except ImportError as exc:
        raise ImportError(
            f"robot = \"{name}\" needs example-robot-data: pip install \"pinmech[robots]\""
        ) from exc
    loader = erd.ROBOTS.get(name)
    if loader is None:
        close = difflib.get_close_matches(str(name), list(erd.ROBOTS), n=5)
        hint = f" (did you mean {', '.join(close)}?)" if close else ""
        known = ", ".join(sorted(erd.ROBOTS)[:30])
        raise SceneError(f"unknown robot {name!r}{hint}; example-robot-data has {len(erd.ROBOTS)}: {known}, ...",
                         path=where, key="robot")
    return loader


def robot_urdf(name: str, *, where: str = "") -> Path:
    """Path of the URDF of an example-robot-data robot ("ur5", "panda", "talos", ...).

    Raises:
        ImportError: the loaders are not installed (names the extra to install).
        SceneError: no robot of that name.
    """
    loader = _loader(name, where)
    import example_robot_data as erd  # importable: _loader checked it
    if not loader.urdf_filename:
        raise SceneError(f"robot {name!r} is described in SDF, not URDF", path=where, key="robot")
    relative = join(loader.path, loader.urdf_subpath, loader.urdf_filename)
    return Path(join(erd.getModelPath(relative), relative)).resolve()


def robot_root_joint(name: str, *, where: str = "") -> str | None:
    """"free_flyer" for a robot example-robot-data builds on a floating base (Talos,
    quadrupeds), None for a fixed-base arm: the `root_joint` of `Mechanism.from_urdf`
    that reproduces the loader's full model."""
    return "free_flyer" if getattr(_loader(name, where), "free_flyer", False) else None
