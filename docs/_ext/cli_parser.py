"""pinmech's argument parser as sphinx-argparse reads it: the same parser, its texts escaped
for reStructuredText (`kg*m^2` is a unit, not the start of emphasis; `code` is code)."""

from __future__ import annotations

import argparse
import re

from pinmech.cli import build_parser

_CODE = re.compile(r"`([^`]+)`")


def _rst(text: str | None) -> str | None:
    if not text:
        return text
    return _CODE.sub(r"``\1``", text.replace("\\", "\\\\").replace("*", "\\*").replace("|", "\\|"))


def _escape(parser: argparse.ArgumentParser) -> None:
    parser.description, parser.epilog = _rst(parser.description), _rst(parser.epilog)
    for action in parser._actions:
        action.help = _rst(action.help)
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                choice.help = _rst(choice.help)
            for sub in action.choices.values():
                _escape(sub)


def parser() -> argparse.ArgumentParser:
    """`pinmech.cli.build_parser()`, its help texts escaped for reStructuredText."""
    built = build_parser()
    _escape(built)
    return built
