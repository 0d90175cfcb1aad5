"""The design commands' files (study and workspace tables, synthesis linkages, figures) are
written whole, as the sweep's are: through a temporary file renamed when complete, so a run
that fails or is stopped while writing leaves the file of the same name as it was and what it
had written as NAME.partial, never a half-written file under the name asked for."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pinmech.design.figure_file import pyplot, save
from pinmech.design.study.report import write_tables


def test_a_prefix_with_a_dot_keeps_it(tmp_path: Path) -> None:
    # "run.2" is a prefix, not a name with a suffix to replace (it wrote run.csv before)
    paths = write_tables({"a [mm]": [1.0, 2.0]}, {"n": 2}, tmp_path / "run.2", parquet=False)
    assert [p.name for p in paths] == ["run.2.csv", "run.2.json"]
    assert (tmp_path / "run.2.csv").read_bytes() == b"a [mm]\r\n1.0\r\n2.0\r\n"  # csv's own line ends, as before
    assert json.loads((tmp_path / "run.2.json").read_text()) == {"n": 2}


def test_a_table_that_fails_while_written_leaves_the_old_file(tmp_path: Path, monkeypatch) -> None:
    pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    old = tmp_path / "run.parquet"
    old.write_bytes(b"the previous run's table")

    def half_then_fail(table, where) -> None:
        Path(where).write_bytes(b"PAR1 half a table")
        raise OSError("disk full")

    monkeypatch.setattr(pq, "write_table", half_then_fail)
    with pytest.raises(OSError, match="disk full"):
        write_tables({"a [mm]": [1.0]}, {}, tmp_path / "run")
    assert old.read_bytes() == b"the previous run's table"
    assert (tmp_path / "run.parquet.partial").read_bytes() == b"PAR1 half a table"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "no temporary file left behind"


def test_a_figure_that_fails_while_drawn_leaves_the_old_file(tmp_path: Path) -> None:
    plt = pyplot("test")
    old = tmp_path / "map.png"
    old.write_bytes(b"the previous figure")
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    fig.savefig = lambda where, **_: (_ for _ in ()).throw(KeyboardInterrupt())  # stopped while drawing
    with pytest.raises(KeyboardInterrupt):
        save(plt, fig, old)
    assert old.read_bytes() == b"the previous figure"
    assert not list(tmp_path.glob(".map.png*")), "no temporary file left behind"


def test_a_figure_is_a_complete_png(tmp_path: Path) -> None:
    plt = pyplot("test")
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    path = save(plt, fig, tmp_path / "map.png")
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[-8:-4] == b"IEND"  # the PNG signature and its last chunk
