"""`pinmech synth FILE` (or `synthesize`): dimensional synthesis from a synthesis file, the
linkages found written as drawn linkages with their scenes and checked by the engine."""

from __future__ import annotations

import argparse
import math
import sys

from pinmech.design.study.cli import _workers
from pinmech.solve.kernels import KERNELS


def add_parser(sub) -> None:
    """The `synth` subcommand's arguments."""
    synth = sub.add_parser("synth", aliases=["synthesize"],
                           help="find linkages that meet a synthesis file's targets without defects",
                           description="Dimensional synthesis (models/synthesis/*.toml): a seeded differential "
                           "evolution then an exact-gradient refinement; every linkage is free of branch, circuit "
                           "and order defects. Exit codes as `pinmech --help`.")
    synth.add_argument("synthesis_file", help="synthesis file (TOML), e.g. models/synthesis/four_bar_path.toml")
    synth.add_argument("--workers", type=_workers, default=0,
                       help="Dask worker processes of a LocalCluster evaluating each generation (default 0: "
                            "in this process; the answer is the same on any number)")
    synth.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="a running Dask scheduler (tcp://HOST:PORT) instead of a LocalCluster")
    synth.add_argument("--out", default=None, metavar="PREFIX",
                       help="write PREFIX_1.toml (drawn linkage), PREFIX_1_scene.toml, ... for each linkage, "
                            "PREFIX.json, and check each one with the engine")
    synth.add_argument("--plot", action="store_true", help="with --out: PREFIX.png, the targets over the coupler curves")
    synth.add_argument("--json", action="store_true", help="print the JSON summary instead of the text one")
    synth.add_argument("--kernel", choices=KERNELS, default=None,
                       help="kinematic passes of a drawn six-bar's candidates (default: the template scene's "
                       "[solver] kernel); four-bars and slider-cranks are solved in closed form")
    synth.set_defaults(func=cmd_synth)


def cmd_synth(args: argparse.Namespace) -> int:
    """Run the synthesis; print its report; write the linkages, scenes, JSON and figure."""
    import json

    from pinmech.design.synthesis.file import load_synthesis
    from pinmech.design.synthesis.report import figure, summary, text
    from pinmech.design.synthesis.search import synthesise
    from pinmech.exceptions import OptionRefused, SynthesisError
    from pinmech.outputs import write_whole

    if args.plot and not args.out:
        raise OptionRefused("--plot writes PREFIX.png: give --out PREFIX too", options=["--plot"])
    spec = load_synthesis(args.synthesis_file)
    if args.out:
        from pinmech.outputs import check_prefix

        endings = [f"_{i}{end}" for i in range(1, spec.keep + 1) for end in (".toml", "_scene.toml")]
        inputs = {"the synthesis file": spec.path, **({"its scene": spec.scene} if spec.scene else {})}
        check_prefix("--out", args.out, [*endings, ".json", *([".png"] if args.plot else [])], inputs)
    result = synthesise(spec, workers=args.workers, scheduler=args.scheduler, kernel=args.kernel)
    if not result.linkages:
        causes = ", ".join(f"{n} {c}" for c, n in sorted(result.rejected.items())) or "none"
        raise SynthesisError(f"no linkage meets the targets without a defect and within the constraints "
                             f"after {result.evaluations} candidates (rejected: {causes}); widen the bounds or the "
                             "constraints, or raise generations", path=str(spec.path), rejected=dict(result.rejected))
    report = summary(result)
    lines = [text(result)]
    written, failed = [], []
    if args.out:
        for i, (lk, entry) in enumerate(zip(result.linkages, report["linkages"]), start=1):
            files, line, error = _write_and_check(spec, lk, entry, f"{args.out}_{i}", i)
            lines.append(line)
            written += files
            if error is not None:
                failed.append((i, error))
        json_path = f"{args.out}.json"
        write_whole(json_path, json.dumps(report, indent=2))
        written.append(json_path)
        if args.plot:
            written.append(figure(result, f"{args.out}.png"))
    print(json.dumps(report, indent=2) if args.json else "\n".join(lines))
    if written:
        print("wrote " + ", ".join(str(p) for p in written), file=sys.stderr)
    if failed:  # every linkage listed and written; the exit code says a check failed
        print(f"pinmech: the engine check failed for linkage(s) {', '.join(str(i) for i, _ in failed)} of "
              f"{len(result.linkages)} (each listed above with its cause)", file=sys.stderr)
        raise failed[0][1]
    return 0


def _write_and_check(spec, lk, entry: dict, prefix: str, i: int) -> tuple[list, str, Exception | None]:
    """Write linkage i and its scene, check them with the engine: the files, the listing's
    line, and the check's error (None: passed). A failed check is reported with its
    linkage (`engine_check` in the JSON), never in place of the others."""
    from pinmech.design.synthesis.linkage import EngineCheck, engine_check, write_linkage
    from pinmech.exceptions import PinmechError

    if spec.scene is not None:  # a six-bar: its template redrawn, the engine's turn
        from pinmech.design.synthesis import sixbar_output as six

        files = six.write_linkage(spec, lk, prefix)
    else:
        files = write_linkage(lk, prefix, f"{spec.title}: linkage {i}", str(spec.path),
                              spec.targets[:, :2] if lk.task in ("path", "motion") else None)
    entry["files"] = [str(p) for p in files]
    try:
        if spec.scene is not None:
            check = EngineCheck(None, *six.engine_check(spec, files[1], lk))
        else:
            check = engine_check(files[1], lk, spec.targets, spec.angles)
    except PinmechError as exc:
        entry["engine_check"] = f"failed: {exc}"
        return list(files), f"linkage {i}: {files[0]}; the engine check (pinmech sweep of {files[1]}) FAILED: {exc}", exc
    entry["engine_check"] = "passed"
    angular = lk.task == "function" and lk.topology != "slider-crank"
    scale, unit = (180 / math.pi, "deg") if angular else (1e3, "mm")
    entry[f"engine_errors_{unit}"] = [float(e) * scale for e in check.errors]
    also = ""
    if check.angle_errors is not None:
        entry["engine_angle_errors_deg"] = [float(e) * 180 / math.pi for e in check.angle_errors]
        also = f" and {max(entry['engine_angle_errors_deg']):.3g} deg"
    own = ""
    if check.drift is not None:
        entry["engine_drift_mm"] = check.drift * 1e3
        own = f", and within {check.drift * 1e3:.3g} mm of the synthesised linkage's own coupler point"
    return list(files), (f"linkage {i}: {files[0]}; the engine (pinmech sweep of {files[1]}) is within "
                         f"{check.errors.max() * scale:.3g} {unit}{also} of the targets{own}"), None
