"""The search: SciPy's differential evolution over the synthesis file's bounds, seeded,
with its population evaluated by a map (this process, or the Dask cluster of cluster.py),
then a least-squares refinement of the best distinct candidates with the exact Jacobian
(implicit-function theorem, fourbar.point_jacobian). Each refined linkage is
checked again for defects and constraints (motion.causes) before it is kept.

Same seed, same linkage on any number of workers: the population is evaluated row by row
in the same arithmetic and gathered in order, and DE updates it once per generation
(`updating="deferred"`) whatever evaluates it.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from pathlib import Path

import numpy as np

from pinmech.design.synthesis.file import SIX_BARS, SynthesisSpec, load_synthesis
from pinmech.design.synthesis.kinematics import kinematics
from pinmech.design.synthesis.result import MET as _MET, Linkage, SynthesisResult
from pinmech.design.synthesis.tasks import classical_rows, evaluate, refined, search_bounds
from pinmech.solve.kernels import checked_kernel

_EXTRA = 'pip install "pinmech[study]"'
_CLOSE = 3e-2  # from a best relative rms target error below this, every 10th generation tries a refinement ...
_STRATEGY = "rand1bin"
_STALL = 100  # generations without a 1 % better best: DE restarts with the next seed
_SETTLED = 5  # refinements in a row (every 10th generation) landing no 1 % lower: a local optimum, restart
_RESTART = 7919  # a restart's seed: the file's + this times the restart's number
_DISTINCT = 0.02  # two linkages whose parameters differ by less than this share of the bounds are one


class PopulationMap:
    """The `workers` of differential_evolution: evaluates a whole population at once, in
    this process or as `chunks` Dask tasks, and counts the rejected candidates by cause."""

    def __init__(self, spec: SynthesisSpec, client=None, chunks: int = 1, address: str = "local") -> None:
        self.spec, self.client, self.chunks, self.address = spec, client, chunks, address
        self.assembly = 1.0
        self.rejected: Counter = Counter()
        self.evaluations = 0

    def __call__(self, func, rows) -> list[float]:
        x = np.array(list(rows), dtype=float)
        if self.client is None:
            parts = [evaluate(self.spec, self.assembly, x)]
        else:
            from pinmech.design.cluster import lost_as_cluster_error

            with lost_as_cluster_error(self.address, lambda: f"{self.evaluations} candidates"):
                futures = self.client.map(evaluate, [self.spec] * self.chunks, [self.assembly] * self.chunks,
                                          np.array_split(x, self.chunks), pure=False)
                parts = self.client.gather(futures)
        self.evaluations += len(x)
        values = []
        for part in parts:
            self.rejected.update(c for c in part.causes if c)
            values += part.values.tolist()
        return values


def synthesise(spec: SynthesisSpec | str | Path, *, workers: int = 0, scheduler: str | None = None,
               kernel: str | None = None) -> SynthesisResult:
    """The best distinct linkages (up to spec.keep) that meet the targets without defects.

    Args:
        spec: a synthesis file's spec, or the file (read with load_synthesis).
        workers: 0 evaluates in this process; n > 0 on a LocalCluster of n worker
            processes (unless a scheduler address is given).
        kernel: the engine's kinematic passes for a drawn six-bar's candidates ("generic" or
            "generated": one kernel for the whole search); None: the template scene's. The
            four-bar and slider-crank topologies are solved in closed form and run no passes.
    """
    from pinmech.design.cluster import checked_workers

    checked_workers(workers)
    if not isinstance(spec, SynthesisSpec):
        spec = load_synthesis(spec)
    if kernel is not None:
        spec = dataclasses.replace(spec, kernel=checked_kernel(kernel))
    if scheduler is None and workers == 0:
        return _run(spec, PopulationMap(spec))
    from pinmech.design.cluster import connected, local_cluster, require_dask

    distributed = require_dask()
    if scheduler is not None:  # the study's checks: the address, a TCP connection, Dask's handshake
        with connected(scheduler, distributed) as client:
            return _run(spec, PopulationMap(spec, client, max(workers, 1), scheduler))
    with local_cluster(workers) as cluster, distributed.Client(cluster) as client:
        return _run(spec, PopulationMap(spec, client, workers, "local"))


def _run(spec: SynthesisSpec, mapper: PopulationMap) -> SynthesisResult:
    """DE on each assembly in turn (the second only if the first found no linkage meeting
    the targets within _MET), restarted with the next seed of the stream when it stalls
    until the assembly's generations are spent; the best distinct refined, best first."""
    found: list[Linkage] = []
    generations = 0
    assemblies = (1.0,) if spec.topology in SIX_BARS else getattr(kinematics(spec.topology), "ASSEMBLIES", (1.0, -1.0))
    for assembly in assemblies:  # a six-bar's: as drawn
        mapper.assembly = assembly
        left, restart = spec.generations, 0
        while left > 0 and not any(lk.meets(_MET) for lk in found):
            rows, energies, nit = _evolved(spec, mapper, assembly, spec.seed + _RESTART * restart, left)
            generations, left, restart = generations + nit, left - nit, restart + 1
            starts = _distinct(spec, rows, energies, 3 * spec.keep) + _classical(spec, assembly, 3 * spec.keep)
            found += [lk for lk in (refined(spec, assembly, x) for x in starts) if lk is not None]
        if any(lk.meets(_MET) for lk in found):
            break
    found.sort(key=lambda lk: float(np.sum(lk.errors**2)))
    kept: list[Linkage] = []
    for lk in found:
        if all(_far(spec, _bounded(spec, lk), _bounded(spec, other)) for other in kept):
            kept.append(lk)
    return SynthesisResult(spec, kept[:spec.keep], mapper.rejected, mapper.evaluations, generations)


