"""Shared fixtures: paths of the bundled models and scenes, and the closed forms in scripts/."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
SCENES = MODELS / "scenes"

# The independent closed-form derivations live in scripts/ as worked examples.
sys.path.insert(0, str(ROOT / "scripts"))


@pytest.fixture
def models_dir() -> Path:
    return MODELS


@pytest.fixture
def scenes_dir() -> Path:
    return SCENES


@pytest.fixture
def r_rtr_scene() -> Path:
    return SCENES / "r_rtr.toml"


@pytest.fixture
def figures(monkeypatch):
    """The figures pinmech saves, kept open to be read (closed after the test)."""
    import pinmech.draw.plot

    kept = []

    def keep(plt, fig, path):
        kept.append(fig)
        return path

    monkeypatch.setattr(pinmech.draw.plot, "_save", keep)
    yield kept
    import matplotlib.pyplot as plt

    for fig in kept:
        plt.close(fig)
