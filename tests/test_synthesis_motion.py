"""Four-bar motion generation: the coupler carried through poses of the bundled four-bar's
coupler, solved by the engine, the linkage hidden, recovered without defects."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.design.synthesis.linkage import engine_check, write_linkage
from pinmech.design.synthesis.search import synthesise
from tests._engine_poses import engine_poses

ROOT = Path(__file__).resolve().parents[1]
LOWER = np.array([-0.06, -0.06, 0.04, -0.06, 0.01, 0.04, 0.02, -0.15, -0.15])
UPPER = np.array([0.06, 0.06, 0.16, 0.06, 0.08, 0.2, 0.16, 0.15, 0.15])


def test_motion_synthesis_recovers_the_bundled_four_bar(tmp_path):
    # Seven poses (P and the coupler's angle + 30 deg: a part's line 30 deg off the bar) of
    # the bundled four-bar, from the engine. The synthesis meets them within 1e-8 of the
    # linkage's size and 1e-8 rad, and the engine sweeping the written linkage does too.
    crank = np.arange(65.0, 335.0, 45.0)
    places, angles = engine_poses(crank)
    angles = angles + np.radians(30.0)
    spec = SynthesisSpec(Path("test.toml"), "test", "motion", "four-bar", places, None, LOWER, UPPER,
                         seed=1, population=15, generations=400, keep=1, angles=angles)
    best = synthesise(spec).linkages[0]
    assert best.meets(1e-8)
    _, scene = write_linkage(best, tmp_path / "found", "found", "test.toml")
    check = engine_check(scene, best, places, angles)
    assert check.errors.max() <= 1e-8 * best.size and check.angle_errors.max() <= 1e-8
