"""meshcat drawings of a Pinocchio model: one pose or an animation, as an offline HTML page.

The inputs are plain Pinocchio objects and numpy arrays (a `pin.Model`, its visual
`pin.GeometryModel`, configuration vectors, points and vectors in the world frame), so this
module knows nothing of scenes or solvers. meshcat (the extra `viz`) is imported inside the
functions only.

A static page needs no server: `_OfflineWindow` stands in for meshcat's ZMQ server, keeps
the scene tree and writes one self-contained page (meshcat's JavaScript embedded, about
850 KB, no network). meshcat's camera orbits the world origin, so the drawing is shifted to
put the centre of its bounding box there, and the camera looks along a planar mechanism's
normal from the distance at which the drawing spans most of the view.
"""

from __future__ import annotations

import base64
import contextlib
import functools
import html
import io
import itertools
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.exceptions import PinmechError

INSTALL_HINT = 'drawing needs meshcat: pip install "pinmech[viz]"'
ROOT = "pinmech"  # the drawing's node in meshcat's scene tree
_FOV_DEG = 75.0  # vertical field of view of meshcat's default camera [deg]
_ASPECT = 4 / 3  # width / height of a typical browser window
_FILL = 0.85  # share of the view's width or height the drawing spans
_ARROW_SHARE = 1 / 3  # longest arrow of a unit, as a share of the drawing's size
_OBLIQUE = np.array([1.0, 0.6, 0.8]) / np.linalg.norm([1.0, 0.6, 0.8])  # towards the camera, 3-D
_OBLIQUE_ZOOM = 3.0  # camera zoom of a 3-D view: mild perspective
_PLANAR_ZOOM = 10.0  # camera zoom of a planar view: nearly no perspective
_POINT_COLOUR = 0x222222


class DrawError(PinmechError):
    """An input of the drawing layer is malformed: wrong shape, not finite, unreadable.

    Attributes:
        argument: name of the offending argument ("q", "plane_normal", "urdf_path", ...).
        value: the offending value, or its shape.
    """

    exit_code = 9

    def __init__(self, message: str, *, argument: str, value: Any = None):
        super().__init__(message)
        self.argument = argument
        self.value = value


@dataclass(frozen=True)
class Arrow:
    """A vector drawn from a point; arrows of one unit share one scale.

    Attributes:
        start: tail, world frame [m], shape (3,).
        vector: the vector in world axes, in `unit` (m/s, m/s^2, N, ...), shape (3,).
        color: RGB in [0, 1].
        label: text drawn at the tip ("" for none).
        unit: the vector's unit, named in the page's legend.
    """

    start: np.ndarray
    vector: np.ndarray
    color: tuple[float, float, float] = (0.1, 0.2, 0.9)
    label: str = ""
    unit: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", _vector3(self.start, "Arrow.start"))
        object.__setattr__(self, "vector", _vector3(self.vector, "Arrow.vector"))


def arrow_scales(arrows: Sequence[Arrow], size: float) -> dict[str, float]:
    """Drawn length per unit of each arrow unit [m per unit].

    Args:
        arrows: the arrows to draw.
        size: size of the drawing [m]; the longest arrow of each unit is a third of it.
    """
    longest: dict[str, float] = {}
    for arrow in arrows:
        longest[arrow.unit] = max(longest.get(arrow.unit, 0.0), float(np.linalg.norm(arrow.vector)))
    return {unit: _ARROW_SHARE * size / n if n > 0 else 0.0 for unit, n in longest.items()}


def load_visuals(
    urdf_path: str | Path, model: pin.Model, package_dirs: Sequence[str | Path] = ()
) -> pin.GeometryModel:
    """The visual geometry of a URDF (meshes of its own package only), built only when
    drawing; `package_visuals` also says which meshes were left out."""
    return package_visuals(urdf_path, model, package_dirs)[0]


