"""An animation for slides: each frame drawn with matplotlib (Agg) in the mechanism's plane
as the paths figure draws it (pinmech.draw.plot_paths: bars, plates, blocks, ground, one colour
a link, the textbook's letters), the named points' paths traced, the readout in the
title; assembled as a GIF with Pillow, or an MP4 with ffmpeg where it is installed.

Every frame shares one view (the box of every frame's drawing), so a point's pixel is the
same function of its place in all frames (`FrameRenderer.to_pixels`).
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from pinmech.draw.animation import Frames
from pinmech.exceptions import MissingTool, PinmechError
from pinmech.draw.plot_curves import length_unit
from pinmech.draw.plot_paths import PathRecorder, draw_linkage

#: Size of a frame [inches] and its resolution [dots per inch]: 800 x 600 pixels.
FIGSIZE, DPI = (8.0, 6.0), 100
_MARGIN = 0.08  # share of the drawing's size left around it


def check_mp4(path: str | Path) -> str:
    """The ffmpeg executable for `--mp4`, or a `MissingTool` naming what to install."""
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        raise MissingTool(f"--mp4 {path}: needs ffmpeg, which is not installed (apt-get install ffmpeg, or "
                          "https://ffmpeg.org); --gif writes an animation with Pillow alone", tool="ffmpeg",
                          option="--mp4")
    return ffmpeg


def _pillow():
    try:
        from PIL import Image
    except ImportError as exc:
        raise ImportError('--gif needs Pillow: pip install "pinmech[plot]"') from exc
    return Image


class FrameRenderer:
    """Draws the frames of an animation, all in one view.

    Args:
        frames: the poses, readouts and places (`pinmech.draw.animation.Frames`).
    """

    def __init__(self, frames: Frames) -> None:
        from pinmech.draw.plot import _pyplot

        self.plt = _pyplot()
        self.frames = frames
        mech = frames.mechanism
        self.scale, self.unit = length_unit(mech.length_scale)
        plane = PathRecorder(mech, None)  # the mechanism's plane (xy for a spatial one)
        self.axes, self.projection = plane.axes, plane.projection
        self.traces = frames.traces()
        self.paths = {n: np.array([p[n] for p in frames.places]) @ self.axes.T * self.scale for n in self.traces}
        every = np.vstack([np.array(list(p.values())) for p in frames.places]) @ self.axes.T * self.scale
        lo, hi = every.min(axis=0), every.max(axis=0)
        pad = _MARGIN * max(float(np.max(hi - lo)), 1e-9) + 0.1 * max(float(np.max(hi - lo)), 1e-9)
        self.box = (lo - pad, hi + pad)
        self.fig = self.plt.figure(figsize=FIGSIZE, dpi=DPI)
        self.ax = self.fig.add_axes((0.1, 0.1, 0.85, 0.8))

    def draw(self, k: int) -> np.ndarray:
        """Frame k as RGB pixels (height, width, 3), uint8."""
        ax, frames = self.ax, self.frames
        ax.cla()
        for name, colour in self.traces.items():
            uv = self.paths[name]
            ax.plot(uv[:, 0], uv[:, 1], color=colour, linewidth=1.0, alpha=0.35, zorder=1)
            ax.plot(uv[: k + 1, 0], uv[: k + 1, 1], color=colour, linewidth=1.8, zorder=4,
                    label=f"path of {name}")
        draw_linkage(ax, frames.mechanism, frames.qs[k], self.axes, self.scale)
        for name in self.traces:
            ax.plot(*self.paths[name][k], "o", color="black", markersize=6, zorder=7)
        ax.set_xlim(self.box[0][0], self.box[1][0])
        ax.set_ylim(self.box[0][1], self.box[1][1])
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel(f"x [{self.unit}]")
        ax.set_ylabel(f"y [{self.unit}]")
        ax.grid(True, alpha=0.3)
        if self.traces:
            ax.legend(fontsize=8, loc="upper right")
        ax.set_title(f"{frames.title}{self.projection}\n{frames.readouts[k]}", fontsize=11)
        self.fig.canvas.draw()
        return np.asarray(self.fig.canvas.buffer_rgba())[:, :, :3].copy()

    def to_pixels(self, place: np.ndarray) -> np.ndarray:
        """A world place [m] -> its pixel (column, row from the top) in every frame."""
        self.ax.set_xlim(self.box[0][0], self.box[1][0])
        self.ax.set_ylim(self.box[0][1], self.box[1][1])
        self.ax.set_aspect("equal", adjustable="box")
        self.fig.canvas.draw()
        x, y = self.ax.transData.transform(np.asarray(place) @ self.axes.T * self.scale)
        return np.array([x, self.fig.bbox.height - y])

    def __iter__(self) -> Iterator[np.ndarray]:
        for k in range(len(self.frames.qs)):
            yield self.draw(k)

    def close(self) -> None:
        self.plt.close(self.fig)


def write_gif(frames: Frames, path: str | Path, fps: float) -> Path:
    """The frames as a looping GIF (Pillow), `fps` frames a second."""
    image = _pillow()
    renderer = FrameRenderer(frames)
    try:
        pictures = [image.fromarray(pixels) for pixels in renderer]
    finally:
        renderer.close()
    from pinmech.outputs import write_with

    return write_with(path, lambda temporary: pictures[0].save(
        temporary, format="GIF", save_all=True, append_images=pictures[1:], duration=round(1000 / fps), loop=0,
        disposal=1))


def write_mp4(frames: Frames, path: str | Path, fps: float) -> Path:
    """The frames as an H.264 MP4 (ffmpeg), `fps` frames a second."""
    ffmpeg = check_mp4(path)
    image = _pillow()
    renderer = FrameRenderer(frames)
    path = Path(path)
    try:
        with tempfile.TemporaryDirectory() as folder:
            for k, pixels in enumerate(renderer):
                image.fromarray(pixels).save(Path(folder) / f"{k:06d}.png")
            from pinmech.outputs import write_with

            def encode(temporary: Path) -> None:
                subprocess.run([ffmpeg, "-y", "-loglevel", "error", "-framerate", f"{fps:g}", "-i",
                                str(Path(folder) / "%06d.png"), "-pix_fmt", "yuv420p", "-vcodec", "libx264",
                                "-f", "mp4", str(temporary)], check=True, capture_output=True, text=True,
                               timeout=600)

            try:
                write_with(path, encode)
            except subprocess.CalledProcessError as exc:
                said = (exc.stderr or "").strip().splitlines()
                raise PinmechError(f"--mp4 {path}: ffmpeg failed (exit {exc.returncode}): "
                                   f"{said[-1] if said else 'no message'}") from exc
            except subprocess.TimeoutExpired as exc:
                raise PinmechError(f"--mp4 {path}: ffmpeg took more than {exc.timeout:g} s") from exc
    finally:
        renderer.close()
    return path
