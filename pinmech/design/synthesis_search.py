"""The search: SciPy's differential evolution over the synthesis file's bounds, seeded,
with its population evaluated by a map (this process, or the Dask cluster of cluster.py),
then a least-squares refinement of the best distinct candidates with the exact Jacobian
(implicit-function theorem, synthesis_fourbar.point_jacobian). Each refined linkage is
checked again for defects and constraints (synthesis_motion.causes) before it is kept.

Same seed, same linkage on any number of workers: the population is evaluated row by row
in the same arithmetic and gathered in order, and DE updates it once per generation
(`updating="deferred"`) whatever evaluates it.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from pinmech.design.synthesis_file import SynthesisSpec
from pinmech.design.synthesis_fourbar import point_jacobian, pose
from pinmech.design.synthesis_motion import causes, progress, transmission_range, grashof_label
from pinmech.design.synthesis_objective import evaluate, extent, search_bounds, split

_EXTRA = 'pip install "pinmech[study]"'
_CLOSE = 3e-2  # from a best relative rms target error below this, every 10th generation tries a refinement ...
_MET = 1e-10  # ... and DE stops when the refined best meets every target within this share of its size
_STRATEGY = "rand1bin"
_DISTINCT = 0.02  # two linkages whose parameters differ by less than this share of the bounds are one


@dataclass(frozen=True)
class Linkage:
    """A synthesised four-bar that meets the targets without defects.

    Attributes:
        z: (O2x, O2y, O4x, O4y, crank, coupler, rocker, along, across) [m].
        s: the assembly (+1: B left of A -> O4, -1: right).
        theta: the crank's angle at each target [rad] (world x, ccw).
        way: the crank's turn from target to target (+1 ccw, -1 cw).
        errors: |P - target| at each target [m].
        transmission: the least and greatest transmission angle over the motion [rad].
        grashof: its Grashof class.
    """

    z: np.ndarray
    s: float
    theta: np.ndarray
    way: int
    errors: np.ndarray
    transmission: tuple[float, float]
    grashof: str

    @property
    def size(self) -> float:
        """The linkage's size: its longest link [m]."""
        return float(max(math.hypot(self.z[2] - self.z[0], self.z[3] - self.z[1]), *self.z[4:7]))

    def meets(self, relative: float) -> bool:
        """Whether every target is met within `relative` of the linkage's size."""
        return bool(np.max(self.errors) <= relative * self.size)


@dataclass
class SynthesisResult:
    """The linkages found (best first), the candidates rejected by cause, and the search's
    counts (evaluations, generations)."""

    spec: SynthesisSpec
    linkages: list[Linkage]
    rejected: Counter = field(default_factory=Counter)
    evaluations: int = 0
    generations: int = 0


class PopulationMap:
    """The `workers` of differential_evolution: evaluates a whole population at once, in
    this process or as `chunks` Dask tasks, and counts the rejected candidates by cause."""

    def __init__(self, spec: SynthesisSpec, client=None, chunks: int = 1) -> None:
        self.spec, self.client, self.chunks = spec, client, chunks
        self.assembly = 1.0
        self.rejected: Counter = Counter()
        self.evaluations = 0

    def __call__(self, func, rows) -> list[float]:
        x = np.array(list(rows), dtype=float)
        if self.client is None:
            parts = [evaluate(self.spec, self.assembly, x)]
        else:
            futures = self.client.map(evaluate, [self.spec] * self.chunks, [self.assembly] * self.chunks,
                                      np.array_split(x, self.chunks), pure=False)
            parts = self.client.gather(futures)
        self.evaluations += len(x)
        values = []
        for part in parts:
            self.rejected.update(c for c in part.causes if c)
            values += part.values.tolist()
        return values


def synthesise(spec: SynthesisSpec, *, workers: int = 0, scheduler: str | None = None) -> SynthesisResult:
    """The best distinct linkages (up to spec.keep) that meet the targets without defects.

    Args:
        workers: 0 evaluates in this process; n > 0 on a LocalCluster of n worker
            processes (unless a scheduler address is given).
    """
    if scheduler is None and workers == 0:
        return _run(spec, PopulationMap(spec))
    from pinmech.design.cluster import require_dask

    distributed = require_dask()
    if scheduler is not None:
        with distributed.Client(scheduler, timeout="20s") as client:
            return _run(spec, PopulationMap(spec, client, max(workers, 1)))
    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  dashboard_address="127.0.0.1:0", host="127.0.0.1") as cluster, \
            distributed.Client(cluster) as client:
        return _run(spec, PopulationMap(spec, client, workers))


def _run(spec: SynthesisSpec, mapper: PopulationMap) -> SynthesisResult:
    """DE on each assembly in turn (the second only if the first found no linkage meeting
    the targets within _MET), the best distinct refined, best first."""
    found: list[Linkage] = []
    generations = 0
    for assembly in (1.0, -1.0):
        mapper.assembly = assembly
        rows, energies, nit = _evolved(spec, mapper, assembly)
        generations += nit
        found += [lk for lk in (_refined(spec, assembly, x) for x in _distinct(spec, rows, energies, 3 * spec.keep))
                  if lk is not None]
        if any(lk.meets(_MET) for lk in found):
            break
    found.sort(key=lambda lk: float(np.sum(lk.errors**2)))
    kept: list[Linkage] = []
    for lk in found:
        if all(_far(spec, lk.z, other.z) for other in kept):
            kept.append(lk)
    return SynthesisResult(spec, kept[:spec.keep], mapper.rejected, mapper.evaluations, generations)


