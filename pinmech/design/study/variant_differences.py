"""Sensitivities by central differences of re-solved variants, for the outputs whose exact
derivative is not derived: a driver's torque (a link's angular acceleration has its
exact one, accel_sensitivity.py).

    dy/dp_k = (y(p + h e_k) - y(p - h e_k)) / 2h,    h = STEP [m]

each variant written into the model and solved again over the whole cycle on the nominal
assembly (StudyMechanism.cycle, the same path as every variant of a study), its outputs
read as the study reads them. The error is the truncation h^2/6 |d3y/dp3| plus the
solve's error over h: for a four-bar of 0.1 m links, |d3y/dp3| ~ |dy/dp| / (0.1 m)^2 gives
2e-9 of |dy/dp|, and the closure tolerance (1e-13 of the loop) over 2h about 1e-9 of it;
measured on the torque against Norton's hand Newton-Euler: within 1e-6 of the largest
|dy/dp| (tests/test_study_torque.py).
A variant at p +- h that does not solve is a SweepError naming the parameter, never a
silently one-sided difference.
"""

from __future__ import annotations

import numpy as np

from pinmech.exceptions import SweepError

#: The step of the central differences [m] (see the module for its error).
STEP = 1e-5


def central_differences(sm, outputs, columns: slice) -> np.ndarray:
    """d(outputs[columns])/dp (steps, n_columns, n_par) over the cycle by central
    differences of variants re-solved at p +- STEP e_k; the model keeps the parameters it
    had (read before, written back)."""
    p0 = np.array([place.read() for place in sm.placements])
    out = []
    try:
        for k, param in enumerate(sm.spec.params):
            ys = []
            for sign in (+1.0, -1.0):
                p = p0.copy()
                p[k] += sign * STEP
                cycle = sm.cycle(p)
                if cycle.cause:
                    raise SweepError(f"{sm.spec.path}: params.{param.name} at {p[k] * 1e3:.6g} mm (the nominal "
                                     f"{sign * STEP * 1e3:+.0e} mm, for a central difference): {cycle.cause}: "
                                     f"{cycle.detail}", driver=sm.sweep.driver, value=float("nan"),
                                     cause=cycle.error)
                ys.append(outputs.cycle(cycle.q, cycle.v, cycle.a)[:, columns])
            out.append((ys[0] - ys[1]) / (2.0 * STEP))
    finally:
        sm.write(p0)
    return np.stack(out, axis=-1)
