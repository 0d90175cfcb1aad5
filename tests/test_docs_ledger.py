"""The pages users read (README.md and docs/, generated reports included) say what was
measured, against whom, how fast, how exact and on what machine: no developers' ledger
(issue numbers, targets met or not, who was working on the machine, what a past session
did). The targets live in the benchmark scripts' exit codes and in CHANGELOG.md, which
this test does not read (docs/changelog.md only includes it)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs").rglob("*.md") if p.name != "changelog.md")

#: What a ledger says, and why each pattern is one.
LEDGER = {
    r"\bissues? #?\d+": "an issue number",
    r"\bthe issue'?s?\b": "the issue a page was written for",
    r"\bNOT met\b": "a target's verdict",
    r"\b(?:target|goal|bar)s?\b[^.\n]{0,80}?:\s*(?:not )?met\b": "a target's verdict",
    r"\btargets? (?:is |are )?(?:not )?met\b": "a target's verdict",
    r"\b(?:met|reached) again\b": "a verdict against an earlier run",
    r"\bengineers?(?:'s|')? (?:at work|jobs?)\b|\bother engineers\b": "who else was on the machine",
    r"\b(?:this|last|previous|that) session\b|\bsessions? ago\b": "what a session did",
    r"\bthis round\b|\bround \d\b": "the project's rounds",
}


def _flags(pattern: str) -> int:
    """Case-blind, except "NOT met" (upper case is the verdict; "not met" alone is English)."""
    return 0 if "NOT" in pattern else re.I


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_the_page_carries_no_developers_ledger(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    found = [f"{page.relative_to(ROOT)}:{text.count(chr(10), 0, m.start()) + 1}: {m.group(0)!r} ({why})"
             for pattern, why in LEDGER.items() for m in re.finditer(pattern, text, _flags(pattern))]
    assert not found, "\n".join(found)


def test_the_ledger_patterns_catch_what_they_name() -> None:
    """Each pattern matches the phrase it was written for, and not the ordinary words near it."""
    caught = ["issue 23's two speed targets", "at the issue's size", "(target 10: met)",
              "Target (issue 13: at most 3 x): met", "fastest setting: NOT met", "16 loops: met again",
              "with 6 other engineers' jobs on the two cores", "eight engineers at work",
              "the last session's run", "two sessions ago", "in this round", "three targets are met"]
    passed = ["the coupler point through the targets, in order", "meets the targets to 2e-16",
              "its targets come out of the crank's order", "met at five pairs", "four pairs are met exactly",
              "a Dask worker's metrics", "rounds interleaved"]
    def hit(text: str) -> bool:
        return any(re.search(p, text, _flags(p)) for p in LEDGER)
    assert [t for t in caught if not hit(t)] == []
    assert [t for t in passed if hit(t)] == []
