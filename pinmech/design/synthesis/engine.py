"""An engine-evaluated synthesis candidate: a six-bar (any drawn linkage with `[params]`)
whose candidate values are written into the user's model in place (the study's drawing,
drawn_params.py, through a StudyMechanism built from the synthesis file) and followed by
the compiled core over the crank's whole turn on one assembly (variant_core.py).

The follow starts at the drawn pose (the scene's driver value there), where the drawn
linkage's `side =` choices fix the assembly, and goes over the crank's range: the template
scene's [sweep] from .. to if it gives them, else a whole turn from the drawn pose; a candidate is rejected, with its cause, when
it cannot be drawn ("does not assemble at the start"), when its start closes on another
assembly (its signature differs from the template's: "other assembly at the start"), or
when the follow meets a fold ("fold within the turn": a circuit defect, the crank cannot
complete its range) or passes a change point ("change point within the turn": a branch
defect) or an ill-conditioned pose ("singular pose"). Whatever it reports is read along
that one continuation.

One template per process (Pinocchio's models do not pickle: a Dask worker builds its own).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.variant import StudyMechanism
from pinmech.design.synthesis.file import SynthesisSpec
from pinmech.exceptions import ModelError, SceneError

GRID = 360  # poses over the crank's turn (1 deg apart) for the nearest points and the transmission
#: The core's reasons (variant_core.STOPS and the start's), as a synthesis names them.
_CAUSES = {"cannot assemble": "does not assemble at the start", "other assembly": "other assembly at the start",
           "fold within the range": "fold within the turn", "changes assembly": "change point within the turn",
           "singular pose": "singular pose", "unusable": "no compiled core"}
_TEMPLATES: dict[tuple, "EngineTemplate"] = {}


class EngineTemplate:
    """A six-bar synthesis file's template linkage on the engine.

    Attributes:
        sm: the StudyMechanism of the scene with the free params as drawn study params.
        outputs: the coupler point's x, y (path), the output link's angle (function), or
            the point's x, y and its link's angle (motion), then the transmission angle of
            each dyad in spec.pins.
        start, stop: the crank's range [rad]: the template scene's [sweep] from .. to, else
            one turn from its driver's value (full: a whole turn).
        grid: the crank's values over the range [rad], GRID + 1 of them (poses: distinct).
    """

    def __init__(self, spec: SynthesisSpec) -> None:
        shown = {"path": {"points": [spec.point]}, "function": {"links": [spec.output]},
                 "motion": {"points": [spec.point], "links": [spec.output]}}[spec.task]
        if spec.pins:
            shown["transmission"] = list(spec.pins)
        raw = {"scene": str(spec.scene.resolve()), "kind": "sensitivity", "steps": 2,
               "params": {name: {"param": name} for name in spec.free}, "outputs": shown}
        self.spec = spec
        searched = spec.population * len(spec.free) * spec.generations * (GRID + 1)  # poses, for kernel "auto"
        self.sm = StudyMechanism(dataclasses.replace(parse_study(raw, spec.path), kernel=spec.kernel), poses=searched)
        self.outputs = StudyOutputs(self.sm)
        self.drawing = self.sm.placements[0].drawing
        self.template = dict(self.drawing.values)
        self.core = self.sm.core
        self.p0 = self.core.p0
        self.start, self.stop = float(self.sm.values[0]), float(self.sm.values[-1])  # the scene's [sweep] from..to
        if not self.stop > self.start:
            raise SceneError(f"a six-bar synthesis follows the crank up from [sweep] from to to: give to above from "
                             f"(from {math.degrees(self.start):.6g} deg, to {math.degrees(self.stop):.6g} deg)",
                             path=str(spec.scene), key="sweep")
        self.full = math.isclose(self.stop - self.start, 2 * math.pi, abs_tol=1e-12)
        self.grid = np.linspace(self.start, self.stop, GRID + 1)
        self.poses = GRID if self.full else GRID + 1  # distinct poses of the grid (a full turn's ends are one)
        self.width = {"path": 2, "function": 1, "motion": 3}[spec.task]  # P's x, y; the link's angle; both

    def write(self, p: np.ndarray) -> str:
        """Draw the linkage with the free params p [m] and write it into the model: "" or
        "does not assemble at the start" (a compass of the drawing cannot close)."""
        values = {**self.template, **{n: float(v) for n, v in zip(self.spec.free, p)}}
        if values == self.drawing.values:
            return ""
        try:
            self.drawing.write(values)
        except ModelError:  # the model keeps the last drawing that closed, and drawing.values its values
            return "does not assemble at the start"
        return ""

    def follow(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, str]:
        """The linkage now written followed from its drawn pose through the crank's values
        (increasing from p0) [rad]: q (n, nq) and dq/dtheta (n, nv) at each, and "" or the
        cause (module doc) where the follow does not reach the last."""
        self.core.targets = np.ascontiguousarray(values, dtype=float)
        path, why = self.core.attempt()
        if path is None:
            return np.zeros((0, self.sm.model.nq)), np.zeros((0, self.sm.model.nv)), _CAUSES.get(why, why)
        return path[0], path[1], ""

    def mapped(self, theta: np.ndarray) -> np.ndarray:
        """Crank values theta [rad] as values of the range (start + a turn's multiple); NaN
        where one lies outside a range that is not a whole turn."""
        value = self.start + np.mod(np.asarray(theta, dtype=float) - self.start, 2 * math.pi)
        return value if self.full else np.where(value <= self.stop, value, np.nan)

    def values(self, Q: np.ndarray) -> np.ndarray:
        """The outputs (n, width + len(pins)) at the poses Q: P's x, y [m] (path), the link's
        angle [rad] (function), or both (motion), then the transmission angles [rad]."""
        zero = np.zeros((len(Q), self.sm.model.nv))
        return self.outputs.cycle(Q, zero, zero)

    def jacobians(self, q: np.ndarray, d1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """At the closed pose q of the linkage now written, with dq/dtheta d1: the reported
        output's derivatives along the free params (width, n_free) [m/m or rad/m] (the
        implicit-function theorem, sensitivity.output_sensitivity, the drawing's own
        change by its central differences) and along the crank (width,) [m/rad or rad/rad]."""
        from pinmech.design.study.sensitivity import output_sensitivity

        zero = np.zeros(self.sm.model.nv)
        dp = output_sensitivity(self.sm, self.outputs, q, zero)[:self.width]
        Y_q, _ = self.outputs.jacobians(self.sm.at(q))
        return dp, Y_q[:self.width] @ d1

    def size(self, p: np.ndarray) -> float:
        """The linkage's size: its largest param (length or coordinate) [m] with p written."""
        values = {**self.template, **{n: float(v) for n, v in zip(self.spec.free, p)}}
        return float(max(abs(v) for v in values.values()))


def template(spec: SynthesisSpec) -> EngineTemplate:
    """This process's template of a six-bar synthesis file (built at its first use)."""
    key = (str(spec.path), str(spec.scene), spec.free, spec.task, spec.point, spec.output, spec.pins)
    if key not in _TEMPLATES:
        _TEMPLATES.clear()
        _TEMPLATES[key] = EngineTemplate(spec)
    return _TEMPLATES[key]
