"""Offline meshcat drawings: one solved pose, or a driver cycle as an animation.

meshcat (extra `viz`) is imported here only. A static page needs no server: an in-process
stand-in for meshcat's ZMQ server keeps the scene tree and writes the same self-contained
HTML (meshcat's JavaScript embedded, about 850 KB, no network). The drawing is centred on
the world origin (where meshcat's camera looks), and the camera looks along a planar
mechanism's normal from a distance that makes it fill most of the view.
"""

from __future__ import annotations

import base64
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinmech.exceptions import ModelError
from pinmech.mechanism import Mechanism

INSTALL_HINT = 'drawing needs meshcat: pip install "pinmech[viz]"'
ROOT = "pinmech"
_FOV_DEG = 75.0  # meshcat's default perspective camera
_FILL = 0.85  # share of the view the mechanism should span
_ASPECT = 4 / 3  # a typical browser window, width / height


def _meshcat():
    try:
        import meshcat
        import meshcat.geometry
    except ImportError as exc:
        raise ImportError(INSTALL_HINT) from exc
    return meshcat


@dataclass(frozen=True)
class Arrow:
    """A vector drawn from a point: start [m], vector (any unit), RGB colour in [0, 1]."""

    start: np.ndarray
    vector: np.ndarray
    color: tuple[float, float, float]
    label: str = ""


