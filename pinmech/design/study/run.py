"""Design studies, the Python face: `study("models/studies/four_bar_tolerance.toml")`.

    import pinmech
    result = pinmech.study("models/studies/four_bar_tolerance.toml", workers=2)
    print(result.summary())

Kinds: "sensitivity" (exact dy/dp over the cycle, sensitivity.py), "tolerance"
(seeded Monte Carlo beside the linear estimate, tolerance.py) and "grid" (the outputs over
a grid of parameter values, grid.py) and "workspace" (a parallel mechanism's workspace,
singularity loci and conditioning, workspace.py), run in batches here or on Dask (cluster.py).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pinmech.design.cluster import built, run_batches
from pinmech.design.study.capability import limits as capability_limits
from pinmech.design.study.grid import grid_size
from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.file import StudySpec, load_study
from pinmech.design.study.tolerance import Batch, BatchResult, Spread, batches, spread
from pinmech.design.workspace.run import WorkspaceResult, run_workspace
from pinmech.design.workspace.file import WorkspaceSpec, is_workspace, parse_workspace
from pinmech.exceptions import SceneError
from pinmech.solve.kernels import checked_kernel
from pinmech.toml_file import read_toml


@dataclass(frozen=True)
class StudyResult:
    """A study's results (SI).

    Attributes:
        spec: the study file, validated; driver: the swept driver; values: its values [rad or m].
        outputs: output names; kinds: "length" or "angle" each; params: parameter names.
        nominal_p: the parameters' nominal values [m].
        nominal: (steps, n_out) outputs of the nominal; sensitivity: (steps, n_out, n_par) dy/dp.
        spread: the tolerance study's Spread (None for a sensitivity study).
        batches: a tolerance or grid study's variants (grid points), batch by batch (empty
            for a sensitivity study).
    """

    spec: StudySpec
    driver: str
    values: np.ndarray
    outputs: list[str]
    kinds: list[str]
    params: list[str]
    nominal_p: np.ndarray
    nominal: np.ndarray
    sensitivity: np.ndarray
    spread: Spread | None = None
    batches: tuple[BatchResult, ...] = ()
    param_kinds: tuple[str, ...] = ()  # "length" or "angle" each (a drawn angle param) ; () all lengths
    limits: dict = dataclasses.field(default_factory=dict)  # output -> (lower, upper) of its deviation [SI]
    certify: str = "every-pose"  # the certification dial the variants were followed with (certify.py)

    def param_kind(self, k: int) -> str:
        """Parameter k's kind: "length" [m] or "angle" [rad]."""
        return self.param_kinds[k] if self.param_kinds else "length"

    @property
    def variants(self) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """The variants' parameters (N, n_par) [m], outputs (N, steps, n_out) and causes."""
        if not self.batches:
            return np.zeros((0, len(self.params))), np.zeros((0, len(self.values), len(self.outputs))), []
        return (np.concatenate([b.p for b in self.batches]), np.concatenate([b.y for b in self.batches]),
                [c for b in self.batches for c in b.causes])

    @property
    def transmission(self) -> np.ndarray | None:
        """A grid study's least transmission angle over the cycle at each point (N,) [rad]
        (NaN where the point failed); None for other studies and mechanisms without a dyad."""
        if not self.batches or any(b.extra is None for b in self.batches):
            return None
        return np.concatenate([b.extra for b in self.batches])


