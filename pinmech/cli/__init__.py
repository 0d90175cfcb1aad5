"""The `pinmech` command: one plain function per subcommand, `main(argv)` for tests.

Exit codes: 0 success; 1 hand values mismatch (`check`); 2 usage or other pinmech error;
3 bad URDF; 4 bad scene or hand file (unknown name, unit, key); 5 drivers do not match
the mobility; 6 a loop cannot close; 7 singular pose, or forces not determined; 8 inconsistent
task; 9 a drawing input out of range; 10 another assembly than the scene's (or none reachable
on it); 11 the drivers cannot go further (a fold: limit angle, extreme, stroke); 12 a joint
beyond its limits (URDF <limit>, MJCF range; with --limits error); 13 forces that fail their own power balance; 14 a planar design diagnostic asked of a spatial mechanism;
15 a synthesis that found no linkage (without defects, within its constraints).
An output file that cannot be written is 2.
Stopped by a signal: 128 + its number (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP), outputs kept
as NAME.partial.
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Sequence

from pinmech.cli.parser import SUBCOMMANDS, build_parser
from pinmech.exceptions import PinmechError
from pinmech.interrupts import SIGNALS

__all__ = ["build_parser", "main", "parse_args"]


class _ParseAgain(Exception):
    """A command line the one-subcommand parser cannot take."""


class _SubcommandOnly(argparse.ArgumentParser):
    """A parser that stops at an error instead of printing it: `parse_args` then parses
    again with every subcommand's parser, which says what is wrong as it always has."""

    def error(self, message: str):
        raise _ParseAgain(message)


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line parsed, building only the parser of the subcommand it names
    (all eleven, with their help texts, take about 10 ms to build). Any error, and
    `pinmech --help`, go through the full parser: the messages are the same."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in SUBCOMMANDS:
        try:
            parser = build_parser(argv[0], parser_class=_SubcommandOnly)
            return _refuse_empty(parser, parser.parse_args(argv))
        except _ParseAgain:
            pass
    parser = build_parser()
    return _refuse_empty(parser, parser.parse_args(argv))


def _refuse_empty(parser: argparse.ArgumentParser, args: argparse.Namespace) -> argparse.Namespace:
    """`args`, unless an option or file was given as empty text (`--plot ""`, `--from "$UNSET"`):
    that is an OptionRefused naming it, never the option left out in silence."""
    from pinmech.exceptions import OptionRefused

    for action in _actions(parser, args.command):
        value = getattr(args, action.dest, None)
        values = value if isinstance(value, list) else [value]
        if any(isinstance(v, str) and not v.strip() for v in values):
            name = action.option_strings[-1] if action.option_strings else (action.metavar or action.dest)
            several = isinstance(value, list) and len(value) > 1
            what = f"{name} has an empty value in {value!r}" if several else f"{name} is empty"
            raise OptionRefused(f"{what}: give it a value, or leave the option out", options=[name])
    return args


def _actions(parser: argparse.ArgumentParser, command: str) -> list[argparse.Action]:
    """The arguments of `command`'s sub-parser."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[command]._actions


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; every pinmech error becomes one line on stderr and its exit code."""
    try:
        args = parse_args(argv)
    except PinmechError as exc:  # an empty option
        print(f"pinmech: error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    try:
        with SIGNALS.installed():
            return args.func(args)
    except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM, SIGHUP: one line, 128 + the signal's number
        signum = getattr(exc, "signum", signal.SIGINT)
        print(f"pinmech: interrupted by {signal.Signals(signum).name}: stopped{_kept(exc)}", file=sys.stderr)
        return 128 + int(signum)
    except PinmechError as exc:
        print(f"pinmech: error: {_one_line(exc)}{_kept(exc)}", file=sys.stderr)
        return exc.exit_code
    except ImportError as exc:
        print(f"pinmech: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `pinmech sweep ... | head`
        return 0
    except OSError as exc:  # an output file that cannot be written (no such folder, no permission)
        print(f"pinmech: error: {_one_line(exc)}{_kept(exc)}", file=sys.stderr)
        return 2


def _one_line(error: BaseException) -> str:
    """The error's message on one line (a library's message may run over several)."""
    return " ".join(part.strip() for part in str(error).splitlines() if part.strip())


def _kept(error: BaseException) -> str:
    """The partial output files a failed run kept (outputs.py), for its one line."""
    kept = getattr(error, "kept", [])
    return f"; incomplete output kept in {', '.join(kept)}" if kept else ""


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
