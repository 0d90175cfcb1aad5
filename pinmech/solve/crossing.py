"""Whether a singular closed pose is a change point (a crossing of two branches) or a fold.

At a closed pose q of a mechanism driven along one driver, the closure rows' Jacobian
over the dependent joints and that driver, [J_dep, J_drv] (dimensionless: rows over the
loop's size, columns times their velocity scales), has a null space of dimension one at
a regular pose and at a fold (the tangent, with no driver motion at the fold), and of
dimension two at a change point, where two branches cross with two tangents (Norton,
Design of Machinery, §2.12; any bifurcation of the solution curve). So J_dep alone is
singular at both; [J_dep, J_drv] loses rank only at the crossing.
"""

from __future__ import annotations

import numpy as np

from pinmech.solve.core import core_for

#: [J_dep, J_drv]'s smallest singular value over its largest, below which the pose is a
#: crossing. A pose closed from a step onto the crossing stays about sqrt(residual)
#: (1e-7 for the 1e-13 closure) off it, its ratio that size; at a fold the driver's
#: column is the lever of the driver on the loop, of the order of the link ratios (above
#: 1e-2 for links within a factor 100 of each other): 1e-5 leaves a margin of 100 both ways.
CROSSING = 1e-5


def is_change_point(solver, q: np.ndarray, driver: str) -> bool:
    """True where the closed pose q is a crossing of two branches along `driver` (the
    other drivers held), False at a regular pose or a fold."""
    compiled = core_for(solver)
    if compiled is None or not solver._cuts:
        return False
    compiled.residual(np.asarray(q, dtype=float))
    jacobian = np.asarray(compiled.jacobian(False))
    scale = np.asarray(solver.mechanism.velocity_scale(), dtype=float)
    k = solver.drivers.index(driver)
    columns = [int(v) for v in solver._dep_v] + [int(solver._drv_v[k])]
    values = np.linalg.svd(jacobian[:, columns] * scale[columns], compute_uv=False)
    return bool(values.size) and values[-1] <= CROSSING * values[0]