def study(path: str | Path | StudySpec | WorkspaceSpec, *, workers: int = 0, scheduler: str | None = None,
          progress: Callable[[int, int], None] | None = None, certify: str | None = None,
          kernel: str | None = None) -> StudyResult | WorkspaceResult:
    """Run a study file.

    Args:
        path: the study file (or a StudySpec already loaded).
        workers: 0 runs the variants in this process, n > 0 on a Dask LocalCluster of n
            processes; scheduler: a running Dask scheduler's address instead.
        progress: called with (variants done, variants) as each batch of a tolerance or grid
            study finishes.
        certify: the certification dial of each variant's cycle ("every-pose", "every-K",
            "ends", "none"; certify.py); None: the scene's `[solver] certify`. A workspace
            study solves each grid point on its own, certified, and refuses another level.
        kernel: the kinematic passes every variant runs, "generic" or "generated" (one
            kernel for every variant: the lengths are its inputs); None: the scene's [solver] kernel.

    Raises:
        SceneError: a bad study file (FrameNotFound: a name the model lacks); the scene's
            and model's errors; for a workspace study, a mechanism that is not parallel
            (key "scene") or a grid reaching no point (key "workspace").
        LoopClosureError: the nominal does not assemble.
        SweepError: the nominal's cycle fails.
        ImportError: naming `pinmech[study]`, without Dask.
    """
    from pinmech.design.cluster import checked_workers

    checked_workers(workers)  # before the file is read: a count that would fork the machine to a halt
    spec = path if isinstance(path, (StudySpec, WorkspaceSpec)) else load_any_study(Path(path))
    if certify is not None:
        spec = _with_certify(spec, certify)
    if kernel is not None:
        spec = dataclasses.replace(spec, kernel=checked_kernel(kernel))
    if spec.kind == "workspace":
        return run_workspace(spec, workers=workers, scheduler=scheduler, progress=progress)
    sm, outputs = built(spec)
    limits = capability_limits(spec.limits, outputs.names, outputs.kinds, str(spec.path))
    cycle = sm.cycle(sm.nominal)
    if cycle.cause:
        from pinmech.exceptions import SweepError

        raise SweepError(f"{spec.path}: the nominal fails over the cycle ({cycle.cause}): {cycle.detail}",
                         driver=sm.sweep.driver, value=float("nan"), cause=cycle.error) from cycle.error
    y0, dy = cycle_sensitivity(sm, outputs, cycle)
    common = dict(spec=spec, driver=sm.sweep.driver, values=sm.values, outputs=outputs.names, kinds=outputs.kinds,
                  params=[p.name for p in spec.params], nominal_p=sm.nominal.copy(), nominal=y0, sensitivity=dy,
                  param_kinds=tuple(place.kind for place in sm.placements), certify=sm.solver.certify)
    if spec.kind == "sensitivity":
        return StudyResult(**common)
    todo = batches(grid_size(spec) if spec.kind == "grid" else spec.samples, spec.batch)
    total, done = sum(b.count for b in todo), [0]

    def tick(batch: Batch) -> None:
        done[0] += batch.count
        progress(done[0], total)

    results = run_batches(spec, todo, workers=workers, scheduler=scheduler, progress=tick if progress else None)
    if spec.kind == "grid":
        return StudyResult(**common, batches=tuple(results))
    return StudyResult(**common, spread=spread(sm, outputs, results), batches=tuple(results), limits=limits)


def _with_certify(spec: StudySpec | WorkspaceSpec, certify: str) -> StudySpec | WorkspaceSpec:
    """The spec with the run's certification level (checked: OptionError naming the levels)."""
    from pinmech.solve.certify import EVERY_POSE, checked_certify

    level = checked_certify(certify)
    if spec.kind == "workspace":
        if level != EVERY_POSE:
            from pinmech.exceptions import OptionError

            raise OptionError(f"{spec.path}: certify = {certify!r}: a workspace study solves each grid point on its "
                              "own, every one certified (no range to certify fewer poses of)", option="certify",
                              value=certify)
        return spec
    return dataclasses.replace(spec, certify=level)


def load_any_study(path: str | Path) -> StudySpec | WorkspaceSpec:
    """A study file of any kind, validated (SceneError naming the file and the key)."""
    path = Path(path)
    raw = read_toml(path, "study", SceneError)
    return parse_workspace(raw, path) if is_workspace(raw) else load_study(path)
