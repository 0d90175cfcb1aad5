"""One variant of a study: the scene's mechanism with its parameters written in place,
solved over one turn of its driver on the nominal assembly, or the cause it failed.

A variant is never dropped in silence: a variant whose loops do not close at the start
("cannot assemble"), that closes there only on another assembly ("other assembly"), that
meets a fold of the driver within the turn ("fold within the range"), passes a change
point where its assembly changes ("changes assembly"), or has a value outside its bounds
("outside bounds") carries that cause.
"""

from __future__ import annotations

import math

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.exceptions import (
    AssemblyError,
    DriverLimitError,
    LoopClosureError,
    ModelError,
    PinmechError,
    SceneError,
    SingularPoseError,
)
from pinmech.io.scene import Scene
from pinmech.design.study.file import StudySpec, spec_scene
from pinmech.design.study.params import Placement, placements, subtrees
from pinmech.design.study.variant_core import CoreCycle
from pinmech.io.sweep import Sweep, sweep_options
from pinmech.solve.kernels import resolved

CAUSES = ("cannot assemble", "other assembly", "fold within the range", "changes assembly", "singular pose",
          "outside bounds")


@dataclass(frozen=True)
class VariantCycle:
    """A variant solved over the cycle: q, v, a at each pose (None where it failed) and the
    cause."""

    values: np.ndarray
    q: np.ndarray | None
    cause: str = ""
    detail: str = ""
    error: PinmechError | None = None  # the error behind the cause (None: outside bounds)
    v: np.ndarray | None = None  # joint velocities [rad/s, m/s] at the scene's driver speed
    a: np.ndarray | None = None  # joint accelerations [rad/s^2, m/s^2]


class StudyMechanism:
    """The scene's mechanism, swept, with the study's parameters bound to its model.

    Built once per process (a Dask worker builds its own from the study file: Pinocchio's
    constraint models do not pickle). Attributes: nominal [m] of each parameter, the
    sweep's driver values [rad or m], and the nominal reference (q and its signs).
    """

    def __init__(self, spec: StudySpec, poses: int | None = None) -> None:
        """`poses`: about how many poses the run solves (default: the study's variants times
        its steps), for the scene's kernel = "auto" (solve/kernels.py's `resolved`)."""
        self.spec = spec
        self.scene = scene = spec_scene(spec)
        self.sweep = Sweep.from_scene(scene)
        self.mechanism, self.solver = self.sweep.mechanism, self.sweep.solver
        if spec.certify is not None:  # the run's dial over the scene's [solver] certify
            self.solver.certify = spec.certify
        self.solver.kernel = resolved(self.solver.kernel, _run_poses(spec) if poses is None else poses)
        self.model = self.mechanism.model
        self.placements: list[Placement] = placements(self.mechanism, spec.params, str(spec.path), scene)
        self._drawing = next((place.drawing for place in self.placements if place.drawn), None)
        for axis in spec.grid:  # a grid's values are in its parameter's own quantity
            if axis.kind != self.placements[axis.param].kind:
                kind = self.placements[axis.param].kind
                raise SceneError(f"grid.{axis.name} is given as {axis.kind}s, but {axis.name} is "
                                 f"{'an' if kind == 'angle' else 'a'} {kind}: give from and to in "
                                 f"{'deg' if kind == 'angle' else 'mm'}", path=str(spec.path), key=f"grid.{axis.name}")
        for p, place in zip(spec.params, self.placements):
            if p.nominal is not None:
                try:
                    place.write(p.nominal)
                except ModelError as exc:  # a drawing the nominal cannot make: the study file's value
                    raise SceneError(f"the nominal cannot be drawn: {exc}", path=str(spec.path),
                                     key=f"params.{p.name}.nominal") from exc
        self.nominal = np.array([place.read() for place in self.placements])
        outside = _outside(spec, self.nominal)
        if outside:
            raise SceneError(f"the nominal {outside}", path=str(spec.path), key="params")
        self.subtree = subtrees(self.model)
        self.values = _cycle_values(scene, self.sweep, spec.steps)
        self.solver.refresh()
        scene_ref = self.solver.reference  # the scene's (scene_solver), closed again for the nominal
        self.reference = self.solver.set_reference(scene_ref.driver_q, scene_ref.q)
        self.assembly = dict(zip(self.solver.structure.names, self.reference.signs))
        self.data = self.model.createData()  # outputs and sensitivities: not the solver's Data
        self.lower = np.array([x.lower for x in spec.params])
        self.upper = np.array([x.upper for x in spec.params])
        self.core = CoreCycle(self.solver, self.sweep.drivers, self.sweep.driver, self.values, self.reference)

    def write(self, p: np.ndarray) -> None:
        """Write the parameter values p [m] into the model in place (a drawn linkage's params
        all at once: one redrawing a variant)."""
        drawn = {}
        for place, value in zip(self.placements, p):
            if place.drawn:
                drawn[place.name] = float(value)
            else:
                place.write(float(value))
        if drawn:
            self._drawing.set(drawn)

    def outside(self, p: np.ndarray) -> np.ndarray:
        """Whether the values p (..., n_par) [m] lie outside a parameter's bounds (...,) bool;
        a batch (count, n_par) is checked in one call."""
        return np.any(p < self.lower, axis=-1) | np.any(p > self.upper, axis=-1)

    def cycle(self, p: np.ndarray) -> VariantCycle:
        """The variant with parameters p [m] over the cycle; the model keeps p afterwards."""
        return self.rejected(p) if self.outside(p) else self.within(p)

    def rejected(self, p: np.ndarray) -> VariantCycle:
        """The variant p [m] outside its bounds, with the first parameter outside named."""
        return VariantCycle(self.values, None, "outside bounds", _outside(self.spec, p))

    def within(self, p: np.ndarray) -> VariantCycle:
        """The variant with parameters p [m] (within their bounds: `outside` checked) over
        the cycle; the model keeps p afterwards. The compiled core follows it in one call
        (variant_core.py); where it hands the variant back, the scene's sweep solves it and
        names what failed. A drawn linkage's variant that cannot be drawn (a compass whose
        circles do not meet, a link of no length) cannot be assembled."""
        try:
            self.write(p)
        except ModelError as exc:
            return VariantCycle(self.values, None, "cannot assemble", str(exc), exc)
        fast = self.core.follow()
        if fast is not None:
            return VariantCycle(self.values, fast[0], v=fast[1], a=fast[2])
        self.solver.refresh()
        try:
            self.solver.set_reference(self.reference.driver_q, self.reference.q, assembly=self.assembly)
        except (LoopClosureError, SingularPoseError) as exc:
            return VariantCycle(self.values, None, "cannot assemble", str(exc), exc)
        except AssemblyError as exc:
            return VariantCycle(self.values, None, "other assembly", str(exc), exc)
        return self._swept()

    def _swept(self) -> VariantCycle:
        rows, v, a = [], [], []
        for chunk in self.sweep.chunks(self.values):
            if chunk.errors:
                exc = next(iter(chunk.errors.values()))
                return VariantCycle(self.values, None, _cause(exc), str(exc), exc)
            if chunk.notes:
                note = next(iter(chunk.notes.values()))
                return VariantCycle(self.values, None, "changes assembly", note,
                                    AssemblyError(note, expected=(), found=()))
            rows.append(chunk.solution.q)
            v.append(chunk.solution.v)
            a.append(chunk.solution.a)
        return VariantCycle(self.values, np.vstack(rows), v=np.vstack(v), a=np.vstack(a))

    def at(self, q: np.ndarray) -> pin.Data:
        """self.data with joint Jacobians and every frame placement at q (kept as self.q_at)."""
        self.q_at = np.array(q, dtype=float)
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        return self.data


