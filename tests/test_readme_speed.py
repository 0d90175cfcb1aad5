"""The README's speed tables quote runs of the benchmarks as written: every row it shows is
a row of a report a script wrote (`scripts/benchmark_peers.py`, `benchmark_loops.py`,
`benchmark_kernels.py`, `benchmark_dial.py`, each `--out docs/_generated/...`), character
for character, so no number in it was typed by hand."""

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
                        for name in ("benchmark_peers.md", "benchmark_loops.md", "kernel_speed.md", "dial_trade.md"))
    written = set(_table_rows(reports))
    rows = _table_rows(_speed_section())
    assert len(rows) >= 6, "the README's speed section lost its tables"
    for row in rows:
        assert row in written, f"not a row of the generated reports: {row}"
