"""Paths of points over a sweep (the coupler curve, a foot's path), drawn in the mechanism's
plane with the mechanism itself at the scene's pose, equal axes, the direction of travel
marked. A spatial mechanism's paths are projected on a chosen world plane (xy, yz, zx).

The mechanism is drawn as a textbook sketches it (`pinmech.model.link_nodes`): bars, plates,
slider blocks, guides and ground triangles, one colour a link.
"""

from __future__ import annotations

from array import array
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from pinmech.draw.label_place import defer
from pinmech.exceptions import PinmechError
from pinmech.model.display import display_names, joint_colours
from pinmech.model.link_nodes import sketch_links, world_nodes
from pinmech.solve.motion import _plane_reference

if TYPE_CHECKING:
    from pinmech.model.mechanism import Mechanism

PLANES = {"xy": (0, 1), "yz": (1, 2), "zx": (2, 0)}


class PathRecorder:
    """Keeps the points' places pose by pose (world frame [m]), then draws them in a plane
    or in 3-D.

    Args:
        mechanism: the model (its plane, or `plane` for a spatial one).
        plane: None (the mechanism's plane; "xy" for a spatial mechanism), one of PLANES
            (a projection on that world plane), or "3d" (a 3-D view).
        length: (factor from m, unit) the figure draws lengths in (None: mm for paths
            within a metre of the origin, else m).
    """

    def __init__(self, mechanism: Mechanism, plane: str | None = None,
                 length: tuple[float, str] | None = None) -> None:
        if plane is not None and plane not in (*PLANES, "3d"):
            raise PinmechError(f"the path plane must be one of {', '.join(PLANES)} or 3d, got {plane!r}")
        self.mechanism, self.is_3d = mechanism, plane == "3d"
        normal = mechanism.plane_normal
        if plane is None and normal is not None:
            e1 = _plane_reference(*normal.tolist())
            self.axes, self.names = np.array([e1, np.cross(normal, e1)]), ("x", "y")
            self.projection = ""
        else:
            i, j = PLANES["xy" if plane in (None, "3d") else plane]
            self.axes, self.names = np.eye(3)[[i, j]], ("xyz"[i], "xyz"[j])
            self.projection = ", 3-D view" if self.is_3d else f", projected on the world {plane or 'xy'} plane"
        self.xyz: dict[str, tuple[array, array, array]] = {}
        self.labels = display_names(mechanism)
        self.count = 0
        self.length = length

    def add(self, positions: dict[str, np.ndarray]) -> None:
        """One pose: point name -> world position [m] (NaN where the pose failed)."""
        for name, p in positions.items():
            for values, x in zip(self.xyz.setdefault(name, (array("d"), array("d"), array("d"))), p.tolist()):
                values.append(x)
        self.count += 1

    @property
    def uv(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """The paths in the drawing plane's coordinates [m]."""
        return {name: tuple(self.axes @ np.array(xyz)) for name, xyz in self.xyz.items()}

    def draw(self, ax, q: np.ndarray | None, travel: str, *, backwards: bool = False,
             ghosts: list[tuple[np.ndarray, str]] = (), folds: list[np.ndarray] = (), timing=None,
             targets: dict[str, list[tuple[float, float]]] | None = None) -> None:
        """Paths, the mechanism at q (if given) and arrows of travel, on matplotlib axes
        (3-D axes when the recorder is 3-D); `backwards`: the points move against the order
        they were recorded in (a driver turning at a negative speed), and the arrows say so;
        `ghosts`: (q, label) of poses outlined thinly (limit positions); `folds`: q at the
        driver's own limits, outlined dotted; `timing`: a
        `plot_timing.TimingMarks` whose marks are drawn on the paths; `targets`: point ->
        places (world x, y [m]) drawn on its path, numbered (a synthesis's targets)."""
        if self.is_3d:
            return self._draw_3d(ax, q, travel, backwards)
        scale, unit = self._unit()
        for k, (ghost, label) in enumerate(ghosts):
            draw_ghost(ax, self.mechanism, ghost, self.axes, scale, "outlines: limit positions" if k == 0 else None)
        for k, fold in enumerate(folds):
            draw_ghost(ax, self.mechanism, fold, self.axes, scale, "outlines: folds (the driver's limits)" if k == 0
                       else None, style=(0, (1, 1.5)), gid="fold")
        for k, (name, (u, v)) in enumerate(self.uv.items()):
            u, v = np.array(u) * scale, np.array(v) * scale
            (line,) = ax.plot(u, v, linewidth=1.6, color=self._colour(name), linestyle=("-", "--", "-.", ":")[k % 4],
                              marker=self._marker(name), markevery=[0], markersize=7, markeredgecolor="0.1",
                              label=f"path of {self.labels.get(name, name)}", zorder=4)  # marked where it begins
            _arrows(ax, u[::-1], v[::-1], line.get_color()) if backwards else _arrows(ax, u, v, line.get_color())
        for name, places in (targets or {}).items():
            self._targets(ax, name, places, scale)
        if q is not None:  # after the paths: its guides span the strokes drawn
            draw_linkage(ax, self.mechanism, q, self.axes, scale)
        if timing is not None:
            self._timing(ax, timing, scale)
        frame(ax)
        ax.set_xlabel(f"{self.names[0]} [{unit}]", fontsize=9)
        ax.set_ylabel(f"{self.names[1]} [{unit}]", fontsize=9)
        self._finish(ax, travel)
        return None

    def _unit(self) -> tuple[float, str]:
        if self.length is not None:
            return self.length
        return (1000.0, "mm") if self._size() < 1.0 else (1.0, "m")

    def _timing(self, ax, timing, scale: float) -> None:
        """A dot on each path at every timing mark, the driver's value beside it."""
        keys = sorted(timing.marks)
        for name in timing.points:
            uv = np.array([self.axes @ timing.marks[k][name] for k in keys]).reshape(-1, 2) * scale
            colour = self._colour(name)
            ax.plot(uv[:, 0], uv[:, 1], self._marker(name), markersize=4.5, markerfacecolor=colour, markeredgecolor=colour,
                    zorder=5, gid=f"timing {name}", label=f"{self.labels.get(name, name)} every "
                    f"{timing.label(timing.step if not timing.sweep.is_angular else np.degrees(timing.step))} "
                    "of the driver")
            middle = np.nanmean(uv, axis=0)
            for text, p in _merged([timing.label(k) for k in keys], uv, 1e-6 * max(self._size() * scale, 1e-300)):
                defer(ax, text, p, middle, fontsize=6.5, color=colour, zorder=6, gid=f"timing {name}")

    def _targets(self, ax, name: str, places: list[tuple[float, float]], scale: float) -> None:
        """A point's target places as crosses in its colour, numbered 1, 2, ... (labels apart)."""
        xyz = np.column_stack([np.asarray(places, float), np.zeros(len(places))])
        uv = (xyz @ self.axes.T) * scale
        colour = self._colour(name)
        ax.plot(uv[:, 0], uv[:, 1], "x", color=colour, markersize=8, markeredgewidth=2, zorder=6,
                gid=f"targets {name}", label=f"targets of {self.labels.get(name, name)}")
        middle = uv.mean(axis=0)
        for k, p in enumerate(uv, start=1):
            defer(ax, str(k), p, middle, fontsize=8, color=colour, zorder=7, gid=f"targets {name}")

    def _colour(self, name: str) -> str:
        """A point's own colour (figure_style.py), by its place among the recorded points."""
        return self._style(name)[0]

    def _marker(self, name: str) -> str:
        """A point's own marker (figure_style.py)."""
        return self._style(name)[1]

    def _style(self, name: str) -> tuple[str, str]:
        from pinmech.draw.figure_style import point_style

        names = list(self.xyz)
        return point_style(names.index(name) if name in names else len(names))

    def _draw_3d(self, ax, q: np.ndarray | None, travel: str, backwards: bool = False) -> None:
        scale, unit = self._unit()
        if q is not None:
            draw_linkage_3d(ax, self.mechanism, q, scale)
        for k, (name, xyz) in enumerate(self.xyz.items()):
            x, y, z = (np.array(c) * scale for c in xyz)
            colour = self._colour(name)
            ax.plot(x, y, z, linewidth=1.6, color=colour, linestyle=("-", "--", "-.", ":")[k % 4],
                    label=f"path of {self.labels.get(name, name)}")
            if backwards:
                x, y, z = x[::-1], y[::-1], z[::-1]
            ok = np.nonzero(np.isfinite(x) & np.isfinite(y) & np.isfinite(z))[0]
            arrow = 0.08 * self._size() * scale
            for i in ok[len(ok) // 5 :: max(1, len(ok) // 5)][:4]:  # arrows of travel
                step = np.array([x[i + 1] - x[i], y[i + 1] - y[i], z[i + 1] - z[i]]) if i + 1 < len(x) else np.zeros(3)
                if np.all(np.isfinite(step)) and np.linalg.norm(step) > 0:
                    ax.quiver(x[i], y[i], z[i], *step, color=colour, length=arrow, normalize=True,
                              arrow_length_ratio=0.5, linewidth=1.6)
        lo, hi = np.array(ax.get_xlim3d() + ax.get_ylim3d() + ax.get_zlim3d()).reshape(3, 2).T
        centre, half = (lo + hi) / 2, float(np.max(hi - lo)) / 2
        ax.set_xlim3d(centre[0] - half, centre[0] + half)  # equal axes
        ax.set_ylim3d(centre[1] - half, centre[1] + half)
        ax.set_zlim3d(centre[2] - half, centre[2] + half)
        ax.set_box_aspect((1, 1, 1))
        for axis, label in zip("xyz", "xyz"):
            getattr(ax, f"set_{axis}label")(f"{label} [{unit}]", fontsize=9)
        self._finish(ax, travel)

    def _finish(self, ax, travel: str) -> None:
        ax.set_title(f"paths of points ({travel}){self.projection};\nmechanism at the scene's pose", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)

    def _size(self) -> float:
        values = [np.abs(np.array(c)) for xyz in self.xyz.values() for c in xyz]
        finite = [x[np.isfinite(x)] for x in values]
        return float(max((np.max(x) for x in finite if x.size), default=0.0))


def _merged(texts: list[str], places: np.ndarray, tol: float) -> list[tuple[str, np.ndarray]]:
    """One label a place: the texts of marks within tol of each other joined ("90°, 270°")."""
    out: list[tuple[str, np.ndarray]] = []
    for text, p in zip(texts, places):
        same = next((k for k, (_, q) in enumerate(out) if np.linalg.norm(p - q) <= tol), None)
        if same is None:
            out.append((text, p))
        else:
            out[same] = (f"{out[same][0]}, {text}", out[same][1])
    return out


def _arrows(ax, u: np.ndarray, v: np.ndarray, colour: str, count: int = 4) -> None:
    """Arrowheads along a path, the way it is travelled."""
    ok = np.nonzero(np.isfinite(u) & np.isfinite(v))[0]
    if len(ok) < 3:
        return
    for k in np.linspace(0, len(ok) - 2, count + 2)[1:-1].astype(int):
        i, j = ok[k], ok[k + 1]
        if j != i + 1 or (u[i], v[i]) == (u[j], v[j]):
            continue
        ax.annotate("", xy=(u[j], v[j]), xytext=(u[i], v[i]), zorder=5,
                    arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.4, "mutation_scale": 14})


def draw_linkage(ax, mechanism: Mechanism, q: np.ndarray, axes: np.ndarray, scale: float = 1.0,
                 labels: bool = True) -> None:
    """The mechanism at q on matplotlib axes, in the plane spanned by `axes` (2 x 3) [m x scale];
    `labels` False: its joints and points not named (a small drawing over a map)."""
    from matplotlib.patches import Polygon

    data = mechanism.model.createData()
    pin.forwardKinematics(mechanism.model, data, q)
    sketches = sketch_links(mechanism)
    spans = [np.linalg.norm(a.position - b.position) for s in sketches.values() for a in s.nodes for b in s.nodes]
    size = scale * max(spans, default=mechanism.length_scale)
    colours = joint_colours(mechanism)  # as in every figure (pinmech.model.display)
    if labels:
        _labels(ax, mechanism, sketches, data, axes, scale, size)
    drawn = np.vstack([(world_nodes(s, data) @ axes.T) * scale for s in sketches.values()] + [_data_corners(ax)])
    for link in sketches.values():
        uv = (world_nodes(link, data) @ axes.T) * scale
        colour = colours[link.joint]
        if link.is_ground:
            _ground(ax, link, uv, size, axes, scale, drawn)
            continue
        if link.is_plate and len(_hull(uv)) >= 3:
            ax.add_patch(Polygon(_hull(uv), closed=True, facecolor=colour, alpha=0.3, edgecolor=colour, lw=2,
                                 zorder=2))
        elif len(uv) >= 2:  # a bar, end to end (its points on it)
            ends = uv[list(_farthest(uv))]
            ax.plot(ends[:, 0], ends[:, 1], color=colour, linewidth=4, solid_capstyle="round", zorder=2)
        if link.slide_axis is not None:
            axis = axes @ (data.oMi[link.joint].rotation @ link.slide_axis)
            _block(ax, uv[0], axis / max(np.linalg.norm(axis), 1e-300), size, colour)
        for node, p in zip(link.nodes, uv):
            if node.kind == "revolute":
                ax.plot(*p, "o", markersize=5, markerfacecolor="white", markeredgecolor="0.15", zorder=3)


def draw_ghost(ax, mechanism: Mechanism, q: np.ndarray, axes: np.ndarray, scale: float = 1.0,
               label: str | None = None, style=(0, (3, 2)), gid: str = "ghost") -> None:
    """The mechanism at q outlined thinly (a limit position beside the drawn pose): each
    moving link's bar or plate edge, dashed (`style`) in its colour [m x scale]."""
    data = mechanism.model.createData()
    pin.forwardKinematics(mechanism.model, data, q)
    colours = joint_colours(mechanism)
    for link in sketch_links(mechanism).values():
        uv = (world_nodes(link, data) @ axes.T) * scale
        if link.is_ground or len(uv) < 2:
            continue
        hull = _hull(uv) if link.is_plate and len(uv) >= 3 else np.empty((0, 2))
        ring = np.vstack([hull, hull[:1]]) if len(hull) >= 3 else uv[list(_farthest(uv))]
        ax.plot(ring[:, 0], ring[:, 1], color=colours[link.joint], linewidth=1.0, linestyle=style,
                alpha=0.55, zorder=1.5, gid=gid, label=label)
        label = None


def _labels(ax, mechanism: Mechanism, sketches: dict, data: pin.Data, axes: np.ndarray, scale: float,
            size: float) -> None:
    """Every joint, cut and named point written beside its place (once a place), as the
    textbook letters them (pinmech.model.display), away from the mechanism's centre."""
    names = display_names(mechanism)
    places: list[tuple[np.ndarray, str]] = []
    for link in sketches.values():
        for node, p in zip(link.nodes, (world_nodes(link, data) @ axes.T) * scale):
            if node.kind != "other" and not any(np.linalg.norm(p - q) <= 1e-6 * size for q, _ in places):
                places.append((p, names.get(node.name, node.name)))
    if not places:
        return
    centre = np.mean([p for p, _ in places], axis=0)
    for p, name in places:
        away = p - centre
        away = away / np.linalg.norm(away) if np.linalg.norm(away) > 1e-9 * size else np.array([0.0, 1.0])
        ax.annotate(name, p, xytext=tuple(13 * away), textcoords="offset points", ha="center", va="center",
                    fontsize=9, fontweight="bold", color="0.1", zorder=6)


def _farthest(uv: np.ndarray) -> tuple[int, int]:
    """Indices of the two points farthest apart (in the plane or in space)."""
    d = np.linalg.norm(uv[:, None, :] - uv[None, :, :], axis=2)
    i, j = np.unravel_index(np.argmax(d), d.shape)
    return int(i), int(j)


def _hull(uv: np.ndarray) -> np.ndarray:
    """The convex hull of points in the plane, counter-clockwise (Andrew's monotone chain)."""
    pts = sorted(map(tuple, np.round(uv, 12)))
    if len(pts) < 3:
        return np.array(pts)

    def half(points):
        out = []
        for p in points:
            while len(out) >= 2 and _turn(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out[:-1]

    return np.array(half(pts) + half(pts[::-1]))


def _turn(o, a, b) -> float:
    """z of (a - o) x (b - o): positive for a left turn."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def draw_linkage_3d(ax, mechanism: Mechanism, q: np.ndarray, scale: float = 1.0) -> None:
    """The mechanism at q on 3-D matplotlib axes: each link's nodes joined by lines [m x scale]."""
    data = mechanism.model.createData()
    pin.forwardKinematics(mechanism.model, data, q)
    colours = joint_colours(mechanism)  # as in every figure (pinmech.model.display)
    for link in sketch_links(mechanism).values():
        xyz = world_nodes(link, data) * scale
        colour = colours[link.joint]
        pins = xyz[[n.kind == "revolute" for n in link.nodes]]
        if len(pins):
            ax.scatter(*pins.T, s=18, facecolors="white", edgecolors="0.15", depthshade=False)
        if link.is_ground or len(xyz) < 2:
            continue
        ring = np.vstack([xyz, xyz[:1]]) if link.is_plate else xyz[list(_farthest(xyz))]
        ax.plot(*ring.T, color=colour, linewidth=3.5)


#: The drawing's margin round what it holds, a share of its larger side; its least height to width.
MARGIN, LEAST_ASPECT = 0.06, 0.5


def frame(ax) -> float:
    """Axes limits from what the axes hold (the mechanism, paths, outlines), a margin round
    it, to equal scales, the axes' box fitted to them (no empty bands); the height-to-width
    ratio drawn, at least LEAST_ASPECT (a flat slider-crank is not drawn as a strip)."""
    (x0, y0), (x1, y1) = ax.dataLim.get_points()
    width, height = x1 - x0, y1 - y0
    pad = MARGIN * max(width, height)
    width, height = width + 2 * pad, height + 2 * pad
    grow = max(LEAST_ASPECT * width - height, 0.0) / 2
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad - grow, y1 + pad + grow)
    ax.set_aspect("equal", adjustable="box")
    return (height + 2 * grow) / width


def _data_corners(ax) -> np.ndarray:
    """The corners of what the axes hold so far (paths, outlines), shape (k, 2); none if empty."""
    if not ax.has_data() or not np.all(np.isfinite(ax.dataLim.get_points())):
        return np.zeros((0, 2))
    (x0, y0), (x1, y1) = ax.dataLim.get_points()
    return np.array([[x0, y0], [x0, y1], [x1, y0], [x1, y1]])


def _ground(ax, link, uv: np.ndarray, size: float, axes: np.ndarray, scale: float, drawn: np.ndarray) -> None:
    """Triangles under the fixed pivots, a dashed line along each guide: over what is drawn
    along it (the mechanism, and the paths and outlines drawn before it: the slider's stroke),
    and a margin, never farther (a long guide would shrink the mechanism in its figure)."""
    from matplotlib.patches import Polygon

    h = 0.08 * size
    for node, p in zip(link.nodes, uv):
        if node.kind == "revolute":
            ax.add_patch(Polygon([p, p + (-0.6 * h, -h), p + (0.6 * h, -h)], closed=True, facecolor="0.75",
                                 edgecolor="0.3", zorder=1))
            ax.plot([p[0] - h, p[0] + h], [p[1] - h] * 2, color="0.3", linewidth=1.5, zorder=1)
    for origin, axis in link.guides:
        p, d = axes @ origin * scale, axes @ axis
        d = d / max(float(np.linalg.norm(d)), 1e-300)
        along = (drawn - p) @ d
        margin = 0.08 * size
        ends = np.array([p + (along.min() - margin) * d, p + (along.max() + margin) * d])
        ax.plot(ends[:, 0], ends[:, 1], color="0.45", linestyle="--", linewidth=1.2, zorder=1, gid="guide")


def _block(ax, centre: np.ndarray, axis: np.ndarray, size: float, colour: str) -> None:
    from matplotlib.patches import Polygon

    across = np.array([-axis[1], axis[0]])
    a, b = 0.1 * size * axis, 0.055 * size * across
    corners = [centre - a - b, centre + a - b, centre + a + b, centre - a + b]
    ax.add_patch(Polygon(corners, closed=True, facecolor=colour, edgecolor="0.15", alpha=0.8, zorder=3))