def package_visuals(
    urdf_path: str | Path, model: pin.Model, package_dirs: Sequence[str | Path] = ()
) -> tuple[pin.GeometryModel, list[str]]:
    """The visual geometry of a URDF, and the mesh files left out of it because they lie
    outside the model's own package (visual_files.py: a page must carry no other file).

    Args:
        urdf_path: the URDF file `model` was built from.
        model: the kinematic model the visuals hang on.
        package_dirs: folders holding `package://NAME/...` meshes; by default the URDF's
            own folder and its parents.
    """
    from pinmech.visual_files import drop_outside, package_roots

    path = Path(urdf_path)
    if not path.is_file():
        raise DrawError(f"no URDF file at {path}", argument="urdf_path", value=str(path))
    dirs = [str(d) for d in package_dirs] or [str(p) for p in path.resolve().parents][:5]
    try:
        visuals = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.VISUAL, package_dirs=dirs)
    except (ValueError, RuntimeError) as exc:
        raise DrawError(
            f"{path}: cannot build its visual geometry: {exc}",
            argument="urdf_path",
            value=str(path),
        ) from exc
    return visuals, drop_outside(visuals, model, package_roots(path, dirs))


def snapshot_html(
    model: pin.Model,
    visual_model: pin.GeometryModel,
    q: np.ndarray,
    *,
    points: Mapping[str, np.ndarray] | None = None,
    arrows: Sequence[Arrow] | None = None,
    plane_normal: np.ndarray | None = None,
    show_grid: bool = True,
    title: str = "pinmech",
) -> str:
    """A self-contained HTML page of the model at q, framed, with named points and arrows.

    Args:
        model: the kinematic model.
        visual_model: its visual geometry (`load_visuals`).
        q: configuration, shape (model.nq,).
        points: named points, world frame [m], drawn as dots with labels.
        arrows: vectors; each unit is scaled so that its longest arrow is a third of the
            drawing's size, and the page's title and legend state the scale.
        plane_normal: normal of a planar mechanism's plane (world axes): the camera looks
            along it. None: an oblique view.
        show_grid: draw meshcat's grid (cells of a round length, named in the legend) and axes.
        title: the page's title, before the legend.
    """
    scene = _Scene(model, visual_model, _OfflineWindow(), show_grid=show_grid)
    legend = _draw_pose(scene, _configuration(model, q, "q"), points, arrows, plane_normal)
    return scene.vis.window.page(title, legend)


def animation_html(
    model: pin.Model,
    visual_model: pin.GeometryModel,
    qs: Sequence[np.ndarray],
    *,
    fps: float = 30,
    points_per_frame: Sequence[Mapping[str, np.ndarray]] | None = None,
    plane_normal: np.ndarray | None = None,
    show_grid: bool = True,
    title: str = "pinmech",
) -> str:
    """A self-contained HTML page playing the poses qs in a loop (meshcat's play controls).

    The page shows one still frame when its address ends in `#frame=K` (K from 0).

    Args:
        qs: configurations, one per frame, each of shape (model.nq,).
        fps: frames per second [1/s].
        points_per_frame: named points of each frame, world frame [m] (same names in all).
        Others: as in `snapshot_html`. The drawing is framed for all poses at once.
    """
    qs = [_configuration(model, q, f"qs[{i}]") for i, q in enumerate(qs)]
    if not qs:
        raise DrawError("no poses to animate", argument="qs", value=0)
    if not fps > 0:
        raise DrawError(f"fps must be positive, got {fps}", argument="fps", value=fps)
    frames = (
        [_points(p) for p in points_per_frame] if points_per_frame is not None else [{}] * len(qs)
    )
    if len(frames) != len(qs):
        raise DrawError(
            f"{len(frames)} sets of points for {len(qs)} poses",
            argument="points_per_frame",
            value=len(frames),
        )
    scene = _Scene(model, visual_model, _OfflineWindow(), show_grid=show_grid)
    scene.orient(plane_normal)
    body = np.vstack([scene.corners(q) for q in qs] + [_stack(p) for p in frames])
    labels = scene.label_boxes([p for f in frames for p in f.values()], _size(body))
    size, grid = scene.frame(np.vstack([body, labels]))
    scene.pose(scene.vis, qs[0])
    scene.add_points(frames[0], size)
    _animate(scene, qs, frames, fps)
    return scene.vis.window.page(title, _legend(grid if show_grid else None, {}), fps=fps)


