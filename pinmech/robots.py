"""Robots from example-robot-data, by name, as URDF paths: no meshes, no RobotWrapper.

The loaders package (`pip install "pinmech[robots]"`) knows where each robot's URDF lies;
pinmech then builds a kinematic model only (no visual or collision geometry) and locks
every joint a scene does not move.
"""

from __future__ import annotations

from os.path import join
from pathlib import Path

from pinmech.exceptions import SceneError


def robot_urdf(name: str, *, where: str = "") -> Path:
    """Path of the URDF of an example-robot-data robot ("ur5", "panda", "talos", ...).

    Raises:
        ImportError: the loaders are not installed (names the extra to install).
        SceneError: no robot of that name.
    """
    try:
        import example_robot_data as erd
    except ImportError as exc:
        raise ImportError(
            f"robot = \"{name}\" needs example-robot-data: pip install \"pinmech[robots]\""
        ) from exc
    loader = erd.ROBOTS.get(name)
    if loader is None:
        known = ", ".join(sorted(erd.ROBOTS)[:30])
        raise SceneError(f"unknown robot {name!r}; example-robot-data has: {known}, ...", path=where, key="robot")
    if not loader.urdf_filename:
        raise SceneError(f"robot {name!r} is described in SDF, not URDF", path=where, key="robot")
    relative = join(loader.path, loader.urdf_subpath, loader.urdf_filename)
    return Path(join(erd.getModelPath(relative), relative)).resolve()
