"""`pinmech study FILE`: run a design study file and report it (the CLI's face of study.py)."""

from __future__ import annotations

import argparse
import os
import sys

from pinmech.solve.kernels import KERNELS


def _workers(text: str) -> int:
    """--workers: a whole number of worker processes, 0 to cluster.checked_workers' most (argparse type)."""
    from pinmech.design.cluster import checked_workers
    from pinmech.exceptions import OptionError

    try:
        return checked_workers(int(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of worker processes (0 runs in this process)")
    except OptionError as exc:
        raise argparse.ArgumentTypeError(str(exc).replace("workers = ", "", 1))


class ProgressBar:
    """A tqdm bar of the variants done, moved as each batch finishes (on Dask too)."""

    def __init__(self, tqdm) -> None:
        self._tqdm, self._bar = tqdm, None

    @classmethod
    def on_terminal(cls, *, quiet: bool) -> ProgressBar | None:
        """A bar when stderr is a terminal and not --quiet; None otherwise. Without tqdm,
        one line naming the extra that brings it, and no bar."""
        if quiet or not sys.stderr.isatty():
            return None
        try:
            from tqdm import tqdm
        except ImportError:
            print('no progress bar: pip install "pinmech[progress]" (tqdm)', file=sys.stderr)
            return None
        return cls(tqdm)

    def __call__(self, done: int, total: int) -> None:
        if self._bar is None:
            self._bar = self._tqdm(total=total, unit="variant", file=sys.stderr, mininterval=0.5)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


def add_parser(sub) -> None:
    """The `study` subcommand's arguments."""
    study = sub.add_parser("study", help="run a design study (sensitivity, tolerance, grid or workspace) from a study file",
                           description="Run a study file (models/studies/*.toml): exact sensitivities over the "
                           "cycle, or a seeded Monte Carlo tolerance study on Dask. Exit codes as `pinmech --help`.")
    study.add_argument("study_file", help="study file (TOML), e.g. models/studies/four_bar_tolerance.toml")
    study.add_argument("--workers", type=_workers, default=None,
                       help="Dask worker processes of a LocalCluster (default: the CPU count; 0: in this process)")
    study.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="a running Dask scheduler (tcp://HOST:PORT) instead of a LocalCluster "
                            "(default: $DASK_SCHEDULER_ADDRESS if set)")
    study.add_argument("--out", default=None, metavar="PREFIX",
                       help="write PREFIX.csv, PREFIX.parquet (pyarrow) and PREFIX.json")
    study.add_argument("--plot", action="store_true",
                       help="with --out: PREFIX_sensitivity.png; for a tolerance study PREFIX_histogram.png, PREFIX_sigma.png "
                            "(spread against the driver), PREFIX_pareto.png, PREFIX_ellipses.png (point outputs); "
                            "PREFIX_grid.png for a 1-D or 2-D grid study, PREFIX_workspace.png for a workspace study")
    study.add_argument("--json", action="store_true", help="print the JSON summary instead of the text one")
    study.add_argument("--certify", metavar="LEVEL",
                       help="poses of each variant's cycle given the exact condition number: "
                       "every-pose, every-K (e.g. every-10), ends or none (default: the scene's [solver] certify, "
                       "else every-pose); every pose keeps its residual and assembly checks")
    study.add_argument("--kernel", choices=KERNELS, default=None,
                       help="kinematic passes of every variant (default: the scene's [solver] kernel); "
                       "generated: one kernel for the whole study, the lengths are its inputs")
    study.add_argument("--quiet", action="store_true",
                       help="no progress bar (there is none either when stderr is not a terminal)")
    study.set_defaults(func=cmd_study)


def cmd_study(args: argparse.Namespace) -> int:
    """Run the study; print its summary; write the table, JSON and figures asked."""
    import json

    from pinmech.design.cluster import scheduler_address
    from pinmech.exceptions import OptionRefused
    from pinmech.design.study.run import load_any_study, study
    from pinmech.design.study.report import summary, text, write

    if args.plot and not args.out:
        raise OptionRefused("--plot writes PREFIX_*.png: give --out PREFIX too", options=["--plot"])
    spec = load_any_study(args.study_file)
    if args.out:
        _check_out(args, spec)
    scheduler = scheduler_address(args.scheduler)
    workers = (os.cpu_count() or 1) if args.workers is None else args.workers
    bar = ProgressBar.on_terminal(quiet=args.quiet)
    try:
        result = study(spec, workers=workers, scheduler=scheduler, progress=bar, certify=_certify(args),
                       kernel=args.kernel)
    finally:
        if bar is not None:
            bar.close()
    if result.spec.kind == "workspace":
        return _workspace_output(result, args)
    print(json.dumps(summary(result), indent=2) if args.json else text(result))
    if args.out:
        written = write(result, args.out)
        if args.plot:
            from pinmech.design.study.plot import grid_figure, sensitivity_bars, tolerance_histograms

            written.append(sensitivity_bars(result, f"{args.out}_sensitivity.png"))
            if result.spec.kind == "grid":
                written.append(grid_figure(result, f"{args.out}_grid.png"))
            if result.spread is not None:
                from pinmech.design.study.plot_tolerance import ellipse_curves, pareto, point_pairs, sigma_curves

                written.append(tolerance_histograms(result, f"{args.out}_histogram.png"))
                written.append(sigma_curves(result, f"{args.out}_sigma.png"))
                written.append(pareto(result, f"{args.out}_pareto.png"))
                if point_pairs(result.outputs):
                    written.append(ellipse_curves(result, f"{args.out}_ellipses.png"))
        print("wrote " + ", ".join(str(p) for p in written), file=sys.stderr)
    return 0


def _certify(args: argparse.Namespace) -> str | None:
    """--certify checked (an OptionRefused naming it), or None."""
    if args.certify is None:
        return None
    from pinmech.cli.scene_args import certify_argument

    return certify_argument(args.certify)


def _check_out(args: argparse.Namespace, spec) -> None:
    """Before the study runs: every file --out PREFIX (and --plot) writes can be made, and
    none is another's, the study file or its scene."""
    from pinmech.outputs import check_prefix

    endings = [".csv", ".json", ".parquet"]
    if args.plot:
        endings += ["_workspace.png"] if spec.kind == "workspace" else ["_sensitivity.png", "_grid.png",
                                                                       "_histogram.png"]
    check_prefix("--out", args.out, endings, {"the study file": spec.path, "its scene": spec.scene})


def _workspace_output(result, args: argparse.Namespace) -> int:
    """A workspace study's summary, table, JSON and map."""
    import json

    if result.spec.space == "actuator":
        from pinmech.design.workspace.actuator_plot import actuator_figure as figure
        from pinmech.design.workspace.actuator_report import summary, text, write
    else:
        from pinmech.design.workspace.plot import workspace_figure as figure
        from pinmech.design.workspace.report import summary, text, write

    print(json.dumps(summary(result), indent=2) if args.json else text(result))
    if args.out:
        written = write(result, args.out)
        if args.plot:
            written.append(figure(result, f"{args.out}_workspace.png"))
        print("wrote " + ", ".join(str(p) for p in written), file=sys.stderr)
    return 0
