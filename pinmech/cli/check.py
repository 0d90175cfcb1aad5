"""`pinmech check HAND_FILE`: hand-calculated values against pinmech."""

from __future__ import annotations

import argparse

from pinmech.exceptions import PinmechError


def add_parser(sub) -> None:
    check = sub.add_parser("check", help="compare hand-calculated values with pinmech")
    check.add_argument("hand_file", help="hand-value file (TOML), e.g. models/scenes/r_rtr.hand.toml")
    check.add_argument("--slack", type=float, default=None,
                       help="units of the last printed digit still called rounding (default 2)")
    check.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                       help="override a value of the hand file's scene")
    check.set_defaults(func=cmd_check)


def cmd_check(args: argparse.Namespace) -> int:
    """`pinmech check HAND_FILE`: hand values against pinmech, non-zero exit on a mismatch."""
    from pinmech.io.analysis import analyse
    from pinmech.io.check import DEFAULT_SLACK, check_slack, compare, format_verdicts, load_hand_file
    from pinmech.io.report import to_dict
    from pinmech.io.scene import Scene

    slack = args.slack if args.slack is not None else DEFAULT_SLACK
    try:
        check_slack(slack, "--slack")
    except PinmechError as exc:  # a usage error (2), not a hand file's (4)
        raise PinmechError(str(exc)) from None
    hand = load_hand_file(args.hand_file)
    analysis = analyse(Scene.load(hand.scene, args.overrides))
    verdicts = compare(to_dict(analysis), hand.values, slack)
    print(f"{hand.source or hand.path}  vs  pinmech on {hand.scene.name}")
    print(format_verdicts(verdicts))
    return 1 if any(v.verdict == "MISMATCH" for v in verdicts) else 0