class _OfflineWindow:
    """Stands in for meshcat's ZMQ server: keeps the scene tree and renders static HTML."""

    web_url = "(offline: no server)"

    def __init__(self) -> None:
        from meshcat.servers.tree import SceneTree

        self.tree = SceneTree()

    def send(self, command) -> None:
        import umsgpack
        from meshcat.servers.tree import find_node

        data = command.lower()
        packed = umsgpack.packb(data)
        node = find_node(self.tree, [p for p in data["path"].split("/") if p])
        kind = data["type"]
        if kind == "set_transform":
            node.transform = packed
        elif kind == "set_object":
            node.object, node.properties = packed, []
        elif kind == "set_property":
            node.properties.append(packed)
        elif kind == "set_animation":
            node.animation = packed

    def get_scene(self) -> str:
        from meshcat.servers.tree import walk

        commands = []
        for node in walk(self.tree):
            for blob in ([node.object] if node.object is not None else []) + list(node.properties) + \
                    ([node.transform] if node.transform is not None else []) + \
                    ([node.animation] if node.animation is not None else []):
                commands.append(
                    'fetch("data:application/octet-binary;base64,' + base64.b64encode(blob).decode() + '")'
                    ".then(r => r.arrayBuffer()).then(b => viewer.handle_command_bytearray(new Uint8Array(b)));"
                )
        script = (Path(_meshcat().__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")
        return (
            "<!DOCTYPE html>\n<html><head><meta charset=utf-8><title>pinmech</title>"
            "<style>body{margin:0} #meshcat-pane{width:100vw;height:100vh;overflow:hidden}</style></head>"
            f'<body><div id="meshcat-pane"></div><script>{script}</script><script>'
            'var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));\n'
            + "\n".join(commands) + "</script></body></html>\n"
        )


def load_visuals(mechanism: Mechanism) -> pin.GeometryModel:
    """The visual geometry of the mechanism's URDF (meshes too), built only when drawing."""
    path = Path(mechanism.source).resolve()
    package_dirs = [str(p) for p in path.parents][:6]  # package://NAME/... resolves in one of these
    try:
        return pin.buildGeomFromUrdf(mechanism.model, str(path), pin.GeometryType.VISUAL, package_dirs=package_dirs)
    except (ValueError, RuntimeError) as exc:
        raise ModelError(f"cannot load its visual geometry: {exc}", path=str(path)) from exc


class Drawing:
    """A meshcat scene of one mechanism: geometry, named points, arrows, camera."""

    def __init__(self, mechanism: Mechanism, *, visuals: pin.GeometryModel | None = None,
                 live: bool = False, show_grid: bool = True) -> None:
        meshcat = _meshcat()
        from pinocchio.visualize import MeshcatVisualizer

        self.mechanism = mechanism
        self.visuals = visuals if visuals is not None else load_visuals(mechanism)
        window = None if live else _OfflineWindow()
        self.vis = meshcat.Visualizer(window=window) if window is not None else meshcat.Visualizer()
        self.viz = MeshcatVisualizer(mechanism.model, self.visuals, self.visuals)
        self.viz.initViewer(viewer=self.vis)
        self.viz.loadViewerModel(rootNodeName=ROOT)
        self.centre = np.zeros(3)
        for key in ("top_color", "bottom_color"):  # a white page, as in a report
            self.vis["/Background"].set_property(key, [1.0, 1.0, 1.0])
        if not show_grid:
            self.vis["/Grid"].set_property("visible", False)
            self.vis["/Axes"].set_property("visible", False)

    # ------------------------------------------------------------------ content
    def placements(self, q: np.ndarray) -> list[np.ndarray]:
        """Homogeneous world transforms of every visual at q."""
        pin.forwardKinematics(self.viz.model, self.viz.data, q)
        pin.updateGeometryPlacements(self.viz.model, self.viz.data, self.visuals, self.viz.visual_data)
        return [self.viz.visual_data.oMg[i].homogeneous for i in range(self.visuals.ngeoms)]

    def frame_poses(self, qs: Sequence[np.ndarray], extra: Sequence[np.ndarray] = ()) -> None:
        """Centre the drawing at the origin and aim the camera, from every pose drawn."""
        sizes = [_geometry_size(g) for g in self.visuals.geometryObjects]
        lows, highs = [np.asarray(p) for p in extra], [np.asarray(p) for p in extra]
        for q in qs:
            for T, size in zip(self.placements(q), sizes):
                lows.append(T[:3, 3] - size)
                highs.append(T[:3, 3] + size)
        lo = np.min(lows, axis=0) if lows else np.zeros(3)
        hi = np.max(highs, axis=0) if highs else np.zeros(3)
        self.centre = 0.5 * (lo + hi)
        self.vis[ROOT].set_transform(_translation(-self.centre))
        self._aim(hi - lo)

    def _aim(self, size: np.ndarray) -> None:
        normal = self.mechanism.plane_normal
        view = normal if normal is not None else np.array([1.0, 0.8, 0.6]) / np.linalg.norm([1.0, 0.8, 0.6])
        up = _screen_up(view)
        right = np.cross(up, view)
        tan = math.tan(math.radians(_FOV_DEG) / 2)
        height, width = float(np.abs(up) @ size), float(np.abs(right) @ size)  # the box, seen
        distance = max(height / (2 * tan * _FILL), width / (2 * tan * _ASPECT * _FILL), 1e-9)
        distance += 0.5 * float(np.abs(view) @ size)  # from the box's near face, not its centre
        eye = view * distance
        if normal is not None:  # straight down the normal leaves "up" undefined: tilt a hair
            eye = eye - up * 1e-3 * distance  # so that world y (or z) is up
        rotated = np.array([eye[0], eye[2], -eye[1]])  # world -> meshcat's camera frame (x +90 deg)
        self.vis["/Cameras/default/rotated/<object>"].set_property("position", rotated.tolist())

    def show(self, q: np.ndarray) -> None:
        for visual, T in zip(self.visuals.geometryObjects, self.placements(q)):
            self.vis[self.viz.getViewerNodeName(visual, pin.GeometryType.VISUAL)].set_transform(
                T @ np.diag([*visual.meshScale, 1.0]))

    def points(self, positions: dict[str, np.ndarray], radius: float) -> None:
        g = _meshcat().geometry
        for name, p in positions.items():
            node = self.vis[f"{ROOT}/points/{name}"]
            node.set_object(g.Sphere(radius), g.MeshLambertMaterial(color=0x222222))
            node.set_transform(_translation(p))

    def arrows(self, arrows: Sequence[Arrow], length: float) -> None:
        """Draw arrows, each colour (one kind of quantity) scaled so its longest is `length` [m]."""
        g = _meshcat().geometry
        longest: dict[tuple, float] = {}
        for a in arrows:
            longest[a.color] = max(longest.get(a.color, 0.0), float(np.linalg.norm(a.vector)))
        for i, a in enumerate(arrows):
            scale = length / longest[a.color] if longest[a.color] > 0 else 0.0
            vec = np.asarray(a.vector) * scale
            n = float(np.linalg.norm(vec))
            if n == 0:
                continue
            colour = int(255 * a.color[0]) << 16 | int(255 * a.color[1]) << 8 | int(255 * a.color[2])
            material = g.MeshLambertMaterial(color=colour)
            radius = 0.02 * length
            R = _rotation_y_to(vec / n)
            shaft = self.vis[f"{ROOT}/arrows/{i}/shaft"]
            shaft.set_object(g.Cylinder(0.8 * n, radius), material)
            shaft.set_transform(_pose(R, np.asarray(a.start) + 0.4 * vec))
            head = self.vis[f"{ROOT}/arrows/{i}/head"]
            head.set_object(g.Cylinder(0.2 * n, radiusTop=0.0, radiusBottom=2.5 * radius), material)
            head.set_transform(_pose(R, np.asarray(a.start) + 0.9 * vec))

    def html(self) -> str:
        return self.vis.static_html()


def snapshot_html(mechanism: Mechanism, q: np.ndarray, *, points: dict[str, np.ndarray] | None = None,
                  arrows: Sequence[Arrow] = (), show_grid: bool = True) -> str:
    """A self-contained HTML page of the mechanism at q, framed, with points and arrows."""
    drawing = Drawing(mechanism, show_grid=show_grid)
    drawing.show(q)
    points = points or {}
    drawing.frame_poses([q], list(points.values()))
    size = mechanism.length_scale
    drawing.points(points, 0.02 * size)
    drawing.arrows(arrows, 0.35 * size)
    return drawing.html()


def animation_html(mechanism: Mechanism, qs: Sequence[np.ndarray], *, fps: int = 30,
                   show_grid: bool = True) -> str:
    """A self-contained HTML page playing the poses `qs` as a meshcat animation."""
    meshcat = _meshcat()
    from meshcat.animation import Animation

    drawing = Drawing(mechanism, show_grid=show_grid)
    drawing.show(qs[0])
    drawing.frame_poses(qs)
    animation = Animation(default_framerate=fps)
    names = [drawing.viz.getViewerNodeName(v, pin.GeometryType.VISUAL) for v in drawing.visuals.geometryObjects]
    for i, q in enumerate(qs):
        with animation.at_frame(drawing.vis, i) as frame:
            for visual, name, T in zip(drawing.visuals.geometryObjects, names, drawing.placements(q)):
                frame[name].set_transform(T @ np.diag([*visual.meshScale, 1.0]))
    drawing.vis.set_animation(animation, play=True, repetitions=0)
    del meshcat
    return drawing.html()


def live_view(mechanism: Mechanism, q: np.ndarray) -> str:
    """Draw in a live meshcat server (opened in a browser by the user); returns its URL."""
    drawing = Drawing(mechanism, live=True)
    drawing.show(q)
    drawing.frame_poses([q])
    return drawing.vis.url()


# ---------------------------------------------------------------------- geometry helpers
def _translation(p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def _pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = _translation(p)
    T[:3, :3] = R
    return T


def _any_perpendicular(v: np.ndarray) -> np.ndarray:
    helper = np.eye(3)[int(np.argmin(np.abs(v)))]
    w = helper - v * (v @ helper)
    return w / np.linalg.norm(w)


def _screen_up(view: np.ndarray) -> np.ndarray:
    """The world direction to show upwards when looking along `view`: y, else z."""
    for axis in (np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])):
        up = axis - view * (view @ axis)
        if np.linalg.norm(up) > 0.5:
            return up / np.linalg.norm(up)
    return _any_perpendicular(view)


def _rotation_y_to(u: np.ndarray) -> np.ndarray:
    """A rotation taking the y axis (meshcat cylinders' axis) to the unit vector u."""
    y = np.array([0.0, 1.0, 0.0])
    axis = np.cross(y, u)
    s, c = np.linalg.norm(axis), float(y @ u)
    if s < 1e-12:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    return pin.exp3(axis / s * math.atan2(s, c))


def _geometry_size(obj: pin.GeometryObject) -> float:
    """Half the largest dimension of a primitive (0 for meshes: their placement suffices)."""
    geom = obj.geometry
    for attr in ("halfSide",):
        if hasattr(geom, attr):
            return float(np.max(getattr(geom, attr)))
    if hasattr(geom, "radius"):
        return float(max(geom.radius, getattr(geom, "halfLength", 0.0)))
    return 0.0
