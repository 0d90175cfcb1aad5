"""Each synthesis task's search rows: their bounds, their batch objective, the refinement
of one row and the classical starting rows (path: objective and
path; function: function; motion: poses)."""

from __future__ import annotations

import numpy as np

from pinmech.design.synthesis.burmester import four_bar_rows
from pinmech.design.synthesis.slider_three_poses import slider_crank_rows
from pinmech.design.synthesis.file import SIX_BARS, SynthesisSpec
from pinmech.design.synthesis.function import evaluate_function, freudenstein_rows, function_bounds, refined_function
from pinmech.design.synthesis.inverted_function import (evaluate_inverted_function, inverted_function_bounds,
                                                        refined_inverted_function)
from pinmech.design.synthesis.objective import BatchValues, evaluate_path, path_bounds
from pinmech.design.synthesis.path import refined_path
from pinmech.design.synthesis.poses import evaluate_poses, poses_bounds, refined_poses
from pinmech.design.synthesis.result import Linkage
from pinmech.design.synthesis.sixbar import evaluate_sixbar, refined_sixbar, sixbar_bounds
from pinmech.design.synthesis.slider_function import (evaluate_slider_function, refined_slider_function,
                                                      slider_function_bounds)


def _task(spec: SynthesisSpec) -> str:
    """The task's key: "slider function" for a slider-crank's function, "inverted function" for an
    inverted slider-crank's (their own rows); "six-bar" for a Watt's or a Stephenson's path,
    function or motion (on the engine)."""
    if spec.topology in SIX_BARS:
        return "six-bar"
    if spec.task == "function" and spec.topology != "four-bar":
        return {"slider-crank": "slider function", "inverted-slider-crank": "inverted function"}[spec.topology]
    return spec.task


def search_bounds(spec: SynthesisSpec) -> list[tuple[float, float]]:
    """The bounds of the task's search rows."""
    return {"function": function_bounds, "motion": poses_bounds, "slider function": slider_function_bounds,
            "inverted function": inverted_function_bounds,
            "six-bar": sixbar_bounds}.get(_task(spec), path_bounds)(spec)


#: Rows evaluated at once: a block's arrays (rows x 180 crank angles: 92 kB at 64 rows) stay
#: in the CPU's caches, where a whole population's were allocated and faulted in afresh at
#: every call, three times slower. Every row is evaluated on its own arithmetic, so the
#: blocks change no bit of the values.
BLOCK = 64


def evaluate(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> BatchValues:
    """The task's objective of rows x on one assembly (a Dask task), BLOCK rows at a time."""
    function = {"function": evaluate_function, "motion": evaluate_poses,
                "slider function": evaluate_slider_function,
                "inverted function": evaluate_inverted_function,
                "six-bar": evaluate_sixbar}.get(_task(spec), evaluate_path)
    if len(x) <= BLOCK:
        return function(spec, assembly, x)
    parts = [function(spec, assembly, x[i:i + BLOCK]) for i in range(0, len(x), BLOCK)]
    return BatchValues(np.concatenate([p.values for p in parts]), [c for p in parts for c in p.causes],
                       np.concatenate([p.theta for p in parts]))


def refined(spec: SynthesisSpec, assembly: float, x: np.ndarray) -> Linkage | None:
    """Row x refined with the exact Jacobian, checked for defects (None: it has one)."""
    return {"function": refined_function, "motion": refined_poses,
            "slider function": refined_slider_function,
            "inverted function": refined_inverted_function,
            "six-bar": refined_sixbar}.get(_task(spec), refined_path)(spec, assembly, x)


def classical_rows(spec: SynthesisSpec) -> np.ndarray:
    """Rows from the classical closed forms (Freudenstein for functions, Burmester's dyad
    pairs for four poses of a four-bar, the slider-crank's three-pose construction, those
    within the bounds), best first."""
    if spec.task == "function" and spec.topology == "four-bar":
        return freudenstein_rows(spec)
    if spec.task == "motion" and spec.topology == "four-bar" and len(spec.targets) == 4:
        rows = four_bar_rows(spec.targets, spec.angles)
        inside = np.all((rows[:, :9] >= spec.lower) & (rows[:, :9] <= spec.upper), axis=1)
        return rows[inside]
    if spec.task == "motion" and spec.topology == "slider-crank" and len(spec.targets) == 3:
        reach = spec.upper[5] + float(np.abs(np.concatenate((spec.lower[6:], spec.upper[6:]))).max())  # |B - P|
        rows = slider_crank_rows(spec.targets, spec.angles, spec.lower[:2], spec.upper[:2], reach)[:, :9]
        inside = np.all((rows[:, :8] >= spec.lower) & (rows[:, :8] <= spec.upper), axis=1)
        return rows[inside]
    return np.zeros((0, len(search_bounds(spec))))
