"""The Python API example of docs/howto/python.md runs as printed (from the repository's
root) and says what its comments say: D's velocity at the textbook pose, and frames along a sweep."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _api_block() -> str:
    section = (ROOT / "docs" / "howto" / "python.md").read_text(encoding="utf-8")
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_python_api_example_runs_as_printed(monkeypatch):
    monkeypatch.chdir(ROOT)
    scope: dict = {}
    exec(compile(_api_block(), "docs/howto/python.md", "exec"), scope)  # noqa: S102
    np.testing.assert_allclose(scope["motion"].points["D"].velocity, [0.935792, -0.685048, 0.0], atol=1e-6)
    paths = scope["paths"]
    assert paths.velocity.shape == (len(scope["s"].q), 2, 3)
    assert os.path.samefile(Path.cwd(), ROOT)
