"""`pinmech design FILE`: the design page of a drawn linkage, in the browser."""

from __future__ import annotations

import argparse
from pathlib import Path

from pinmech.exceptions import PinmechError


def add_parser(sub) -> None:
    page = sub.add_parser("design", help="design a drawn linkage in the browser: drag its joints and see its "
                          "curves and diagnostics redrawn (pinmech[page])")
    page.add_argument("file", help="a drawn-linkage TOML file, or a scene that names one (linkage = ...)")
    page.add_argument("--driver", help="the driven joint (default: the scene's driver, or the linkage's first joint)")
    page.add_argument("--speed", help="the driver's speed for velocities and accelerations (default: the "
                      "scene's, or '60 rpm')")
    page.add_argument("-o", "--output", help="where the page saves the linkage (default: FILE's linkage "
                      "itself); the scene and figures are written beside it")
    page.add_argument("--port", type=int, default=0, help="the port on 127.0.0.1 (default: any free one)")
    page.add_argument("--no-browser", action="store_true", help="print the page's address, open no browser")
    page.set_defaults(func=cmd_design)


def cmd_design(args: argparse.Namespace) -> int:
    """Serve the page until Ctrl-C; its address (with its token) printed."""
    try:
        import starlette  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError as exc:
        raise PinmechError(f"pinmech design needs the page extra: pip install 'pinmech[page]' ({exc})") from None
    from pinmech.draw.design_page.messages import Saving
    from pinmech.draw.design_page.save import leading_comments
    from pinmech.draw.design_page.server import PageServer
    from pinmech.draw.design_page.session import Session, read_design_file

    if not 0 <= args.port <= 65535:
        raise PinmechError(f"--port must be between 0 and 65535, got {args.port}")
    spec, source, driver, speed = read_design_file(args.file)
    session = Session(spec, source, driver=args.driver or driver, speed=args.speed or speed)
    target = Path(args.output) if args.output else Path(source)
    server = PageServer(session, Saving(target, leading_comments(Path(source))), args.port)
    print(f"pinmech design: {server.url}  (Ctrl-C stops)", flush=True)
    if not args.no_browser:
        import webbrowser

        webbrowser.open(server.url)
    try:
        server.serve()
    finally:
        session.close()
    return 0