class LiveView:
    """A drawing served by meshcat's own server on this machine (loopback); `close()` stops it.

    Attributes:
        url: the address to open in a browser.
        visualizer: the `meshcat.Visualizer`, to draw more.
        legend: the drawing's scales, as in a static page's title.
    """

    def __init__(self, visualizer: Any, legend: str) -> None:
        self.visualizer = visualizer
        self.url: str = visualizer.url()
        self.legend = legend

    def close(self) -> None:
        """Stop the meshcat server this view started."""
        _stop_server(self.visualizer.window)

    def __enter__(self) -> Any:  # the view itself (typing.Self from Python 3.11 on)
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def live_viewer(
    model: pin.Model,
    visual_model: pin.GeometryModel,
    q: np.ndarray,
    *,
    points: Mapping[str, np.ndarray] | None = None,
    arrows: Sequence[Arrow] | None = None,
    plane_normal: np.ndarray | None = None,
    show_grid: bool = True,
) -> LiveView:
    """Start meshcat's server on loopback and draw the model at q in it (as `snapshot_html`).

    Returns:
        The running view: open `view.url` in a browser; `view.close()` stops the server.
    """
    meshcat = _meshcat()
    q = _configuration(model, q, "q")
    from pinmech.view_server import start_server

    process, zmq_url, _ = start_server()  # on 127.0.0.1 only, and stopping with pinmech (view_server.py)
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL: the caller decides
            window = meshcat.visualizer.ViewerWindow(zmq_url=zmq_url, start_server=False, server_args=[])
    except BaseException:
        process.kill()
        process.wait(timeout=10)
        raise
    window.server_proc = process
    try:
        scene = _Scene(model, visual_model, window, show_grid=show_grid)
        return LiveView(scene.vis, _draw_pose(scene, q, points, arrows, plane_normal))
    except BaseException:
        _stop_server(window)
        raise


def _stop_server(window: Any) -> None:
    """Close the socket to a meshcat server and stop the server process (ours)."""
    window.zmq_socket.close(linger=0)
    if window.server_proc is not None and window.server_proc.poll() is None:
        window.server_proc.kill()
        window.server_proc.wait(timeout=10)
    for pipe in (window.server_proc.stdin, window.server_proc.stdout) if window.server_proc is not None else ():
        if pipe is not None:
            pipe.close()


# ------------------------------------------------------------------------------------ drawing
def _meshcat() -> Any:
    try:
        with warnings.catch_warnings():  # meshcat's server module imports a deprecated zmq module
            warnings.simplefilter("ignore", DeprecationWarning)
            import meshcat
            import meshcat.animation
            import meshcat.geometry
            import meshcat.visualizer
    except ImportError as exc:
        raise ImportError(INSTALL_HINT) from exc
    return meshcat


