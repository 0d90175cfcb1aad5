"""Forces over a sweep: driver effort and reaction columns, the torque curve, the energy
fluctuation and the coefficient of speed fluctuation for a flywheel.

`SweepForces` solves the forces of each pose a sweep yields (from the pose's joint
coordinates, rates and accelerations); the CSV and JSON-lines tables and the torque plot
below read them. The summary (mean torque, energy fluctuation, worst power residual,
torque zero crossings) is printed once the sweep ends.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import IO, Any

import numpy as np

from pinmech.exceptions import SceneError
from pinmech.solve.flywheel import EnergyFluctuation, energy_fluctuation
from pinmech.solve.forces import ForceSolution, advantage_unit, mechanical_advantage
from pinmech.solve.forces_report import forces_dict
from pinmech.io.forces_scene import ForceSettings, force_settings, force_solver
from pinmech.io.sweep import Sweep, SweepPose
from pinmech.io.tables import SweepCsv, SweepJsonLines, row


class SweepForces:
    """Forces at every solved pose of a sweep, and what the cycle adds up to.

    Args:
        sweep: the sweep (its scene gives gravity, loads and massless links).
        static: zero speeds and accelerations at every pose (statics).
        minimum_norm: minimum-norm reactions where the loops are redundant.
        flywheel: flywheel inertia [kg m^2] for the coefficient of speed fluctuation
            (default: the scene's `[forces] flywheel`).

    Raises:
        SceneError: a mechanism with joints of more than one degree of freedom.
    """

    def __init__(self, sweep: Sweep, *, static: bool = False, minimum_norm: bool = False,
                 flywheel: float | None = None) -> None:
        self.sweep = sweep
        mech = sweep.mechanism
        self.settings: ForceSettings = force_settings(sweep.scene)
        self.static = static or self.settings.static
        self.flywheel = flywheel if flywheel is not None else self.settings.flywheel
        if any(j.nv != 1 for j in mech.joints.values()):
            raise SceneError("forces over a sweep need one-dof joints only", path=str(sweep.scene.path))
        self.solver = force_solver(sweep.scene, mech, sweep.drivers.names, self.settings, minimum_norm=minimum_norm)
        self._last: tuple[int, ForceSolution | None] = (-1, None)
        self.values: list[float] = []
        self.efforts: list[float] = []
        self.worst_power = 0.0
        self.driver_index = sweep.drivers.names.index(sweep.driver)

    def solve(self, pose: SweepPose) -> ForceSolution | None:
        """The forces at a pose (None where the pose failed); each pose solved once."""
        if self._last[0] == pose.index:
            return self._last[1]
        result = None
        if pose.motion is not None:
            q, v, a = self._state(pose)
            result = self.solver.solve(q, v, a)
            self.values.append(pose.value)
            self.efforts.append(float(result.effort[self.driver_index]))
            self.worst_power = max(self.worst_power, result.power.residual, result.equation_residual)
        self._last = (pose.index, result)
        return result

    def _state(self, pose: SweepPose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        mech = self.sweep.mechanism
        q, v, a = mech.neutral(), np.zeros(mech.model.nv), np.zeros(mech.model.nv)
        for name, joint in pose.motion.joints.items():
            mech.set_coordinate(q, name, joint.q)
            idx = mech.joint(name).idx_v
            v[idx], a[idx] = joint.v, joint.a
        if self.static:
            v[:], a[:] = 0.0, 0.0
        return q, v, a

    # ------------------------------------------------------------------ tables
    def columns(self, first: ForceSolution) -> list[str]:
        """CSV columns of the forces, with units."""
        planar = self._planar_z()
        cols = [f"{n}.{'torque [N*m]' if self._angular(n) else 'force [N]'}" for n in first.drivers]
        for name, r in first.reactions.items():
            if r.kind == "prismatic":  # the normal force as a vector: its side of the guide is its sign
                cols += [f"{name}.N{c} [N]" for c in ("xy" if planar else "xyz")] + [f"{name}.moment [N*m]"]
            else:
                cols += [f"{name}.F{c} [N]" for c in ("xy" if planar else "xyz")] + [f"{name}.|F| [N]"]
        if self._advantage(first) is not None:
            unit = advantage_unit(self._angular(first.drivers[0]), self.solver.loads[0])
            cols.append(f"mechanical_advantage [{unit}]")
        return cols + ["power_residual [1]"]

    def _advantage(self, f: ForceSolution) -> float | None:
        return mechanical_advantage(f, self.solver.loads) if self.static else None

    def cells(self, f: ForceSolution | None, width: int) -> list[object]:
        """One row of `columns` (blank where the pose failed)."""
        if f is None:
            return [""] * width
        planar = self._planar_z()
        normal = self.sweep.mechanism.plane_normal
        out: list[object] = [float(e) for e in f.effort]
        for r in f.reactions.values():
            if r.kind == "prismatic":
                moment = float(normal @ r.moment) if normal is not None else float(np.linalg.norm(r.moment))
                out += [float(x) for x in (r.normal_force[:2] if planar else r.normal_force)] + [moment]
            else:
                out += [float(x) for x in (r.force[:2] if planar else r.force)] + [r.magnitude]
        advantage = self._advantage(f)
        if advantage is not None:
            out.append(advantage)
        return out + [max(f.power.residual, f.equation_residual)]

    def _planar_z(self) -> bool:
        normal = self.sweep.mechanism.plane_normal
        return normal is not None and abs(abs(normal[2]) - 1.0) < 1e-12

    def _angular(self, name: str) -> bool:
        return self.sweep.mechanism.joint(name).is_angular

    # ------------------------------------------------------------------ cycle
    def energy(self) -> EnergyFluctuation | None:
        """Energy fluctuation of the swept driver's torque curve (None for a slider, < 2
        poses, or a driver that turned back at a fold: its net travel is no cycle)."""
        if not self.sweep.is_angular or len(self.values) < 2 or self.values[0] == self.values[-1] \
                or not self._monotonic():
            return None
        return energy_fluctuation(np.array(self.values), np.array(self.efforts))

    def _monotonic(self) -> bool:
        steps = np.diff(np.array(self.values))
        return bool(np.all(steps > 0) or np.all(steps < 0))

    def _energy_coarse(self) -> EnergyFluctuation | None:
        """The energy fluctuation from every other pose (None below five poses): how much it
        moves is how far the trapezoids between the poses may be off. (The rule's error
        falls as the step squared, so the full set's is about a third of that change where
        the poses resolve the curve; it was half of it at 361 poses of the slider-crank.)"""
        n = len(self.values)
        if n < 5:
            return None
        keep = list(range(0, n, 2)) + ([n - 1] if (n - 1) % 2 else [])
        return energy_fluctuation(np.array(self.values)[keep], np.array(self.efforts)[keep])

    def summary(self) -> list[str]:
        """Lines for the end of a sweep: the cycle's torque, energy, zero crossings, residual."""
        name, angular = self.sweep.driver, self.sweep.is_angular
        unit = "N m" if angular else "N"
        lines = [(f"forces at {len(self.values)} poses ({'statics' if self.static else 'dynamics'}); "
                  f"largest power-balance or equation residual {self.worst_power:.1e}")]
        if self.efforts:
            e = np.array(self.efforts)
            lines.append(f"{name}: driver {'torque' if angular else 'force'} from {e.min():.6g} to {e.max():.6g} {unit}")
            crossings = self._zero_crossings()
            if crossings:
                lines.append(f"{name}: the driver effort changes sign (zero: toggle or load reversal) near "
                             + ", ".join(crossings))
        energy = None if self.static else self.energy()
        if not self.static and angular and len(self.values) > 2 and not self._monotonic():
            lines.append(f"{name}: no mean torque or energy fluctuation: the driver turned back at a fold, so "
                         "the curve is not one run of the driver")
        if energy is not None:
            coarse = self._energy_coarse()
            change = None if coarse is None else abs(coarse.energy_fluctuation - energy.energy_fluctuation)
            if change is not None and change > 0.05 * energy.energy_fluctuation:
                lines.append(f"{name}: mean torque {_shown(energy.mean_torque, self.efforts):.6g} N m over "
                             f"{math.degrees(energy.span):.6g} deg; energy fluctuation not resolved by "
                             f"{len(self.values)} poses ({energy.energy_fluctuation:.4g} J from them, "
                             f"{coarse.energy_fluctuation:.4g} J from every other one): sweep with more --steps")
                energy = None  # no flywheel sized from it
            else:
                about = "" if change is None else f" (within about {change:.2g} J: the trapezoids between the poses)"
                lines.append(f"{name}: mean torque {_shown(energy.mean_torque, self.efforts):.6g} N m over "
                             f"{math.degrees(energy.span):.6g} deg; energy fluctuation {energy.energy_fluctuation:.6g} J"
                             f"{about}, slowest at {math.degrees(energy.slowest_angle):.4g} deg, fastest at "
                             f"{math.degrees(energy.fastest_angle):.4g} deg")
        if energy is not None:
            speed = abs(float(self.sweep.drivers.v[self.driver_index]))
            if self.flywheel and speed > 0:
                lines.append(f"{name}: coefficient of speed fluctuation {energy.speed_fluctuation(self.flywheel, speed):.4g}"
                             f" with a {self.flywheel:.6g} kg m^2 flywheel at {speed:.6g} rad/s (flywheel inertia only)")
        return lines

    def _zero_crossings(self) -> list[str]:
        x, e = np.array(self.values), np.array(self.efforts)
        out = []
        for i in np.nonzero(np.sign(e[:-1]) * np.sign(e[1:]) < 0)[0][:12]:
            at = x[i] - e[i] * (x[i + 1] - x[i]) / (e[i + 1] - e[i])
            out.append(f"{math.degrees(at):.4g} deg" if self.sweep.is_angular else f"{at:.6g} m")
        return out


