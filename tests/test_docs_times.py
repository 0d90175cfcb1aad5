"""Every time quoted in README.md and docs/ comes from a script's report in docs/_generated
(which names the machine it ran on), or is a setting or a quantity of the model, not a
measurement of how long pinmech took. A time typed into a page by hand goes stale and
was measured on some machine the reader cannot see; this test finds each."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GENERATED = ROOT / "docs" / "_generated"
PAGES = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs").rglob("*.md") if "_generated" not in p.parts)
TIME = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)\s?(µs|us|ms|s|min|minutes?|seconds?|hours?)\b(?![/^])")
#: A time in words ("about a minute"): never from a report.
WORDS = re.compile(r"\b(?:(?:a|one|half an?) (?:minute|hour)"
                   r"|(?:two|three|a few|few|several) (?:minutes|seconds|hours))\b", re.I)

#: Times that are not measurements of pinmech: (page, the words around the time), and why.
NOT_MEASURED = {
    ("accuracy.md", "under a 20 s alarm"): "a test harness's setting",
    ("benchmarks.md", "until it fills 50 ms"): "the benchmark's sample length, a setting",
    ("speed.md", "Taylor step at 1 ms"): "a path's time step, an input",
    ("speed.md", "(1 ms: 7e-11 m)"): "a path's time step, an input",
    ("sweeps.md", "(0.0815 s in 1 ms steps: 81 steps and one of 0.5 ms)"): "a path's duration and steps",
    ("sweeps.md", "at t ≈ 0.099 s"): "the model's time along a path",
    ("studies.md", "aim at 0.1 to 1 s of work a task"): "advice on a setting",
    ("studies.md", "a 1 s tick"): "a Dask setting",
    ("studies.md", "5 s monitors"): "a Dask setting",
    ("studies_cluster.md", "a 1 s event-loop tick"): "a Dask setting",
    ("synthesis.md", "Pyslvs' published 51 s"): "a published figure, quoted as such",
}


def _prose(text: str) -> str:
    """The page without its code (fenced blocks and inline code: commands and files)."""
    return re.sub(r"`[^`]*`", "", re.sub(r"```.*?```", "", text, flags=re.S))


def _reports_of(page: Path, text: str) -> str:
    """The text of the generated reports a page includes or names."""
    names = set(re.findall(r"_generated/(\w+\.(?:md|txt))", text))
    return "\n".join((GENERATED / n).read_text(encoding="utf-8") for n in sorted(names) if (GENERATED / n).exists())


def test_every_time_quoted_comes_from_a_report_or_is_not_a_measurement() -> None:
    loose = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        reported = set(re.findall(r"\d+(?:\.\d+)?", _reports_of(page, text)))
        for line in _prose(text).splitlines():
            for m in TIME.finditer(line):
                if m.group(1) in reported:
                    continue  # a number of a report the page includes or names
                if any(page.name == name and words in line for name, words in NOT_MEASURED):
                    continue
                loose.append(f"{page.relative_to(ROOT)}: {m.group(0)!r} in {line.strip()[:100]!r}")
        prose = " ".join(_prose(text).split())  # a time in words may span two lines
        loose += [f"{page.relative_to(ROOT)}: {m.group(0)!r} in words" for m in WORDS.finditer(prose)]
    assert loose == [], "times typed by hand (quote a script's report, or drop them):\n" + "\n".join(loose)


def test_every_generated_timing_report_names_its_machine() -> None:
    """A report with times says what machine it ran on (cores at least)."""
    unnamed = [p.name for p in GENERATED.glob("*.md")
               if re.search(r"\b(us|ms|wall|µs)\b", p.read_text(encoding="utf-8"))
               and not re.search(r"\bcores?\b|machine", p.read_text(encoding="utf-8"))]
    assert unnamed == []


def test_the_design_times_report_lists_every_bundled_command() -> None:
    """scripts/design_times.py times files that exist, and its report has a row for each
    (measured, or marked not run)."""
    import sys

    sys.path.insert(0, str(ROOT / "scripts"))
    import design_times

    report = (GENERATED / "design_times.md").read_text(encoding="utf-8")
    for command in design_times.COMMANDS.values():
        assert (ROOT / command.split()[2]).is_file(), command
        assert f"| `{command}` |" in report, command