class _Scene:
    """One meshcat scene: the model's visuals under ROOT, points, labels, arrows, camera."""

    def __init__(
        self, model: pin.Model, visual_model: pin.GeometryModel, window: Any, *, show_grid: bool
    ) -> None:
        meshcat = _meshcat()
        from pinocchio.visualize import MeshcatVisualizer

        _check_visuals(model, visual_model)
        self.vis = meshcat.Visualizer(window=window)
        self.viz = MeshcatVisualizer(model, None, visual_model)
        self.viz.initViewer(viewer=self.vis)
        self.viz.loadViewerModel(rootNodeName=ROOT)
        self.objects = list(visual_model.geometryObjects)
        self.names = [self.viz.getViewerNodeName(g, pin.GeometryType.VISUAL) for g in self.objects]
        self.local_corners = [_local_corners(g) for g in self.objects]
        self.orient(None)
        self.show_grid = show_grid
        for key in ("top_color", "bottom_color"):  # a white page, as in a report
            self.vis["/Background"].set_property(key, [1.0, 1.0, 1.0])
        self.vis["/Grid"].set_property("visible", show_grid)
        self.vis["/Axes"].set_property("visible", show_grid)

    def placements(self, q: np.ndarray) -> list[np.ndarray]:
        """World transforms (4x4, unscaled) of every visual at configuration q."""
        pin.forwardKinematics(self.viz.model, self.viz.data, q)
        pin.updateGeometryPlacements(
            self.viz.model, self.viz.data, self.viz.visual_model, self.viz.visual_data
        )
        return [M.homogeneous for M in self.viz.visual_data.oMg]

    def corners(self, q: np.ndarray) -> np.ndarray:
        """Corners of every visual's box at q, world frame [m], shape (n, 3)."""
        rows = [c @ T[:3, :3].T + T[:3, 3] for T, c in zip(self.placements(q), self.local_corners)]
        return np.vstack(rows) if rows else np.zeros((0, 3))

    def pose(self, target: Any, q: np.ndarray, *, scaled: bool = True) -> None:
        """Place the visuals at q in a visualizer or an animation frame (which keeps scales)."""
        for obj, name, T in zip(self.objects, self.names, self.placements(q)):
            target[name].set_transform(T @ np.diag([*obj.meshScale, 1.0]) if scaled else T)

    def orient(self, plane_normal: np.ndarray | None) -> None:
        """Choose the view: along a planar mechanism's normal (world y up), else oblique."""
        self.back = _unit(plane_normal, "plane_normal") if plane_normal is not None else _OBLIQUE
        self.zoom = _PLANAR_ZOOM if plane_normal is not None else _OBLIQUE_ZOOM
        self.up = _screen_up(self.back)
        self.right = np.cross(self.up, self.back)

    def frame(self, extent: np.ndarray) -> tuple[float, float]:
        """Centre the points `extent` [m] at the origin, aim the camera, scale the grid.

        Returns:
            The drawing's size (largest side of the bounding box) [m] and the grid cell [m].
        """
        extent = extent if len(extent) else np.zeros((1, 3))
        lo, hi = extent.min(axis=0), extent.max(axis=0)
        centre, size = 0.5 * (lo + hi), _size(extent)
        self.vis[ROOT].set_transform(_translation(-centre))
        self._aim(extent - centre, size)
        cell = _round_length(size / 8)
        self.vis["/Grid"].set_transform(
            _translation([-centre[0], -centre[1], lo[2] - centre[2] - 0.01 * size])
            @ np.diag([cell / 0.5] * 3 + [1.0])
        )  # meshcat's cells: 0.5 m
        self.vis["/Axes"].set_transform(_translation(-centre) @ np.diag([0.5 * size] * 3 + [1.0]))
        return size, cell

    def label_boxes(self, anchors: Sequence[np.ndarray], size: float) -> np.ndarray:
        """Corners of the labels of points or arrow tips at `anchors` [m], to frame them too."""
        corners = [
            a + self._label_offset(size) + 0.05 * size * (i * self.right + j * 0.6 * self.up)
            for a in anchors
            for i in (-1, 1)
            for j in (-1, 1)
        ]
        return np.reshape(corners, (-1, 3))

    def _aim(self, points: np.ndarray, size: float) -> None:
        """Put the camera on the `back` axis where `points` (centred, [m]) fill _FILL of the view.

        A zoom above 1 puts the camera that much farther away with a narrower view: less
        perspective (a planar mechanism seen as in a drawing, its grid under its joints).
        """
        back = self.back
        tan = math.tan(math.radians(_FOV_DEG) / 2) * _FILL / self.zoom
        depth = points @ back
        distance = float(
            np.max(
                np.concatenate(
                    [
                        depth + np.abs(points @ self.up) / tan,
                        depth + np.abs(points @ self.right) / (tan * _ASPECT),
                        depth + 0.05 * size,
                    ],
                    axis=None,
                )
            )
        )
        eye = back * distance
        if abs(back[2]) > 0.999:  # along world z (the orbit's up axis): tilt a hair so y is up
            eye = eye - math.copysign(1e-3, back[2]) * distance * self.up
        camera = self.vis["/Cameras/default/rotated/<object>"]
        camera.set_property("position", [eye[0], eye[2], -eye[1]])  # the camera's frame: x +90 deg
        camera.set_property("zoom", self.zoom)
        camera.set_property("near", distance / 100)
        camera.set_property("far", distance * 100)

    def add_points(self, points: Mapping[str, np.ndarray], size: float) -> None:
        """Draw named points (world frame [m]) as dark dots with their names."""
        g = _meshcat().geometry
        for name, p in points.items():
            node = self.vis[f"{ROOT}/points/{_node(name)}"]
            on_top = g.MeshBasicMaterial(color=_POINT_COLOUR, transparent=True, depthTest=False)
            node.set_object(g.Sphere(0.01 * size), on_top)  # seen through the bodies
            node.set_transform(_translation(p))
            self.add_label(f"points/{_node(name)}/label", name, self._label_offset(size), size)

    def move_points(self, frame: Any, points: Mapping[str, np.ndarray]) -> None:
        """Move the named points in one animation frame."""
        for name, p in points.items():
            frame[f"{ROOT}/points/{_node(name)}"].set_transform(_translation(p))

    def add_label(self, path: str, text: str, position: np.ndarray, size: float) -> None:
        """A text that always faces the camera, drawn over the geometry, at position [m] (in its parent)."""
        g = _meshcat().geometry
        texture = g.GenericTexture(
            {"type": "_text", "text": text, "font_size": 90, "font_face": "sans-serif"}
        )
        sprite_material, sprite = _sprite_classes()
        node = self.vis[f"{ROOT}/{path}"]
        node.set_object(
            sprite(
                g.Box([1, 1, 1]), sprite_material(map=texture, transparent=True, depthTest=False)
            )
        )
        node.set_transform(_translation(position) @ np.diag([0.1 * size] * 3 + [1.0]))

    def _label_offset(self, size: float) -> np.ndarray:
        return 0.035 * size * (self.right + 0.6 * self.up)

    def add_arrows(self, arrows: Sequence[Arrow], scales: Mapping[str, float], size: float) -> None:
        """Draw arrows (cylinder and cone), each unit at its scale [m per unit]."""
        g = _meshcat().geometry
        radius = 0.008 * size
        for i, arrow in enumerate(arrows):
            vec = arrow.vector * scales[arrow.unit]
            length = float(np.linalg.norm(vec))
            if length == 0.0:
                continue
            head = min(0.35 * length, 6 * radius)
            material = g.MeshLambertMaterial(color=_hex(arrow.color))
            R = pin.Quaternion.FromTwoVectors(
                np.array([0.0, 1.0, 0.0]), vec / length
            ).toRotationMatrix()
            shaft = self.vis[f"{ROOT}/arrows/{i}/shaft"]
            shaft.set_object(g.Cylinder(length - head, radius), material)
            shaft.set_transform(_pose(R, arrow.start + vec * (0.5 * (length - head) / length)))
            cone = self.vis[f"{ROOT}/arrows/{i}/head"]
            cone.set_object(g.Cylinder(head, radiusTop=0.0, radiusBottom=2.5 * radius), material)
            cone.set_transform(_pose(R, arrow.start + vec * ((length - 0.5 * head) / length)))
            if arrow.label:
                tip = arrow.start + vec + self._label_offset(size)
                self.add_label(f"arrows/{i}/label", arrow.label, tip, size)


