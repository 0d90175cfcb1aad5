"""What a synthesis returns: the linkages found, each able to say how closely it meets
its targets, and the candidates rejected by cause."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from pinmech.design.synthesis.file import SynthesisSpec

#: What "meets the targets" means: every target within this share of the linkage's size
#: (its longest link; an output angle within this many radians). The search stops once
#: a refined linkage meets it; the report says whether each linkage does.
MET = 1e-10


@dataclass(frozen=True)
class Linkage:
    """A synthesised four-bar (or slider-crank) that meets the targets without defects.

    Attributes:
        z: (O2x, O2y, O4x, O4y, crank, coupler, rocker, along, across) [m]; a slider-crank's
            slider.NAMES.
        s: the assembly (+1: B left of A -> O4, -1: right).
        theta: the crank's angle at each target [rad] (world x, ccw).
        way: the crank's turn from target to target (+1 ccw, -1 cw).
        errors: |P - target| at each target [m] (path), or the rocker's angle error at
            each pair [rad] (function).
        transmission: the least and greatest transmission angle over the motion [rad].
        grashof: its Grashof class.
        task: "path", "function" or "motion".
        phi0: a function generator's rocker angle asked at the first pair, or a motion
            generator's angle from the bar A -> B to the poses' line [rad].
        angle_errors: a motion generator's coupler angle error at each pose [rad].
        topology: "four-bar", "slider-crank" or "inverted-slider-crank" (z: its
            inverted.NAMES; phi0 of a function: the guide's angle at the first pair),
            "watt" or "stephenson".
        params: a six-bar's drawn linkage's [params] (z: its free ones, spec.free) [m].
    """

    z: np.ndarray
    s: float
    theta: np.ndarray
    way: int
    errors: np.ndarray
    transmission: tuple[float, float]
    grashof: str
    task: str = "path"
    phi0: float = 0.0
    angle_errors: np.ndarray | None = None
    topology: str = "four-bar"
    params: dict[str, float] | None = None

    @property
    def size(self) -> float:
        """The linkage's size: its longest link [m] (a slider-crank's: the largest of crank,
        rod and offset; a six-bar's: its largest param, length or coordinate)."""
        if self.params is not None:
            return float(max(abs(v) for v in self.params.values()))
        from pinmech.design.synthesis.kinematics import kinematics

        return kinematics(self.topology).size(self.z)

    def meets(self, relative: float) -> bool:
        """Whether every target is met within `relative` of the linkage's size (path; a
        motion's angles within `relative` rad too), or every output angle within `relative`
        rad (a four-bar's, an inverted slider-crank's or a six-bar's function; a slider-crank's
        travel within `relative` of its size)."""
        if self.task == "function" and self.topology != "slider-crank":  # an output angle
            return bool(np.max(self.errors) <= relative)
        angles = self.angle_errors if self.angle_errors is not None else np.zeros(1)
        return bool(np.max(self.errors) <= relative * self.size and np.max(angles) <= relative)


@dataclass
class SynthesisResult:
    """The linkages found (best first), the candidates rejected by cause, and the search's
    counts (evaluations, generations)."""

    spec: SynthesisSpec
    linkages: list[Linkage]
    rejected: Counter = field(default_factory=Counter)
    evaluations: int = 0
    generations: int = 0
