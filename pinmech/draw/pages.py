"""Public drawing functions: a pose or an animation as an offline page, or a live meshcat view."""

from __future__ import annotations

import contextlib
import io
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pinmech.draw.geometry import _size
from pinmech.draw.inputs import DrawError, _configuration, _points, _stack
from pinmech.draw.offline import _OfflineWindow
from pinmech.draw.scene import (
    Arrow,
    _animate,
    _draw_pose,
    _legend,
    _meshcat,
    _Scene,
    coincident_groups,
)


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
    from pinmech.model.visual_files import drop_outside, package_roots

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


def mechanism_visuals(mechanism) -> tuple[pin.GeometryModel, list[str]]:
    """The visual geometry of a mechanism from the file its model was built from (the
    URDF, a drawn linkage's generated URDF, an MJCF file), links without visuals
    sketched, and the meshes left out (outside the model's package)."""
    from pinmech.draw.sketch import sketch_visuals
    from pinmech.model.file_colours import UNCOLOURED

    path = mechanism.urdf_path or mechanism.source
    skipped: list[str] = []
    if str(path).endswith(".xml"):
        from pinmech.model.mjcf import mjcf_visuals

        visuals = mjcf_visuals(path, mechanism.model)
        _paint_uncoloured(mechanism, visuals, lambda obj: tuple(obj.meshColor[:3]) == UNCOLOURED)
    else:
        visuals, skipped = package_visuals(path, mechanism.model)
        _paint_uncoloured(mechanism, visuals)
    return sketch_visuals(mechanism, visuals), skipped


def _paint_uncoloured(mechanism, visuals: pin.GeometryModel, uncoloured=lambda obj: not obj.overrideMaterial) -> None:
    """A visual its file does not colour (a URDF visual without a material, an MJCF geom
    without rgba or material) takes its link's colour (pinmech.model.display), as the curves and
    polygons draw that link; a visual the file colours keeps the file's colour."""
    from pinmech.model.display import joint_colours

    colours = joint_colours(mechanism)
    for obj in visuals.geometryObjects:
        if uncoloured(obj):
            obj.meshColor = np.array([*colours[obj.parentJoint], 1.0])
            obj.overrideMaterial = True


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
    scene = _Scene(model, visual_model, _OfflineWindow(), show_grid=show_grid, orthographic=True)
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
    readouts: Sequence[str] | None = None,
    traces: Mapping[str, tuple[float, float, float]] | None = None,
) -> str:
    """A self-contained HTML page playing the poses qs in a loop.

    The page shows one still frame when its address ends in `#frame=K` (K from 0).

    Args:
        qs: configurations, one per frame, each of shape (model.nq,).
        fps: frames per second [1/s].
        points_per_frame: named points of each frame, world frame [m] (same names in all).
        readouts: one text a frame (the driver's value, "A = 30 deg"): the page then has a
            bar of controls, play/pause, a slider over the frames and this readout.
        traces: points of `points_per_frame` whose paths over the frames are drawn, each in
            its colour (RGB in [0, 1]).
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
    for i, frame in enumerate(frames[1:], 1):
        if set(frame) != set(frames[0]):
            raise DrawError(
                f"points_per_frame[{i}] names {', '.join(sorted(frame)) or 'no point'}, the first frame "
                f"{', '.join(sorted(frames[0])) or 'no point'}: every frame names the same points",
                argument="points_per_frame",
                value=i,
            )
    if readouts is not None and len(readouts) != len(qs):
        raise DrawError(
            f"{len(readouts)} readouts for {len(qs)} poses", argument="readouts", value=len(readouts)
        )
    unknown = sorted(set(traces or {}) - set(frames[0]))
    if unknown:
        raise DrawError(
            f"traces of points not in points_per_frame: {', '.join(unknown)}",
            argument="traces",
            value=unknown[0],
        )
    if len(frames) != len(qs):
        raise DrawError(
            f"{len(frames)} sets of points for {len(qs)} poses",
            argument="points_per_frame",
            value=len(frames),
        )
    scene = _Scene(model, visual_model, _OfflineWindow(), show_grid=show_grid, orthographic=True)
    scene.orient(plane_normal)
    body = np.vstack([scene.corners(q) for q in qs] + [_stack(p) for p in frames])
    labels = scene.label_boxes([p for f in frames for p in f.values()], _size(body))
    size, grid = scene.frame(np.vstack([body, labels]))
    scene.pose(scene.vis, qs[0])
    scene.add_points(frames[0], size, _together(frames, 1e-6 * size))
    for name, colour in (traces or {}).items():
        scene.add_trace(name, np.array([f[name] for f in frames]), colour)
    _animate(scene, qs, frames, fps)
    return scene.vis.window.page(
        title, _legend(grid if show_grid else None, {}), fps=fps, readouts=list(readouts or ())
    )


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
    from pinmech.draw.view_server import start_server

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


def _together(frames: Sequence[Mapping[str, np.ndarray]], tol: float) -> list[list[str]]:
    """Names of points at one place (within tol [m]) in every frame: they share a label."""
    out: list[list[str]] = []
    for group in coincident_groups(frames[0], tol):
        parts: list[list[str]] = []
        for name in group:
            part = next((p for p in parts if all(np.linalg.norm(f[name] - f[p[0]]) <= tol for f in frames)), None)
            if part is None:
                parts.append([name])
            else:
                part.append(name)
        out += parts
    return out


def _stop_server(window: Any) -> None:
    """Close the socket to a meshcat server and stop the server process (ours)."""
    window.zmq_socket.close(linger=0)
    if window.server_proc is not None and window.server_proc.poll() is None:
        window.server_proc.kill()
        window.server_proc.wait(timeout=10)
    for pipe in (window.server_proc.stdin, window.server_proc.stdout) if window.server_proc is not None else ():
        if pipe is not None:
            pipe.close()

