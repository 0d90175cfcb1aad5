"""One meshcat scene of a Pinocchio model: visuals, named points, labels, arrows, camera.

meshcat's camera orbits the world origin, so the drawing is shifted to put the centre of its
bounding box there, and the camera looks along a planar mechanism's normal from the distance
at which the drawing spans most of the view. meshcat (the extra `viz`) is imported inside
the functions only.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.draw.geometry import (
    _hex,
    _local_corners,
    _node,
    _pose,
    _round_length,
    _screen_up,
    _size,
    _translation,
)
from pinmech.draw.inputs import _check_visuals, _points, _stack, _unit, _vector3

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
    """One meshcat scene: the model's visuals under ROOT, points, labels, arrows, camera.

    `orthographic`: a planar view is drawn through an orthographic camera (offline pages,
    whose script keeps it centred when the window's shape changes); else nearly without
    perspective (a far camera, zoomed in).
    """

    def __init__(
        self,
        model: pin.Model,
        visual_model: pin.GeometryModel,
        window: Any,
        *,
        show_grid: bool,
        orthographic: bool = False,
    ) -> None:
        self.orthographic = orthographic
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
        self.planar = plane_normal is not None and self.orthographic
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
        if self.planar:  # a drawing of the plane: orthographic, no perspective at all
            half = max(float(np.max(np.abs(points @ self.up), initial=0.0)),
                       float(np.max(np.abs(points @ self.right), initial=0.0)) / _ASPECT, 1e-9) / _FILL
            g = _meshcat().geometry
            camera.set_object(g.OrthographicCamera(-half * _ASPECT, half * _ASPECT, half, -half,
                                                   distance / 100, distance * 100))
        camera.set_property("position", [eye[0], eye[2], -eye[1]])  # the camera's frame: x +90 deg
        camera.set_property("zoom", 1.0 if self.planar else self.zoom)
        camera.set_property("near", distance / 100)
        camera.set_property("far", distance * 100)

    def add_points(
        self, points: Mapping[str, np.ndarray], size: float, groups: list[list[str]] | None = None
    ) -> None:
        """Draw named points (world frame [m]) as dark dots with their names; points at one
        place (B of the crank, B3 of the guide under it) share one label, "B, B3".

        Args:
            groups: the names that share a label (default: those at one place now).
        """
        g = _meshcat().geometry
        for name, p in points.items():
            node = self.vis[f"{ROOT}/points/{_node(name)}"]
            on_top = g.MeshBasicMaterial(color=_POINT_COLOUR, transparent=True, depthTest=False)
            node.set_object(g.Sphere(0.01 * size), on_top)  # seen through the bodies
            node.set_transform(_translation(p))
        for names in groups if groups is not None else coincident_groups(points, 1e-6 * size):
            self.add_label(f"points/{_node(names[0])}/label", ", ".join(names), self._label_offset(size), size)

    def add_trace(self, name: str, path: np.ndarray, colour: tuple[float, float, float]) -> None:
        """The path of a point over the frames (world frame [m], shape (n, 3)), a thin line in
        a pale shade of its colour (the links stay the strongest colours on the page)."""
        g = _meshcat().geometry
        finite = path[np.all(np.isfinite(path), axis=1)]
        if len(finite) < 2:
            return
        pale = tuple(0.5 + 0.5 * c for c in colour)
        line = g.Line(g.PointsGeometry(finite.T.astype(np.float32)), g.LineBasicMaterial(color=_hex(pale)))
        self.vis[f"{ROOT}/traces/{_node(name)}"].set_object(line)

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


def coincident_groups(points: Mapping[str, np.ndarray], tol: float) -> list[list[str]]:
    """Names of the points, grouped where they lie within `tol` [m] of each other (in order)."""
    groups: list[list[str]] = []
    for name, p in points.items():
        for group in groups:
            if np.linalg.norm(points[group[0]] - p) <= tol:
                group.append(name)
                break
        else:
            groups.append([name])
    return groups


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



@functools.cache
def _sprite_classes() -> tuple[type, type]:
    """three.js sprites (always facing the camera), which meshcat-python does not name."""
    g = _meshcat().geometry

    class SpriteMaterial(g.GenericMaterial):
        _type = "SpriteMaterial"

    class Sprite(g.Object):
        _type = "Sprite"

    return SpriteMaterial, Sprite

