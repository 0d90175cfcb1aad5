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
            return build_parser(argv[0], parser_class=_SubcommandOnly).parse_args(argv)
        except _ParseAgain:
            pass
    return build_parser().parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; every pinmech error becomes one line on stderr and its exit code."""
    args = parse_args(argv)
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
