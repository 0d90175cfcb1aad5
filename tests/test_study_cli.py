"""`pinmech study FILE`: its outputs (text, CSV, Parquet, JSON, figures), its errors and exit codes."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from pinmech.cli import main
from tests.tolerance import rounding

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"


def test_a_sensitivity_study_writes_its_table_summary_and_figure(tmp_path, capsys):
    """The CSV holds dy/dp in mm/mm at every pose: the crank's effect on P.x at the first
    pose (60 deg) is the closed-form four-bar's, d/da of P = a e2 + R(theta3)(60, 30) mm,
    checked in tests/test_sensitivity.py; here the table carries the same numbers as the
    Parquet file and the JSON summary their largest value."""
    prefix = tmp_path / "fb"
    assert main(["study", str(STUDIES / "four_bar_sensitivity.toml"), "--out", str(prefix), "--plot"]) == 0
    out = capsys.readouterr().out
    assert "largest |dy/dp| over the cycle" in out
    rows = list(csv.DictReader((prefix.with_suffix(".csv")).open()))
    assert len(rows) == 73 * 4  # P.x, P.y, rocker.angle, rocker.omega at each pose
    pq = pytest.importorskip("pyarrow.parquet")
    parquet = pq.read_table(prefix.with_suffix(".parquet")).to_pydict()
    np.testing.assert_array_equal(parquet["d/d crank [per mm]"], [float(r["d/d crank [per mm]"]) for r in rows])
    summary = json.loads(prefix.with_suffix(".json").read_text())
    px = [abs(float(r["d/d crank [per mm]"])) for r in rows if r["output"] == "P.x"]
    assert summary["outputs"]["P.x"]["max_abs_sensitivity_mm_per_mm"]["crank"] == pytest.approx(max(px), rel=rounding(1.0))
    assert (tmp_path / "fb_sensitivity.png").stat().st_size > 10_000


def test_a_tolerance_study_counts_every_variant(tmp_path, capsys):
    file = tmp_path / "tol.toml"
    text = (STUDIES / "four_bar_tolerance.toml").read_text().replace('scene = "../scenes/', f'scene = "{STUDIES.parent}/scenes/')
    file.write_text(text.replace("samples = 2000", "samples = 100").replace("batch = 100", "batch = 25"))
    prefix = tmp_path / "tol"
    assert main(["study", str(file), "--workers", "0", "--out", str(prefix), "--plot"]) == 0
    assert "solved 100 of 100 variants; failed: none" in capsys.readouterr().out
    rows = list(csv.DictReader(prefix.with_suffix(".csv").open()))
    assert [int(r["variant"]) for r in rows] == list(range(100))
    assert (tmp_path / "tol_histogram.png").stat().st_size > 10_000


@pytest.mark.parametrize("edit, code, message", [
    (("kind = \"tolerance\"", "kind = \"orbit\""), 4, "kind: kind = 'orbit' is not one of sensitivity, tolerance, grid, workspace"),
    (("kind = \"tolerance\"", "kind = \"workspace\""), 4, "unknown key(s) outputs, params, samples, seed, steps; known: batch"),
    (("tolerance = \"0.1 mm\"\n", "tolerance = \"-0.1 mm\"\n"), 4, "params.crank.tolerance: tolerance = '-0.1 mm' must be a positive length"),
    (("joint = \"A\"", "joint = \"Q\""), 4, "unknown joint 'Q'"),
    (("points = [\"P\"]", "points = [\"nowhere\"]"), 4, "outputs.points: unknown point 'nowhere'"),
    (("samples = 2000", "samples = 0"), 4, "samples = 0 must be a whole number from 1"),
])
def test_a_bad_study_file_is_one_line_and_its_exit_code(tmp_path, capsys, edit, code, message):
    file = tmp_path / "bad.toml"
    text = (STUDIES / "four_bar_tolerance.toml").read_text().replace('scene = "../scenes/', f'scene = "{STUDIES.parent}/scenes/')
    assert edit[0] in text
    file.write_text(text.replace(edit[0], edit[1], 1))
    assert main(["study", str(file), "--workers", "0"]) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(file) in err and message in err, err


def test_usage_errors_exit_2(capsys):
    assert main(["study", str(STUDIES / "four_bar_sensitivity.toml"), "--plot"]) == 2
    assert "--plot" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["study", str(STUDIES / "four_bar_sensitivity.toml"), "--workers", "-1"])
    assert exc.value.code == 2


def test_without_dask_the_error_names_the_extra(monkeypatch):
    from pinmech.design.cluster import require_dask

    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(ImportError, match=r'pip install "pinmech\[study\]"'):
        require_dask()


def test_a_nominal_that_fails_is_its_error_on_one_line(tmp_path, capsys):
    """Marghitu's slider-crank meets a dead centre within the turn (a singular pose, exit 7);
    a nominal outside its own bounds is a study-file error (exit 4)."""
    file = tmp_path / "m.toml"
    file.write_text(f'scene = "{STUDIES.parent}/scenes/marghitu_slider_crank.toml"\n'
                    '[params.a]\njoint = "B"\ncomponent = "x"\n[outputs]\npoints = ["C_pin"]\n')
    assert main(["study", str(file), "--workers", "0"]) == 7
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the nominal fails over the cycle (singular pose)" in err, err
    file.write_text(f'scene = "{STUDIES.parent}/scenes/four_bar.toml"\n'
                    '[params.a]\njoint = "A"\ncomponent = "x"\nbounds = ["41 mm", "42 mm"]\n[outputs]\npoints = ["P"]\n')
    assert main(["study", str(file), "--workers", "0"]) == 4
    err = capsys.readouterr().err
    assert "params: the nominal params.a: 40 mm is outside 41 .. 42 mm" in err, err


class _Terminal:
    """A stand-in stderr that says it is a terminal and keeps what is written."""

    def __init__(self) -> None:
        self.text = ""

    def isatty(self) -> bool:
        return True

    def write(self, s: str) -> int:
        self.text += s
        return len(s)

    def flush(self) -> None:
        pass


@pytest.mark.parametrize("quiet", [False, True])
def test_a_progress_bar_on_a_terminal_counts_the_variants_unless_quiet(tmp_path, monkeypatch, capsys, quiet):
    """60 variants in 3 batches of 20: on a terminal the bar ends at 60/60 variants (tqdm's
    own count, moved once a batch); with --quiet nothing is drawn."""
    pytest.importorskip("tqdm")
    file = tmp_path / "tol.toml"
    text = (STUDIES / "four_bar_tolerance.toml").read_text().replace('scene = "../scenes/', f'scene = "{STUDIES.parent}/scenes/')
    file.write_text(text.replace("samples = 2000", "samples = 60").replace("batch = 100", "batch = 20")
                    .replace("steps = 73", "steps = 13"))
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(["study", str(file), "--workers", "0"] + ["--quiet"] * quiet) == 0
    assert ("60/60" in terminal.text) != quiet, terminal.text
    assert "variant" in terminal.text or quiet
