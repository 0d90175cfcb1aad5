"""`pinmech report SCENE -o page.html`: everything about a scene on one offline page."""

from __future__ import annotations

import argparse

from pinmech.cli.arguments import add_scene_arguments
from pinmech.cli.files import check_page, write_text
from pinmech.cli.scene_args import scene_from_args
from pinmech.counts import checked_count
from pinmech.exceptions import PinmechError


def add_parser(sub) -> None:
    page = sub.add_parser("report", help="write one offline HTML page: drawing, tables, polygons, sweep figures")
    add_scene_arguments(page)
    page.add_argument("-o", "--output", required=True, help="the HTML file to write")
    page.add_argument("--hand", help="a hand-value file to check on the page (as pinmech check)")
    page.add_argument("--steps", type=int, default=121, help="poses of the sweep drawn (default 121; 0: none)")
    page.set_defaults(func=cmd_report)


def cmd_report(args: argparse.Namespace) -> int:
    """`pinmech report SCENE -o page.html [--hand FILE]`: everything about the scene on one offline page."""
    from pinmech.io.analysis import analyse
    from pinmech.draw.report_page import report_html

    if args.steps < 0 or args.steps == 1:
        raise PinmechError(f"--steps must be 0 (no sweep) or at least 2, got {args.steps}")
    checked_count(args.steps, "--steps", f"steps = {args.steps}")
    hand_text = None
    scene = scene_from_args(args)
    check_page(args, scene, hand=args.hand)
    analysis = analyse(scene)
    if args.hand:
        from pinmech.io.check import DEFAULT_SLACK, compare, format_verdicts, load_hand_file
        from pinmech.io.report import to_dict
        from pinmech.io.scene import Scene

        hand = load_hand_file(args.hand)
        checked = analyse(Scene.load(hand.scene))
        verdicts = compare(to_dict(checked), hand.values, DEFAULT_SLACK)
        hand_text = f"{hand.source or hand.path}  vs  pinmech on {hand.scene.name}\n" + format_verdicts(verdicts)
    write_text(args.output, report_html(analysis, steps=args.steps, hand_text=hand_text), "offline page")
    return 0
