"""`pinmech solve SCENE`: the textbook-ordered report of one pose, or JSON."""

from __future__ import annotations

import argparse
import sys

from pinmech.cli.arguments import add_limits_argument, add_scene_arguments
from pinmech.cli.scene_args import scene_from_args


def add_parser(sub) -> None:
    solve = sub.add_parser("solve", help="solve a scene and print the report (or JSON)")
    add_scene_arguments(solve)
    solve.add_argument("--json", action="store_true", help="print one JSON object (SI units) instead of text")
    add_limits_argument(solve)
    solve.set_defaults(func=cmd_solve)


def cmd_solve(args: argparse.Namespace) -> int:
    """`pinmech solve SCENE`: the textbook-ordered report, or `--json`."""
    from pinmech.io.analysis import analyse
    from pinmech.solve.limits import enforce, limit_violations
    from pinmech.io.report import to_json, to_text
    from pinmech.io.scene_model import limit_mode

    scene = scene_from_args(args)
    mode = limit_mode(scene, args.limits)
    analysis = analyse(scene)
    violations = limit_violations(analysis.mechanism, analysis.motion)
    enforce(violations, mode, str(scene.path))
    print(to_json(analysis) if args.json else to_text(analysis), end="" if not args.json else "\n")
    for v in violations:
        print(f"pinmech: warning: {v.describe()}", file=sys.stderr)
    return 0