class ForceCsv(SweepCsv):
    """The sweep's CSV with the force columns after the kinematic ones."""

    def __init__(self, forces: SweepForces, stream: IO[str]) -> None:
        super().__init__(forces.sweep, stream)
        self.forces = forces
        self._width = 0

    def _columns(self, pose: SweepPose) -> list[str]:
        extra = self.forces.columns(self.forces.solve(pose))
        self._width = len(extra)
        return super()._columns(pose) + extra

    def _row(self, pose: SweepPose) -> list[object]:
        base = len(self.header) - self._width
        return row(self.sweep, pose, base) + self.forces.cells(self.forces.solve(pose), self._width)


class ForceJsonLines(SweepJsonLines):
    """JSON lines with a `forces` object per solved pose (as `pinmech solve --json`)."""

    def __init__(self, forces: SweepForces, stream: IO[str]) -> None:
        super().__init__(forces.sweep, stream)
        self.forces = forces

    def _entry(self, pose: SweepPose) -> dict[str, Any]:
        entry = super()._entry(pose)
        f = self.forces.solve(pose)
        if f is not None:
            entry["forces"] = forces_dict(f, self.sweep.mechanism, static=self.forces.static)
            if self.forces.static:  # as `pinmech forces --static --json` and the CSV column
                entry["forces"]["mechanical_advantage"] = self.forces._advantage(f)
        return entry