def _draw_pose(
    scene: _Scene,
    q: np.ndarray,
    points: Mapping[str, np.ndarray] | None,
    arrows: Sequence[Arrow] | None,
    plane_normal: np.ndarray | None,
) -> str:
    """Draw one pose with its points and arrows, framed; returns the legend (scales)."""
    points, arrows = _points(points or {}), list(arrows or [])
    scene.orient(plane_normal)
    body = np.vstack([scene.corners(q), _stack(points)])
    scales = arrow_scales(arrows, _size(body))
    tips = [a.start + a.vector * scales[a.unit] for a in arrows]
    labelled = list(points.values()) + [tip for a, tip in zip(arrows, tips) if a.label]
    ends = np.reshape([a.start for a in arrows] + tips, (-1, 3))
    size, grid = scene.frame(np.vstack([body, ends, scene.label_boxes(labelled, _size(body))]))
    scene.pose(scene.vis, q)
    scene.add_points(points, size)
    scene.add_arrows(arrows, scales, size)
    return _legend(grid if scene.show_grid else None, scales)


def _animate(
    scene: _Scene, qs: Sequence[np.ndarray], frames: Sequence[Mapping[str, np.ndarray]], fps: float
) -> None:
    """One animation frame per pose (visuals and points), looping for ever."""
    meshcat = _meshcat()
    animation = meshcat.animation.Animation(default_framerate=fps)
    for i, (q, points) in enumerate(zip(qs, frames)):
        with animation.at_frame(scene.vis, i) as frame:
            scene.pose(frame, q, scaled=False)
            scene.move_points(frame, points)
    scene.vis.set_animation(animation, play=True, repetitions=math.inf)