def _evolved(spec: SynthesisSpec, mapper: PopulationMap, assembly: float) -> tuple[np.ndarray, np.ndarray, int]:
    """DE's final population on one assembly, best first, its objective values and the
    generations it ran."""
    opt = _scipy_optimize()

    def objective(x: np.ndarray) -> float:  # what the map stands for; never called itself
        return float(evaluate(spec, assembly, x[None]).values[0])

    de = opt.differential_evolution(objective, search_bounds(spec), seed=spec.seed, popsize=spec.population,
                                    maxiter=spec.generations, workers=mapper, updating="deferred", polish=False,
                                    init="sobol", tol=0.0, atol=-1.0, mutation=(0.5, 1.0), recombination=0.9,
                                    strategy=_STRATEGY, callback=_stopper(spec, assembly))
    # atol < 0: never "converged" (a population all rejected is flat, not converged)
    order = np.argsort(de.population_energies, kind="stable")
    return de.population[order], de.population_energies[order], int(de.nit)


def _stopper(spec: SynthesisSpec, assembly: float):
    """DE's callback: True (stop) once the best so far refines to a linkage that meets
    every target within _MET of its size (tried every 10th generation from _CLOSE on)."""
    count = iter(range(10**9))

    def callback(intermediate_result) -> bool:
        if next(count) % 10 or intermediate_result.fun > _CLOSE**2 * len(spec.targets):
            return False
        lk = _refined(spec, assembly, intermediate_result.x)
        return lk is not None and lk.meets(_MET)

    return callback


def _distinct(spec: SynthesisSpec, rows: np.ndarray, energies: np.ndarray, count: int) -> list[np.ndarray]:
    """Up to `count` accepted rows, best first, no two closer than _DISTINCT."""
    out: list[np.ndarray] = []
    for x, e in zip(rows, energies):
        if e < 1e2 and all(_far(spec, x[:9], y[:9]) for y in out):
            out.append(x)
        if len(out) == count:
            break
    return out


def _far(spec: SynthesisSpec, a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.max(np.abs(a - b) / (spec.upper - spec.lower)) > _DISTINCT)


def _refined(spec: SynthesisSpec, s0: float, x: np.ndarray) -> Linkage | None:
    """The candidate x on assembly s0 refined by least squares (bounds kept), or x itself
    if the refined one has a defect; None if neither is free of them."""
    opt = _scipy_optimize()
    z, theta0 = split(x[None])
    theta = evaluate(spec, s0, x[None]).theta[0]
    timed = spec.timing is not None
    v0 = np.concatenate((z[0], theta0 if timed else theta))
    S = extent(spec.targets)

    def unpack(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return v[:9], (v[9] + spec.timing if timed else v[9:])

    def residual(v: np.ndarray) -> np.ndarray:
        zz, th = unpack(v)
        r = ((pose(zz[None], np.array([s0]), th[None]).P[0] - spec.targets) / S).ravel()
        return np.where(np.isfinite(r), r, 1.0)  # where the dyad does not close: a step refused

    def jacobian(v: np.ndarray) -> np.ndarray:
        zz, th = unpack(v)
        _, dz, dt = point_jacobian(zz, s0, th)
        n = len(th)
        Jt = np.zeros((n, 2, n))
        Jt[np.arange(n), :, np.arange(n)] = dt
        Jt = Jt.sum(axis=2, keepdims=True) if timed else Jt
        return np.concatenate((dz, Jt), axis=2).reshape(2 * n, -1) / S

    lower = np.concatenate((spec.lower, np.full(len(v0) - 9, -np.inf)))
    upper = np.concatenate((spec.upper, np.full(len(v0) - 9, np.inf)))
    candidates = []
    try:
        with np.errstate(all="ignore"):
            fit = opt.least_squares(residual, np.clip(v0, lower, upper), jac=jacobian, bounds=(lower, upper),
                                    method="trf", x_scale="jac", ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=400)
        candidates.append(fit.x)
    except (np.linalg.LinAlgError, ValueError):  # a fold or an open dyad on the way: keep x
        pass
    candidates.append(v0)
    for v in candidates:
        lk = _linkage(spec, *unpack(v), s0)
        if lk is not None:
            return lk
    return None


def _linkage(spec: SynthesisSpec, z: np.ndarray, theta: np.ndarray, s: float) -> Linkage | None:
    """The Linkage z on assembly s with crank angles theta at the targets, or None if its
    motion has a defect or breaks a constraint."""
    Z, Sa, T = z[None], np.array([s]), theta[None]
    if not np.all(np.isfinite(theta)) or causes(spec, Z, Sa, T)[0]:
        return None
    way, span = progress(T, spec.direction)
    low, high = transmission_range(Z, Sa, T, way, span)
    errors = np.linalg.norm(pose(Z, Sa, T).P[0] - spec.targets, axis=1)
    return Linkage(z.copy(), s, np.array(theta), int(way[0]), errors, (float(low[0]), float(high[0])),
                   grashof_label(z))


def _scipy_optimize():
    try:
        import scipy.optimize as opt
    except ImportError as exc:
        raise ImportError(f"synthesis needs SciPy: {_EXTRA} ({exc})") from exc
    return opt