class TorquePlot:
    """The driver's torque (or force) curve: with its mean and the flywheel's energy E(θ) in
    dynamics, with the mechanical advantage in statics (`pinmech.draw.plot_torque`)."""

    def __init__(self, forces: SweepForces) -> None:
        self.forces = forces
        self.advantage: list[float] = []

    def add(self, pose: SweepPose) -> None:
        f = self.forces.solve(pose)
        if f is not None and self.forces.static and self.forces.solver.loads:
            self.advantage.append(self.forces._advantage(f))

    def save(self, path: str | Path) -> Path:
        from pinmech.draw.plot_torque import save_torque_figure, torque_curve

        f = self.forces
        if not f.values:
            raise SceneError(f"no pose of the sweep could be solved: no torque curve to draw in {path}",
                             path=str(f.sweep.scene.path))
        cycle = not f.static and f.energy() is not None
        unit = advantage_unit(f.sweep.is_angular, f.solver.loads[0]) if self.advantage else "1"
        curve = torque_curve(f.sweep.driver, np.array(f.values), np.array(f.efforts), angular=f.sweep.is_angular,
                             cycle=cycle, advantage=np.array(self.advantage) if self.advantage else None,
                             advantage_unit=unit)
        if cycle:  # the mean as the summary prints it (rounding noise shown as 0)
            curve = replace(curve, mean=_shown(curve.mean, f.efforts))
        kind = "statics" if f.static else "dynamics"
        return save_torque_figure(curve, f"{f.sweep.scene.title}: driver {f.sweep.driver} over the sweep ({kind})", path)


def _shown(mean: float, efforts: list[float]) -> float:
    """The mean torque, with rounding noise (below 1e-12 of the largest torque) shown as 0."""
    return mean if abs(mean) > 1e-12 * max(map(abs, efforts), default=0.0) else 0.0