def _legend(grid: float | None, scales: Mapping[str, float]) -> str:
    """The drawing's scales in words: the grid's cell, and each arrow unit's drawn length."""
    parts = [f"grid cells {_length(grid)}"] if grid else []
    arrows = [
        f"1 {unit or 'unit'} = {_length(scale)}" for unit, scale in scales.items() if scale > 0
    ]
    return "; ".join(parts + (["arrows: " + ", ".join(arrows)] if arrows else []))


def _length(metres: float) -> str:
    return f"{metres * 1000:.3g} mm" if metres < 1 else f"{metres:.3g} m"


# ------------------------------------------------------------------------------- offline page
class _OfflineWindow:
    """Stands in for meshcat's ZMQ server: keeps the scene tree, writes one offline page."""

    web_url = "(offline page: no server)"

    def __init__(self) -> None:
        _meshcat()
        from meshcat.servers.tree import SceneTree

        self.tree = SceneTree()
        self.animations: list[bytes] = []

    def send(self, command: Any) -> None:
        import umsgpack
        from meshcat.servers.tree import find_node

        data = command.lower()
        blob = umsgpack.packb(data)
        path = [p for p in data["path"].split("/") if p]
        kind = data["type"]
        if kind == "set_animation":
            self.animations = [blob]
        elif kind == "delete":
            parent = find_node(self.tree, path[:-1]) if path else None
            if parent is not None and path[-1] in parent:
                del parent[path[-1]]
        else:
            node = find_node(self.tree, path)
            if kind == "set_transform":
                node.transform = blob
            elif kind == "set_object":
                node.object, node.properties = blob, []
            elif kind == "set_property":
                node.properties.append(blob)

    def get_scene(self) -> str:
        """meshcat's `Visualizer.static_html()` asks for this."""
        return self.page("MeshCat", "")

    def page(self, title: str, legend: str, *, fps: float = 30.0) -> str:
        """The whole page: meshcat's script, then every command in tree order, animations last."""
        from meshcat.servers.tree import walk

        blobs = []
        for node in walk(self.tree):
            blobs += ([node.object] if node.object is not None else []) + list(node.properties)
            blobs += [node.transform] if node.transform is not None else []
        commands = "\n".join(
            f'command("{base64.b64encode(b).decode()}");' for b in blobs + self.animations
        )
        script = (Path(_meshcat().__file__).parent / "viewer" / "dist" / "main.min.js").read_text(
            encoding="utf-8"
        )
        heading = f"{title} ({legend})" if legend else title
        return _PAGE.format(
            title=html.escape(heading),
            legend=html.escape(legend),
            script=script,
            commands=commands,
            fps=float(fps),
        )


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>body {{margin: 0}} #meshcat-pane {{width: 100vw; height: 100vh; overflow: hidden}}
#legend {{position: fixed; left: 8px; bottom: 6px; font: 13px sans-serif; color: #444}}</style></head>
<body><div id="meshcat-pane"></div><div id="legend">{legend}</div>
<script>{script}</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
function command(b64) {{ viewer.handle_command_bytearray(Uint8Array.from(atob(b64), c => c.charCodeAt(0))); }}
{commands}
var still = /frame=(\\d+)/.exec(location.hash);
if (still && viewer.animator.duration > 0) {{ viewer.animator.pause(); viewer.animator.seek(Number(still[1]) / {fps}); }}
</script></body></html>
"""


@functools.cache
def _sprite_classes() -> tuple[type, type]:
    """three.js sprites (always facing the camera), which meshcat-python does not name."""
    g = _meshcat().geometry

    class SpriteMaterial(g.GenericMaterial):
        _type = "SpriteMaterial"

    class Sprite(g.Object):
        _type = "Sprite"

    return SpriteMaterial, Sprite


# ----------------------------------------------------------------------------- input checks
def _configuration(model: pin.Model, q: Any, argument: str) -> np.ndarray:
    return _floats(q, model.nq, argument, " (model.nq)")


def _vector3(value: Any, argument: str) -> np.ndarray:
    return _floats(value, 3, argument)


def _floats(value: Any, n: int, argument: str, why: str = "") -> np.ndarray:
    """value as a vector of n finite floats, else a DrawError naming the argument."""
    message = f"{argument} must be {n} finite numbers{why}, got {np.size(value)}: {value!r}"
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise DrawError(message, argument=argument, value=value) from exc
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise DrawError(message, argument=argument, value=value)
    return v


def _unit(value: Any, argument: str) -> np.ndarray:
    v = _vector3(value, argument)
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise DrawError(
            f"{argument} must be a non-zero vector, got {v}", argument=argument, value=v
        )
    return v / n


def _points(points: Mapping[str, Any]) -> dict[str, np.ndarray]:
    return {str(name): _vector3(p, f"points['{name}']") for name, p in points.items()}


def _stack(points: Mapping[str, np.ndarray]) -> np.ndarray:
    return np.array(list(points.values()), dtype=float).reshape(-1, 3)


def _check_visuals(model: pin.Model, visual_model: pin.GeometryModel) -> None:
    for obj in visual_model.geometryObjects:
        if obj.parentJoint >= model.njoints:
            raise DrawError(
                f"visual '{obj.name}' hangs on joint {obj.parentJoint} but the model has "
                f"{model.njoints} joints: the visuals belong to another model",
                argument="visual_model",
                value=obj.name,
            )


# --------------------------------------------------------------------------------- geometry
def _local_corners(obj: pin.GeometryObject) -> np.ndarray:
    """The 8 corners of a visual's bounding box in its own frame [m] (its origin if none)."""
    geometry = obj.geometry
    try:
        geometry.computeLocalAABB()
        lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    except (AttributeError, RuntimeError):
        return np.zeros((1, 3))
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo <= hi)):
        return np.zeros((1, 3))
    return np.array(list(itertools.product(*zip(lo, hi))))