def _run_poses(spec: StudySpec) -> int:
    """The poses a study solves: its variants (samples, grid points, or the nominal and two
    a parameter for its slopes) times its steps."""
    variants = {"tolerance": spec.samples, "grid": math.prod(a.count for a in spec.grid)}
    return variants.get(spec.kind, 2 * len(spec.params) + 1) * spec.steps


def _cycle_values(scene: Scene, sweep: Sweep, steps: int) -> np.ndarray:
    """The study's driver values [rad or m]: `steps` evenly spaced over the scene's
    [sweep] from .. to where it gives them (a five-bar's motor cannot turn fully), else
    over one turn of the driver from its scene value, both ends included."""
    options = sweep_options(scene)
    kind = "angle" if sweep.is_angular else "length"
    start = scene.quantity(options["from"], kind, "sweep", "from") if "from" in options else sweep.start
    span = sweep.default_values(2)[1] - sweep.start
    stop = scene.quantity(options["to"], kind, "sweep", "to") if "to" in options else start + span
    return np.linspace(start, stop, steps) if steps > 1 else np.array([start])


def _cause(exc: PinmechError) -> str:
    cause = getattr(exc, "cause", exc)  # a SweepError carries the pose's error
    if isinstance(cause, DriverLimitError):
        return "fold within the range"
    if isinstance(cause, AssemblyError):
        return "changes assembly"
    if isinstance(cause, SingularPoseError):
        return "singular pose"
    return "cannot assemble" if isinstance(cause, LoopClosureError) else type(cause).__name__


def _outside(spec: StudySpec, p: np.ndarray) -> str:
    for x, value in zip(spec.params, p):
        if not x.lower <= value <= x.upper:
            return (f"params.{x.name}: {value * 1e3:.6g} mm is outside "
                    f"{x.lower * 1e3:.6g} .. {x.upper * 1e3:.6g} mm")
    return ""
