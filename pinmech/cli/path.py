"""`pinmech path SCENE --duration T`: an arm's task integrated in time, with its drift
(`pinmech sweep` on a task scene comes here too)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from pinmech.cli.arguments import add_limits_argument, add_output_arguments, add_path_arguments
from pinmech.cli.files import check_outputs
from pinmech.cli.progress import LimitWatch, progress
from pinmech.cli.scene_args import option_or_scene
from pinmech.exceptions import PinmechError


def add_parser(sub) -> None:
    path = sub.add_parser("path", help="integrate an arm's task over time: joint trajectory and drift")
    path.add_argument("scene", help="a task scene, e.g. models/scenes/planar_arm.toml")
    path.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                      help="override a scene value (repeatable)")
    add_path_arguments(path, required=False)
    add_limits_argument(path)
    add_output_arguments(path)
    path.set_defaults(func=cmd_path)


def cmd_path(args: argparse.Namespace) -> int:
    """`pinmech path SCENE --duration T`: the task integrated in time, with its drift."""
    from pinmech.io.scene import Scene

    return follow_task(args, Scene.load(args.scene, args.overrides))


def follow_task(args: argparse.Namespace, scene) -> int:
    """A task scene followed in time: CSV (JSON lines, a figure) of the joint trajectory."""
    from pinmech.io.analysis_task import scene_pose, scene_tasks
    from pinmech.solve.limits import limits_at
    from pinmech.outputs import Outputs
    from pinmech.solve.path import follow_path, step_count
    from pinmech.io.scene_model import limit_mode, load_mechanism
    from pinmech.io.sweep import sweep_options
    from pinmech.io.tables import PathCsv

    if not scene.is_task:
        raise PinmechError(f"{scene.path}: no [[task]] to follow; a scene with [drivers] is swept: "
                           "pinmech sweep SCENE")
    figure = check_outputs(args, scene)
    options = sweep_options(scene)  # the scene's scheme and gain checked there, naming the file and key
    duration, step, gain = _timing(args, scene, options)
    scheme = args.scheme or options.get("scheme", "taylor")
    mechanism = load_mechanism(scene)
    q0, _, _ = scene_pose(scene, mechanism)
    total = step_count(duration, step) + 1
    sinks = Outputs()
    if args.plot_path:
        from pinmech.draw.plot_task import PathPlot

        note = f" ({scheme}, step {step:g} s" + (f", feedback {gain:g}/s)" if gain else ")")
        sinks.plot(PathPlot(mechanism, scene.title, note=note, total=total), figure)
    if args.csv_path or not (args.plot_path or args.json_path):
        sinks.table(PathCsv, mechanism, args.csv_path, "path points")
    if args.json_path:
        sinks.table(_PathJsonLines, mechanism, args.json_path, None)
    worst = 0.0
    limits = LimitWatch(limit_mode(scene, getattr(args, "limits", None)), "path points", "")
    with sinks:
        for point in progress(follow_path(mechanism, scene_tasks(scene), q0, duration=duration, step=step,
                                           gain=gain, scheme=scheme), total):
            limits.check(limits_at(mechanism, point.q), f"at t = {point.time:.6g} s")
            sinks.add(point)
            worst = max(worst, point.drift)
    limits.summary(total)
    print(f"largest drift of the path from the one asked: {worst:.3e} m", file=sys.stderr)
    return 0


def _timing(args: argparse.Namespace, scene, options: dict[str, Any]) -> tuple[float, float, float]:
    """A path's duration and step [s] and feedback gain [1/s], each error blaming the flag
    or the scene's key it came from."""
    from pinmech.solve.path import check_timing

    duration = option_or_scene(args.duration, "--duration", scene, options, "duration")
    if not duration.value:
        raise PinmechError(f"{scene.path}: say how long to follow the task: --duration '0.08 s' "
                           "(or [sweep] duration = \"0.08 s\")")
    step = option_or_scene(args.step, "--step", scene, options, "step", "1 ms")
    gain = option_or_scene(args.gain, "--gain", scene, options, "gain", 0.0)
    values = {}
    for option in (duration, step):
        values[option.flag] = option.quantity("time")
        if not values[option.flag] > 0:
            raise option.error(f"must be a positive time, got {option.value!r}")
    T, h = values["--duration"], values["--step"]
    if h > T:
        blamed = duration if step.key and not duration.key else step  # the flag just typed, else the step
        raise blamed.error(f"the step ({step.name} = {h:g} s) must not be longer than the duration "
                           f"({duration.name} = {T:g} s)")
    if not 0 <= gain.value <= 1 / h:
        raise gain.error(f"must be a number from 0 to 1/step = {1 / h:.6g} [1/s] (a larger feedback overshoots "
                         f"within one step), got {gain.value!r}")
    check_timing(T, h, float(gain.value), names=(duration.where, step.where, gain.where))
    return T, h, float(gain.value)


class _PathJsonLines:
    """One JSON object per path point (SI): t, q, v, a, drift, condition number."""

    def __init__(self, mechanism, stream) -> None:
        self.stream = stream

    def add(self, point) -> None:
        import json

        self.stream.write(json.dumps({"t": point.time, "q": point.q.tolist(), "v": point.v.tolist(),
                                      "a": point.a.tolist(), "drift": point.drift,
                                      "angular_drift": point.angular_drift, "condition_number": point.condition})
                          + "\n")

    def close(self) -> None:
        self.stream.flush()
