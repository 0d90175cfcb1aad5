"""Shared fixtures: paths of the bundled models and scenes, and the closed forms in scripts/."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from hypothesis import settings

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
SCENES = MODELS / "scenes"

# The independent closed-form derivations live in scripts/ as worked examples.
sys.path.insert(0, str(ROOT / "scripts"))


# Hypothesis: the same examples on every machine and run ("ci", the default: derandomized,
# no example database), or fresh random ones to flush what a fixed draw misses
# (`pytest --hypothesis-profile=explore`). A test's own @settings sets only its counts.
settings.register_profile("ci", derandomize=True, database=None, deadline=None)
settings.register_profile("explore", derandomize=False, database=None, deadline=None)
settings.load_profile("ci")

# Under pytest-xdist (`-n 2 --dist loadgroup`, the README's command) the tests that start a
# browser, a Dask cluster or a viewer server run one after another on one worker: they spawn
# processes and bind sockets of their own, and would fight each other (and time out) side by side.
_SERIAL_FILES = {"test_cluster.py", "test_view_server.py"}
_SERIAL_WORDS = ("dask", "two_workers", "cluster")


def _runs_alone(item: pytest.Item) -> bool:
    name = item.nodeid.rsplit("::", 1)[-1]
    return (item.get_closest_marker("browser") is not None or item.path.name in _SERIAL_FILES
            or any(word in name for word in _SERIAL_WORDS))


def pytest_collection_modifyitems(config, items):
    for item in items:
        if _runs_alone(item):
            item.add_marker(pytest.mark.xdist_group("alone"))


FOUR_BAR_LENGTHS = {"crank": 0, "coupler": 1, "rocker": 2, "ground": 3}  # (a, b, c, d)


def length_slopes(formula, values, params, nominal, h: float = 1e-6):
    """Central differences (steps, n_par) of a hand formula(values, a, b, c, d) of the
    four-bar over the study parameters `params` (named crank, coupler, rocker, ground),
    each length stepped by +- h [m] from `nominal` (a, b, c, d) [m]."""
    import numpy as np

    slopes = []
    for param in params:
        step = np.zeros(4)
        step[FOUR_BAR_LENGTHS[param.name]] = h
        slopes.append((formula(values, *(nominal + step)) - formula(values, *(nominal - step))) / (2 * h))
    return np.stack(slopes, axis=-1)


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
