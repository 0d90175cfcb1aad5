"""The README's speed table quotes one run of the benchmarks as written: every row it shows
is a row of the report `scripts/benchmark_peers.py --out docs/_generated/benchmark_peers.md`
or `scripts/benchmark_loops.py --out docs/_generated/benchmark_loops.md` wrote, character
for character, so no number in it was typed by hand (issue 23: "quote its table in the
README from one run")."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _table_rows(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith("| ") and not line.startswith("| ---")]


def _speed_section() -> str:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    start = readme.index("## Speed")
    end = readme.index("\n## ", start + 1)
    return readme[start:end]


def test_every_row_of_the_readme_speed_tables_is_a_row_the_benchmarks_wrote():
    reports = "\n".join((ROOT / "docs" / "_generated" / name).read_text(encoding="utf-8")
                        for name in ("benchmark_peers.md", "benchmark_loops.md"))
    written = set(_table_rows(reports))
    rows = _table_rows(_speed_section())
    assert len(rows) >= 6, "the README's speed section lost its tables"
    for row in rows:
        assert row in written, f"not a row of the generated reports: {row}"
