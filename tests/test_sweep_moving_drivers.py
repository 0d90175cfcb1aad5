"""A sweep of one driver while the others move too (the five-bar's two motors both turn):
each pose's joint velocities are those of every driver's motion, checked against finite
differences of the closed poses along the drivers' velocity.

Before this test a sweep gave the swept driver's share alone from its second pose on (a
silently wrong velocity, off by 2.9 rad/s). h = 1e-5 s of motion: truncation h^2 |q'''| ~
1e-9, rounding 1e-13 / h ~ 1e-8; asserted to 1e-6 of the largest rate.
"""

from __future__ import annotations

import numpy as np

import pinmech


def test_rates_are_every_drivers_motion(scenes_dir):
    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scenes_dir / "five_bar.toml"))
    drivers, solver = sweep.drivers, sweep.solver
    assert np.count_nonzero(drivers.v) == 2  # both motors turn
    values = sweep.start + np.radians(np.arange(0.0, 40.0, 5.0))
    chunk = next(sweep.chunks(values))
    s = chunk.solution
    k = drivers.names.index(sweep.driver)
    h = 1e-5
    for j, x in enumerate(chunk.values):
        at = drivers.q.copy()
        at[k] = x
        plus = solver.solve(at + h * drivers.v, guess=s.q[j]).q
        minus = solver.solve(at - h * drivers.v, guess=s.q[j]).q
        fd = pinmech_difference(solver, minus, plus) / (2 * h)
        np.testing.assert_allclose(s.v[j], fd, rtol=0, atol=1e-6 * np.abs(fd).max())


def pinmech_difference(solver, q0, q1):
    import pinocchio as pin
    return pin.difference(solver.model, q0, q1)
