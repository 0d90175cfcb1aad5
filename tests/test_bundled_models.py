"""The bundled four-bar and slider-crank, written from the README's format, against their
closed forms over a full crank turn (1e-10 of each quantity's largest magnitude)."""

from __future__ import annotations

import numpy as np
import pytest

import closed_form
from pinmech import Scene, analyse
from pinmech.io.sweep import Sweep
from tests.tolerance import residual


def _close(ours, theirs):
    theirs = np.asarray(theirs, dtype=float)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-10 * np.abs(theirs).max())


def test_four_bar_over_a_turn(scenes_dir):
    sweep = Sweep.from_scene(Scene.load(scenes_dir / "four_bar.toml"))
    values = sweep.default_values(181)
    poses = list(sweep.poses(values))
    cf = closed_form.four_bar(values, 4 * np.pi, 0.0, 0.04, 0.12, 0.08, 0.10, branch=1)
    links = [p.motion.links for p in poses]
    _close([m["rocker"].angular_velocity[2] for m in links], cf.omega4)
    _close([m["rocker"].angular_acceleration[2] for m in links], cf.alpha4)
    _close([m["coupler"].angular_velocity[2] for m in links], cf.omega3)
    _close([p.motion.points["B_pin"].acceleration[:2] for p in poses], cf.aB)


def test_slider_crank_over_a_turn(scenes_dir):
    sweep = Sweep.from_scene(Scene.load(scenes_dir / "slider_crank.toml"))
    values = sweep.default_values(181)
    poses = list(sweep.poses(values))
    cf = closed_form.slider_crank(values, 100 * np.pi, 0.0, 0.05, 0.15, 0.01, branch=1)
    _close([p.motion.joints["slide"].q for p in poses], cf.x_B)
    _close([p.motion.joints["slide"].v for p in poses], cf.v_B)
    _close([p.motion.joints["slide"].a for p in poses], cf.a_B)
    _close([p.motion.links["rod"].angular_acceleration[2] for p in poses], cf.alpha_rod)


@pytest.mark.parametrize("scene", ["four_bar.toml", "slider_crank.toml"])
def test_bundled_scenes_solve(scenes_dir, scene):
    analysis = analyse(Scene.load(scenes_dir / scene))
    assert analysis.solution.is_closed(residual(1.0)) and analysis.mechanism.mobility == 1