def _evolved(spec: SynthesisSpec, mapper: PopulationMap, assembly: float, seed: int,
             generations: int) -> tuple[np.ndarray, np.ndarray, int]:
    """DE's final population on one assembly, best first, its objective values and the
    generations it ran (at most `generations`; fewer once it meets the targets or stalls)."""
    opt = _scipy_optimize()

    def objective(x: np.ndarray) -> float:  # what the map stands for; never called itself
        return float(evaluate(spec, assembly, x[None]).values[0])

    de = opt.differential_evolution(objective, search_bounds(spec), seed=seed, popsize=spec.population,
                                    maxiter=generations, workers=mapper, updating="deferred", polish=False,
                                    init="sobol", tol=0.0, atol=-1.0, mutation=(0.5, 1.0), recombination=0.9,
                                    strategy=_STRATEGY, callback=_stopper(spec, assembly))
    # atol < 0: never "converged" (a population all rejected is flat, not converged)
    order = np.argsort(de.population_energies, kind="stable")
    return de.population[order], de.population_energies[order], int(de.nit)


def _stopper(spec: SynthesisSpec, assembly: float):
    """DE's callback: True (stop) once the best so far refines to a linkage that meets
    every target within _MET of its size (tried every 10th generation from _CLOSE on); or
    once the best has not fallen by 1 % in _STALL generations; or once _SETTLED refinements
    in a row have landed no 1 % lower (the population creeps down a basin whose bottom
    misses the targets: a local optimum). A restart with the next seed does better."""
    count = iter(range(10**9))
    best = [np.inf, 0]  # the best objective that was 1 % below the one before, and its generation
    landed = [np.inf, 0]  # the lowest refined sum of squared errors 1 % below the one before, refinements since

    def callback(intermediate_result) -> bool:
        k = next(count)
        if intermediate_result.fun < 0.99 * best[0]:
            best[:] = [intermediate_result.fun, k]
        if k - best[1] >= _STALL:
            return True
        if k % 10 or intermediate_result.fun > _CLOSE**2 * len(spec.targets):
            return False
        lk = refined(spec, assembly, intermediate_result.x)
        if lk is not None and lk.meets(_MET):
            return True
        value = float(np.sum(lk.errors**2)) if lk is not None else np.inf
        landed[:] = [value, 0] if value < 0.99 * landed[0] else [landed[0], landed[1] + 1]
        return landed[1] >= _SETTLED

    return callback


def _classical(spec: SynthesisSpec, assembly: float, count: int) -> list[np.ndarray]:
    """Up to `count` distinct accepted rows of the classical closed forms, best first."""
    rows = classical_rows(spec)
    if not len(rows):
        return []
    values = evaluate(spec, assembly, rows).values
    order = np.argsort(values, kind="stable")
    return _distinct(spec, rows[order], values[order], count)


def _distinct(spec: SynthesisSpec, rows: np.ndarray, energies: np.ndarray, count: int) -> list[np.ndarray]:
    """Up to `count` accepted rows, best first, no two closer than _DISTINCT."""
    out: list[np.ndarray] = []
    for x, e in zip(rows, energies):
        if e < 1e2 and all(_far(spec, x, y) for y in out):
            out.append(x)
        if len(out) == count:
            break
    return out


def _bounded(spec: SynthesisSpec, lk: Linkage) -> np.ndarray:
    """The linkage's parameters that the file bounds (all of a path's; crank, coupler,
    rocker of a four-bar's function, crank, rod, offset of a slider-crank's)."""
    if spec.task != "function" or spec.topology in SIX_BARS:
        return lk.z
    return lk.z[[4, 5, 3]] if spec.topology == "slider-crank" else lk.z[4:7]


def _far(spec: SynthesisSpec, a: np.ndarray, b: np.ndarray) -> bool:
    n = len(spec.lower)
    return bool(np.max(np.abs(a[:n] - b[:n]) / (spec.upper - spec.lower)) > _DISTINCT)


def _scipy_optimize():
    try:
        import scipy.optimize as opt
    except ImportError as exc:
        raise ImportError(f"synthesis needs SciPy: {_EXTRA} ({exc})") from exc
    return opt