def _screen_up(back: np.ndarray) -> np.ndarray:
    """The world direction shown upwards when the camera sits along `back` (unit).

    meshcat's orbit keeps world z up; looking along z itself, world y is shown up.
    """
    axis = np.array([0.0, 1.0, 0.0]) if abs(back[2]) > 0.999 else np.array([0.0, 0.0, 1.0])
    up = axis - back * (back @ axis)
    return up / np.linalg.norm(up)


def _size(points: np.ndarray) -> float:
    """Largest side of the points' bounding box [m] (1 mm at least, so that there is a view)."""
    return max(float(np.max(np.ptp(points, axis=0))), 1e-3) if len(points) else 1e-3


def _round_length(length: float) -> float:
    """The largest of 1, 2, 5 times a power of ten that is at most `length` [m]."""
    power = 10.0 ** math.floor(math.log10(length))
    return max(m * power for m in (1, 2, 5) if m * power <= length * (1 + 1e-9))


def _translation(p: Any) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def _pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = _translation(p)
    T[:3, :3] = R
    return T


def _hex(rgb: Sequence[float]) -> int:
    r, g, b = (round(255 * min(max(c, 0.0), 1.0)) for c in rgb[:3])
    return r << 16 | g << 8 | b


def _node(name: str) -> str:
    """A point's name as one meshcat path element."""
    return name.replace("/", "_") or "_"
