"""`pinmech animate SCENE`: a driver cycle (or a task in time) as an offline page, a GIF or an MP4."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pinmech.cli.arguments import add_scene_arguments
from pinmech.cli.files import inputs_of, write_page
from pinmech.cli.scene_args import scene_from_args
from pinmech.cli.visuals import visuals
from pinmech.exceptions import PinmechError

#: Most frames `pinmech animate` puts in one page (each frame keeps every link's placement).
_MAX_FRAMES = 20_000


def add_parser(sub) -> None:
    anim = sub.add_parser("animate", help="save a driver cycle (or a task in time) as an offline meshcat "
                          "animation (pinmech[viz]), a GIF or an MP4")
    add_scene_arguments(anim)
    anim.add_argument("-o", "--output", help="the HTML page to write (play/pause, a driver slider, traced paths)")
    anim.add_argument("--gif", help="also write a GIF for slides (Pillow: pinmech[plot])")
    anim.add_argument("--mp4", help="also write an MP4 for slides (needs ffmpeg installed)")
    anim.add_argument("--from", dest="start", help="first driver value (default: the scene's)")
    anim.add_argument("--to", dest="stop", help="last driver value (default: one turn on)")
    anim.add_argument("--duration", help="task scenes: how long to follow the task, e.g. '0.5 s' "
                      "(default: the scene's [sweep] duration)")
    anim.add_argument("--steps", type=int, default=91, help="frames (default 91)")
    anim.add_argument("--fps", type=int, default=30, help="frames per second (default 30)")
    anim.add_argument("--skip-failures", action="store_true", help="leave out poses that cannot close")
    anim.add_argument("--no-grid", action="store_true", help="hide meshcat's grid and axes")
    anim.set_defaults(func=cmd_animate)


def cmd_animate(args: argparse.Namespace) -> int:
    """`pinmech animate SCENE -o FILE.html [--gif FILE] [--mp4 FILE]`: a driver cycle (a task
    scene: its task followed in time), each frame a solved, closed pose."""
    from pinmech.draw.animation import driver_frames, task_frames

    outputs = {"-o": args.output, "--gif": args.gif, "--mp4": args.mp4}
    if not any(outputs.values()):
        raise PinmechError("animate writes -o PAGE.html, --gif FILE.gif or --mp4 FILE.mp4: give at least one")
    scene = scene_from_args(args)
    _check_animation(args, scene)
    if not 2 <= args.steps <= _MAX_FRAMES:
        raise PinmechError(f"--steps must be between 2 and {_MAX_FRAMES} frames (each is kept in the page), "
                           f"got {args.steps}")
    if not args.fps > 0:
        raise PinmechError(f"--fps must be positive, got {args.fps}")
    if scene.is_task:
        frames = task_frames(scene, args.duration, args.steps)
    else:
        frames = driver_frames(scene, args.start, args.stop, args.steps,
                               skip_failures=args.skip_failures)
    if args.output:
        from pinmech.draw import animation_html

        mechanism = frames.mechanism
        write_page(args.output, animation_html(mechanism.model, visuals(mechanism), frames.qs, fps=args.fps,
                                           points_per_frame=frames.places, plane_normal=mechanism.plane_normal,
                                           show_grid=not args.no_grid, title=frames.title,
                                           readouts=frames.readouts, traces=frames.traces()))
    if args.gif:
        from pinmech.draw.animation_export import write_gif

        print(f"wrote {write_gif(frames, args.gif, args.fps)} ({len(frames.qs)} frames)", file=sys.stderr)
    if args.mp4:
        from pinmech.draw.animation_export import write_mp4

        print(f"wrote {write_mp4(frames, args.mp4, args.fps)} ({len(frames.qs)} frames)", file=sys.stderr)
    return 0


def _check_animation(args: argparse.Namespace, scene) -> None:
    """Before solving: the outputs are distinct and writable in kind, ffmpeg is there for
    --mp4, and the range options fit the scene (a driver's range, or a task's duration)."""
    from pinmech.exceptions import OptionRefused
    from pinmech.outputs import check_distinct

    for option, path, suffix in (("--gif", args.gif, ".gif"), ("--mp4", args.mp4, ".mp4")):
        if path and Path(path).suffix.lower() != suffix:
            raise PinmechError(f"{option} {path}: the file must end in {suffix}")
    check_distinct({"-o": args.output, "--gif": args.gif, "--mp4": args.mp4}, inputs_of(scene))
    if args.mp4:
        from pinmech.draw.animation_export import check_mp4

        check_mp4(args.mp4)
    task = scene.is_task
    wrong = ["--from"] * bool(task and args.start) + ["--to"] * bool(task and args.stop)
    wrong += ["--duration"] * bool(not task and args.duration)
    if wrong:
        kind = "a task ([[task]]) followed in time: give --duration" if task else "a driver's cycle: give --from/--to"
        raise OptionRefused(f"{', '.join(wrong)}: this scene animates {kind}", options=wrong, scene=str(scene.path))
