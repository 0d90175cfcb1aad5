"""Options a command cannot honour for the scene it was given, refused out loud.

`pinmech sweep` on a task scene follows the task in time: none of a driver sweep's options
(its range, its solver settings, its forces, `--paths`, `--torque-plot`) means anything
there; on a driven scene the options of a task (`--duration`, ...) mean nothing. A figure's
settings (`--links`, `--points`, `--angles`, `--path-plane`, `--timing-marks`) need the figure they set.
Each was ignored in silence: now each is an `OptionRefused` (exit 2) before anything runs.
"""

from __future__ import annotations

import argparse

from pinmech.exceptions import OptionRefused

#: `pinmech sweep` options (argparse dest -> flag) that only a driver sweep reads.
DRIVER_SWEEP = {
    "driver": "--driver", "first": "--from", "last": "--to", "steps": "--steps", "links": "--links",
    "points": "--points", "paths_path": "--paths", "angles": "--angles", "path_plane": "--path-plane",
    "skip_failures": "--skip-failures", "start_mode": "--start", "no_predictor": "--no-predictor",
    "cold_start": "--cold-start", "no_batch": "--no-batch", "interpolate": "--interpolate", "tol": "--tol",
    "max_iterations": "--max-iterations", "through_folds": "--through-folds", "forces": "--forces",
    "static": "--static", "minimum_norm": "--minimum-norm", "flywheel": "--flywheel",
    "torque_plot": "--torque-plot", "timing_marks": "--timing-marks", "centrodes": "--centrodes",
}
#: Options only a task followed in time reads.
TASK = {"duration": "--duration", "step": "--step", "scheme": "--scheme", "gain": "--gain"}
#: Settings of the sweep figure (`--plot`) alone, and of both it and the paths figure (`--paths`).
PLOT_SETTINGS = {"links": "--links", "angles": "--angles"}
PATH_SETTINGS = {"points": "--points", "path_plane": "--path-plane", "timing_marks": "--timing-marks",
                 "centrodes": "--centrodes"}
_DEFAULTS = {"angles": "continuous"}


def given(args: argparse.Namespace, options: dict[str, str]) -> list[str]:
    """The flags among `options` given on the command line (a value other than the default)."""
    out = []
    for dest, flag in options.items():
        value = getattr(args, dest, None)
        if value is not None and value is not False and value != _DEFAULTS.get(dest):
            out.append(flag)
    return out


def refuse_sweep_options(args: argparse.Namespace, scene: str, *, task: bool) -> None:
    """Raise `OptionRefused` for a `pinmech sweep` option the scene's kind cannot honour.

    Args:
        args: the parsed command line.
        scene: the scene file (for the message).
        task: the scene is a task ([[task]]) followed in time, not a driver sweep.
    """
    if task:
        refused = given(args, DRIVER_SWEEP)
        if refused:
            raise OptionRefused(f"{', '.join(refused)}: for a driver sweep, and this scene is a task ([[task]]) "
                                "followed in time (its figure is --plot: joint coordinates, rates and drift "
                                "against time); leave them out", options=refused, scene=scene)
        return
    refused = given(args, TASK)
    if refused:
        raise OptionRefused(f"{', '.join(refused)}: for a task ([[task]]) followed in time, and this scene "
                            "sweeps its driver; leave them out", options=refused, scene=scene)
    settings = given(args, PLOT_SETTINGS) if not args.plot_path else []
    settings += given(args, PATH_SETTINGS) if not (args.plot_path or args.paths_path) else []
    if settings:
        figure = "--plot FILE" + ("" if given(args, PLOT_SETTINGS) else " or --paths FILE")
        raise OptionRefused(f"{', '.join(settings)}: a setting of a figure, and no such figure is asked: "
                            f"add {figure}", options=settings, scene=scene)
    if args.static and args.flywheel:
        raise OptionRefused("--flywheel: a flywheel is sized from the energy a moving cycle stores, and --static "
                            "has no motion; leave one out", options=["--flywheel"], scene=scene)
