"""The worked examples in scripts/ run to the end (each has a main())."""

from __future__ import annotations

import importlib

import pytest


@pytest.mark.parametrize(
    "name, argv",
    [
        ("r_rtr_example", None),
        ("closed_form", None),
        ("closed_form_forces", None),
        ("benchmark_sweep", ["--poses", "40", "--repeats", "1"]),
        ("sweep_memory", ["--poses", "200"]),
        ("singular_accuracy", []),
    ],
)
def test_script_runs(name, argv, capsys):
    module = importlib.import_module(name)
    module.main() if argv is None else module.main(argv)
    assert capsys.readouterr().out


def test_render_snapshots_script_runs(tmp_path, monkeypatch, capsys):
    pytest.importorskip("meshcat", reason='needs pip install "pinmech[viz]"')
    module = importlib.import_module("render_snapshots")
    monkeypatch.setattr(module, "IMAGES", tmp_path)
    monkeypatch.setattr(module, "SCENES", {"r_rtr": []})
    module.main()
    out = capsys.readouterr().out
    assert "needs Debian's chromium" in out or (tmp_path / "r_rtr.png").stat().st_size > 1000
