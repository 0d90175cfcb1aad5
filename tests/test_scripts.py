"""The worked examples in scripts/ run to the end (each has a main())."""

from __future__ import annotations

import importlib

import pytest


@pytest.mark.parametrize("name", ["r_rtr_example"])
def test_worked_example_runs(name, capsys):
    importlib.import_module(name).main()
    assert capsys.readouterr().out
