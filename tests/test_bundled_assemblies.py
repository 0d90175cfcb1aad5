"""Every bundled scene with drivers stays on its own assembly: one-off solves at 36 driver
values and sweeps at 1, 10, 30 and 45 degree spacing give the poses of a fine sweep.

The reference is the 1-degree sweep itself, checked against the closed forms elsewhere
(tests/test_assembly.py, tests/test_bundled_models.py); here the claim is that the
spacing and the way a pose is asked for do not change the answer: 1e-12 of the
mechanism's size (the solver's tolerance is 1e-13, poses far from singular).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import pinmech
from pinmech.io.sweep import Sweep
from tests.tolerance import REGULAR, closure

SCENES = ["r_rtr.toml", "four_bar.toml", "slider_crank.toml", "four_bar_dynamic.toml", "slider_crank_dynamic.toml"]


def _rows(sweep: Sweep, values: np.ndarray) -> np.ndarray:
    return np.concatenate([c.solution.q for c in sweep.chunks(values)])


@pytest.mark.parametrize("name", SCENES)
def test_any_spacing_gives_the_rows_of_a_fine_sweep(scenes_dir, name):
    path = scenes_dir / name
    if not path.is_file():
        pytest.skip(f"{name} is not bundled")
    sweep = Sweep.from_scene(pinmech.Scene.load(path))
    fine_values = sweep.start + np.radians(np.arange(0, 361, 1.0))
    fine = _rows(sweep, fine_values)
    for spacing in (10, 30, 45):
        sweep = Sweep.from_scene(pinmech.Scene.load(path))
        coarse = _rows(sweep, fine_values[::spacing])
        for qa, qb in zip(coarse, fine[::spacing]):  # turn_gap: radians, or mechanism sizes
            assert sweep.solver.turn_gap(qa, qb) < closure(1.0, REGULAR)
    assert sweep.solver.turn_gap(fine[0], fine[-1]) < closure(1.0, REGULAR)  # a full turn ends where it began


@pytest.mark.parametrize("name", SCENES)
def test_one_off_solves_land_on_the_rows_of_the_sweep(scenes_dir, name):
    path = scenes_dir / name
    if not path.is_file():
        pytest.skip(f"{name} is not bundled")
    sweep = Sweep.from_scene(pinmech.Scene.load(path))
    driver = sweep.driver
    values = sweep.start + np.radians(np.arange(0, 360, 10.0))
    rows = _rows(sweep, values)
    for value, q in zip(values, rows):
        scene = pinmech.Scene.load(path, [f'drivers.{driver}.angle="{math.degrees(value)!r} deg"'])
        analysis = pinmech.analyse(scene)
        assert sweep.solver.turn_gap(analysis.solution.q, q) < closure(1.0, REGULAR)
        assert analysis.solution.assembly.signs == sweep.solver.reference.signs
