"""The driver torque as a study output: each named driver's torque [N m] (force [N] for a
prismatic one) at every pose, from the scene's masses, gravity and loads by the one
inverse-dynamics path (solve/forces.py's ForceSolver, which checks each pose's power
balance), on the variant now written in the model.

Its sensitivity is by central differences of re-solved variants (variant_differences.py):
the exact one would differentiate the inverse dynamics along dq/dp, dv/dp and da/dp
(accel_sensitivity.py has the last), not done yet.
"""

from __future__ import annotations

import numpy as np

from pinmech.exceptions import PinmechError, SceneError
from pinmech.io.forces_scene import force_settings, force_solver


class DriverTorques:
    """The drivers named in `outputs.torque` on a StudyMechanism `sm`.

    Attributes:
        names: "O2.torque" (or "slide.force") each; kinds: "torque" or "force" each.
    """

    def __init__(self, sm, drivers: tuple[str, ...]) -> None:
        spec, solver = sm.spec, sm.solver
        self.columns = []
        for name in drivers:
            if name not in solver.drivers:
                raise SceneError(f"'{name}' is not a driver of the scene (its drivers: {', '.join(solver.drivers)})",
                                 path=str(spec.path), key="outputs.torque")
            self.columns.append(list(solver.drivers).index(name))
        prismatic = [sm.mechanism.joints[n].kind == "prismatic" for n in drivers]
        self.names = [f"{n}.{'force' if p else 'torque'}" for n, p in zip(drivers, prismatic)]
        self.kinds = ["force" if p else "torque" for p in prismatic]
        self._solver = None
        if drivers:
            _refuse_redrawn_masses(sm, spec)
            try:
                self._solver = force_solver(sm.scene, sm.mechanism, tuple(solver.drivers), force_settings(sm.scene))
            except PinmechError as exc:
                raise SceneError(f"the driver torque needs the scene's masses and loads: {exc}",
                                 path=str(spec.path), key="outputs.torque") from exc

    def values(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """(steps, n) efforts [N m or N] at the poses q with rates v, a."""
        if self._solver is None:
            return np.zeros((len(q), 0))
        self._solver.read_placements()  # the variant's dimensions, written in the user's model
        return np.array([self._solver.solve(qi, vi, ai).effort[self.columns] for qi, vi, ai in zip(q, v, a)])


def _refuse_redrawn_masses(sm, spec) -> None:
    """A drawn param redraws the joints but not the [masses] (a centre of mass `at` a joint,
    an inertia written with params): the torque would be the nominal's masses on the
    variant's geometry. Refused by name rather than answered."""
    drawn = [place for place in sm.placements if getattr(place, "drawn", False)]
    masses = sorted(drawn[0].drawing.spec.masses) if drawn else []
    if masses:
        raise SceneError(f"a driver torque with drawn params ({', '.join(p.name for p in drawn)}) is not "
                         f"computed: the links' [masses] ({', '.join(masses)}) are not redrawn with the joints; "
                         "vary the scene's joint or point placements instead, or leave out the torque",
                         path=str(spec.path), key="outputs.torque")
