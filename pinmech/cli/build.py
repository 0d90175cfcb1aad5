"""`pinmech build LINKAGE -o FILE.urdf`: the URDF of a linkage drawn in TOML."""

from __future__ import annotations

import argparse

from pinmech.exceptions import PinmechError


def add_parser(sub) -> None:
    build = sub.add_parser("build", help="write the URDF (with <constraint> loop cuts) of a linkage drawn in TOML")
    build.add_argument("linkage", help="linkage file (TOML), e.g. models/linkages/jansen.toml")
    build.add_argument("-o", "--output", required=True, help="the URDF file to write")
    build.set_defaults(func=cmd_build)


def cmd_build(args: argparse.Namespace) -> int:
    """`pinmech build LINKAGE -o FILE.urdf`: the URDF of a drawn linkage, written whole or not at all."""
    from pinmech.model.linkage_model import build_urdf
    from pinmech.model.linkage_urdf import spanning_tree
    from pinmech.outputs import check_distinct

    check_distinct({"-o": args.output}, {"the linkage file": args.linkage})
    try:
        linkage = build_urdf(args.linkage, args.output)
    except OSError as exc:
        raise PinmechError(f"cannot write {args.output}: {exc.strerror or exc}") from exc
    cuts = [edge.name for edge in spanning_tree(linkage).cuts]
    print(f"{args.output} written: {len(linkage.links) - 1} links, {len(linkage.edges) - len(cuts)} tree joints, "
          f"loop cuts: {', '.join(cuts) or 'none'}")
    return 0
