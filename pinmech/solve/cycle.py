"""A driver swept through a range: every pose closed and rated, on one assembly branch.

How each pose is found is the user's accuracy choice (docs/explanation/speed.md):

    start="predictor" (default): from the previous exact pose moved along the path,
        q (+) (q' dx + q'' dx^2 / 2) on the configuration manifold, where q' and q''
        are the derivatives of the closed configuration with respect to the swept
        driver (its rates at unit driver speed): a guess O(dx^3) off, one Newton step.
    start="warm": from the previous pose as it is (O(dx) off: more Newton iterations).
    start="cold": every pose from the same guess (the scene's): slowest, and where two
        assembly branches are close it may land on the other one.
    batch: accepted for compatibility; the compiled core follows every pose with the
        predictor (the range mode of the one engine, pinmech/csrc).
    interpolate=n: solve every n-th pose exactly (as above) and interpolate the poses
        between (quintic Hermite); their accuracy is measured at the points of each
        interval where the interpolation error peaks: there the poses are also solved
        exactly, and the difference, times INTERPOLATION_SAFETY, is the error bound that
        interpolation adds to each pose of the interval (`Accuracy.interpolation`).

With the other drivers at rest, velocities and accelerations follow from the path
derivatives exactly: q_dot = q' x_dot and q_ddot = q'' x_dot^2 + q' x_ddot.
Poses come out in chunks (arrays), so a million-pose range runs in bounded memory.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from itertools import islice

import numpy as np

from pinmech.solve.assembly_check import check_guessed_pose
from pinmech.solve.continuation import Node, Path, Route, _Singular
from pinmech.solve.core import core_for
from pinmech.exceptions import (
    AssemblyError,
    DriverLimitError,
    LoopClosureError,
    MobilityError,
    OptionError,
    PinmechError,
    SingularPoseError,
)
from pinmech.solve.results import Accuracy, LoopSolution
from pinmech.solve.batch import BatchSolution, BatchSolver
from pinmech.solve.cycle_interpolation import Interpolation
from pinmech.solve.loops import LoopSolver
from pinmech.solve.range_chunk import (  # noqa: F401  (RangeChunk: imported from here by users)
    _ACCURACY,
    RangeChunk,
    _accuracy_arrays,
    _concat,
    _Fallback,
    _stack,
    _store,
)

STARTS = ("predictor", "warm", "cold")
#: Poses per chunk: what is held in memory at once.
CHUNK = 4096
#: Driver rates (|w|, w^2, |alpha|) below which scaling path derivatives cannot overflow
#: float64: q' and q'' of a pose conditioned under any accepted limit stay far below 1e200.
_SAFE_RATE = 1e100
_FAILURES = (LoopClosureError, SingularPoseError, AssemblyError, DriverLimitError)


_SWEEPS = "the sweep's"  # the assembly a sweep keeps, in messages


def solve_range(solver: LoopSolver, driver: str, values: Iterable[float], *, driver_q: np.ndarray,
                driver_v: np.ndarray, driver_a: np.ndarray, guess: np.ndarray | None = None,
                start: str = "predictor", batch: bool = True, interpolate: int = 1, chunk: int = CHUNK,
                through_folds: bool = False) -> Iterator[RangeChunk]:
    """Solve the mechanism as `driver` takes each of `values`, the other drivers held (lazy).

    The first pose is reached from the solver's reference (`LoopSolver.set_reference`)
    by continuation; without a reference it is solved from `guess` and becomes the
    reference. Each later pose follows from the one before by continuation with step
    control (continuation.py): any spacing gives the same poses.

    Args:
        driver_q, driver_v, driver_a: every driver's coordinate, rate and acceleration
            (SI, in `solver.drivers` order); the swept driver's coordinate is replaced.
        guess: the configuration the first pose starts from when the solver has no
            reference (it picks the assembly).
        start, batch, interpolate: the accuracy choices of the module docstring.
        through_folds: at a fold of the driver, go on onto the other branch, the driver
            turning back (values past the fold are mirrored at it); else the poses past
            it fail with DriverLimitError.

    Raises:
        PinmechError: an unknown start, or interpolation or batches asked with the other
            drivers moving (their path is then not the swept driver's alone).
        OptionError: a chunk size that is not a whole number >= 1, or a value of the
            range that is not finite (raised when the range reaches it).
    """
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise OptionError(f"chunk = {chunk!r} must be a whole number of poses, at least 1", option="chunk", value=chunk)
    cycle = _Cycle(solver, driver, driver_q, driver_v, driver_a, guess, start, batch, interpolate, through_folds)
    try:
        values = iter(values)
    except TypeError:
        raise OptionError(f"values must be an iterable of numbers (rad or m), got {values!r:.60}", option="values",
                          value=values) from None
    index = 0
    while True:
        try:
            xs = np.fromiter(islice(values, chunk), dtype=float)
        except (TypeError, ValueError, OverflowError) as exc:
            raise OptionError(f"the driver values of {driver} must be numbers (rad or m) from position {index} on: "
                              f"{exc}", option="values", value=None) from None
        if not xs.size:
            return
        if not np.all(np.isfinite(xs)):
            bad = int(np.flatnonzero(~np.isfinite(xs))[0])
            raise OptionError(f"the driver value at position {index + bad} of the range is {float(xs[bad])}: "
                              f"every value of {driver} must be a finite number", option="values", value=float(xs[bad]))
        yield cycle.chunk(index, xs)
        index += len(xs)


class _Cycle(Interpolation):
    def __init__(self, solver: LoopSolver, driver: str, driver_q: np.ndarray, driver_v: np.ndarray,
                 driver_a: np.ndarray, guess: np.ndarray | None, start: str, batch: bool, interpolate: int,
                 through_folds: bool = False) -> None:
        if not isinstance(start, str) or start not in STARTS:
            raise PinmechError(f"start must be one of {', '.join(STARTS)}, got {start!r}")
        if isinstance(interpolate, bool) or not isinstance(interpolate, (int, np.integer)) or interpolate < 1:
            raise PinmechError(f"interpolate must be a whole number of poses, at least 1, got {interpolate!r}")
        if not isinstance(driver, str) or driver not in solver.drivers:
            raise MobilityError(f"{driver!r} is not a driver ({', '.join(solver.drivers)})",
                                mobility=solver.mechanism.mobility, drivers=len(solver.drivers))
        self.solver, self.k = solver, solver.drivers.index(driver)
        self.q_drv = solver._ordered(driver_q).copy()
        self.v_drv, self.a_drv = solver._ordered(driver_v).copy(), solver._ordered(driver_a).copy()
        others = np.delete(np.concatenate((self.v_drv, self.a_drv)), [self.k, self.k + len(self.v_drv)])
        self.alone = not np.any(others)  # only the swept driver moves
        if interpolate > 1 and (start != "predictor" or not self.alone):
            raise PinmechError("interpolating a sweep needs the predictor start and the other drivers at "
                               "rest (zero speed and acceleration): their motion is not the swept driver's path")
        self.start, self.interpolate = start, int(interpolate)
        self.measurer = BatchSolver(solver) if interpolate > 1 and solver._cuts else None
        self.guess = None if guess is None else np.asarray(guess, dtype=float)
        self.ref: Node | None = None  # the last pose solved: p is the swept value, d1 and d2 its path derivatives
        self.unit_v = np.zeros_like(self.v_drv)
        self.unit_v[self.k] = 1.0
        self.zero = np.zeros_like(self.v_drv)
        x0 = self.q_drv.copy()
        x0[self.k] = 0.0
        self.path = Path(solver, x0, self.unit_v, through_folds=through_folds)  # p = the swept value
        self.mirror = (1.0, 0.0)  # p = a x + b: past each fold crossed, values are mirrored at it
        self.notes: dict[int, str] = {}
        self._index, self._iterations, self._sweeping = 0, 0, False
        self.span_scale = float(solver.mechanism.velocity_scale()[solver.mechanism.joint(driver).idx_v])  # 1: a turn

    # ------------------------------------------------------------------ chunks
    def chunk(self, index: int, xs: np.ndarray) -> RangeChunk:
        """Solve the poses xs that follow the last solved pose (holding the solver's lock)."""
        with self.solver.lock:
            self.solver.refresh()
            out = self._chunk(index, xs)
        notes = {j - index: n for j, n in self.notes.items() if index <= j < index + len(xs)}
        if notes:
            out = RangeChunk(out.start, out.values, out.solution, out.interpolated, out.errors, notes)
        return out

    def _chunk(self, index: int, xs: np.ndarray) -> RangeChunk:
        ref = self.ref
        if self.start != "predictor" or self.mirror != (1.0, 0.0):  # past a fold: pose by pose
            return self._sequential(index, xs)
        if ref is None:  # the first pose, from the user's guess, then the rest
            fast = self._from_reference(index, xs)
            if fast is not None:
                return fast
            head = self._sequential(index, xs[:1])
            if len(xs) == 1:
                return head
            rest = self._chunk(index + 1, xs[1:]) if self.ref is not None else self._sequential(index + 1, xs[1:])
            return _concat(head, rest)
        try:
            if self.interpolate > 1:
                return self._interpolated(index, xs)
            q, d1, d2, acc = self._exact(xs)
            return self._actual(index, xs, q, d1, d2, acc, np.zeros(len(xs), dtype=bool))
        except _Fallback:  # near trouble: pose by pose, each failure named
            self.ref = ref
            return self._sequential(index, xs)

    def _from_reference(self, index: int, xs: np.ndarray) -> RangeChunk | None:
        """The first pose and the rest followed from the solver's reference in one call of
        the compiled core, where the sweep's driver path passes through the reference (the
        other drivers at its values, the first pose within a turn of it); None otherwise,
        or where the core hands a pose back (`_first` then takes the first pose)."""
        solver, ref, k = self.solver, self.solver.reference, self.k
        compiled = core_for(solver)
        if compiled is None or ref is None or not ref.keep or self.interpolate > 1:
            return None
        if not np.array_equal(np.delete(self.q_drv, k), np.delete(ref.driver_q, k)) \
                or not abs(float(xs[0]) - float(ref.driver_q[k])) <= 2.0 * math.pi:
            return None
        try:
            self.ref = self.path.node(float(ref.driver_q[k]), ref.q)
            q, d1, d2, acc = self._compiled(compiled, xs)
        except (_Fallback, _Singular):
            self.ref = None
            return None
        self.q_drv[k] = self.ref.p
        return self._actual(index, xs, q, d1, d2, acc, np.zeros(len(xs), dtype=bool))

    def _sequential(self, index: int, xs: np.ndarray) -> RangeChunk:
        """Pose after pose through `LoopSolver.solve`; a failing pose is kept as an error."""
        rows, errors, values = [], {}, xs.copy()
        for j, x in enumerate(xs):
            self._index = index + j
            try:
                rows.append(self._solve(x, actual=True))
                values[j] = self.ref.p
            except _FAILURES as exc:
                errors[j] = exc
                rows.append(None)
        return RangeChunk(index, values, _stack(rows, self.solver), np.zeros(len(xs), dtype=bool), errors)

    def _exact(self, xs: np.ndarray):
        """Every pose exact, in path-derivative terms: q, q', q'' and accuracy arrays,
        followed by the compiled core (an open chain's poses one by one: the drivers are
        the pose)."""
        compiled = core_for(self.solver)
        if compiled is not None:
            return self._compiled(compiled, xs)
        n, nq, nv = len(xs), self.solver.model.nq, self.solver.model.nv
        q, d1, d2 = np.empty((n, nq)), np.empty((n, nv)), np.empty((n, nv))
        acc = _accuracy_arrays(n)
        for j, x in enumerate(xs):
            sol = self._solve(x, actual=False, fail=_Fallback)
            q[j], d1[j], d2[j] = sol.q, sol.v, sol.a
            _store(acc, j, sol.accuracy)
        return q, d1, d2, acc

    def _compiled(self, compiled, xs: np.ndarray):
        """Every pose exact, as `_exact`, followed by the compiled core (core.py) from the
        last pose; a pose it hands back (a change point, a fold, a singular or too
        ill-conditioned pose) is taken by `_solve` (the core's whole path follow, which names
        what it met), then the core's sweep goes on."""
        n, solver, path = len(xs), self.solver, self.path
        q, d1, d2 = np.empty((n, solver.model.nq)), np.empty((n, solver.model.nv)), np.empty((n, solver.model.nv))
        acc = _accuracy_arrays(n)
        j = 0
        while j < n:
            ref = self.ref
            done, _, Q, D1, D2, numbers = compiled.follow(
                ref.p, ref.q, ref.d1, ref.d2, list(ref.signs), ref.condition, path.x0, path.d, path.unit, xs[j:],
                solver.max_condition)
            if done:
                q[j:j + done], d1[j:j + done], d2[j:j + done] = Q, D1, D2
                for col, name in enumerate(_ACCURACY):
                    acc[name][j:j + done] = numbers[:, col]
                for i in np.flatnonzero(numbers[:, 6] == 0):  # no step: the start pose, whose
                    for name in _ACCURACY[2:]:  # numbers the core was not given
                        acc[name][j + i] = getattr(ref, name)
                    acc["residual"][j + i] = ref.residual
                last = numbers[-1]
                self.ref = Node(float(xs[j + done - 1]), Q[-1].copy(), D1[-1].copy(), D2[-1].copy(), ref.signs,
                                float(last[2]), float(last[3]), float(last[4]), float(last[5]), float(last[0]))
                j += done
            if j < n:  # `_solve` names what the sweep met (the core's Path.follow)
                self._sweeping = True
                try:
                    sol = self._solve(xs[j], actual=False, fail=_Fallback)
                finally:
                    self._sweeping = False
                q[j], d1[j], d2[j] = sol.q, sol.v, sol.a
                _store(acc, j, sol.accuracy)
                j += 1
        return q, d1, d2, acc

    # ------------------------------------------------------------------ pieces
    def _drivers(self, values: np.ndarray) -> np.ndarray:
        rows = np.tile(self.q_drv, (len(values), 1))
        rows[:, self.k] = values
        return rows

    def _solve(self, x: float, *, actual: bool, fail: type[Exception] | None = None) -> LoopSolution:
        """One pose, from the start the user chose, by the assembly rules; it becomes the
        reference pose. With `actual` the result carries the scene's rates, else the path
        derivatives. A failure raises, as `fail` when given."""
        try:
            node = self._reach(x)
        except _FAILURES:
            if fail is not None:
                raise fail from None
            raise
        solver = self.solver
        accuracy = Accuracy(0.0, 0, node.condition, node.sigma_min, node.velocity_residual,
                            node.acceleration_residual)
        if node.condition > solver.max_condition:  # not a pose to go on from: the reference stays
            try:
                solver._residual(node.q)
                solver._rates(node.q, self.zero, self.zero)  # raises SingularPoseError, named
            except SingularPoseError:
                if fail is not None:
                    raise fail from None
                raise
        self.ref = node  # the next pose goes on from this one (a singular one, e.g. a
        self.q_drv[self.k] = node.p  # parallelogram's change point, has no one tangent)
        residual = node.residual
        accuracy = Accuracy(residual, self._iterations, *(getattr(accuracy, f) for f in _ACCURACY[2:]))
        sol = LoopSolution(node.q, node.d1, node.d2, accuracy, solver.drivers)
        if not actual:
            return sol
        if self.alone:
            return self._scaled(sol)
        v, a, acc = solver.rates(node.q, self.v_drv, self.a_drv)
        return LoopSolution(node.q, v, a, Accuracy(residual, self._iterations, acc.condition, acc.sigma_min,
                                                   acc.velocity_residual, acc.acceleration_residual),
                            solver.drivers)

    def _reach(self, x: float) -> Node:
        """The node at swept value x (mirrored past folds crossed), by the start chosen."""
        solver, path, ref = self.solver, self.path, self.ref
        a, b = self.mirror
        p = a * x + b
        self._iterations = 0
        if ref is None:
            return self._first(p)
        if self.start == "predictor":
            route = Route((ref.p,))
            node = path.follow(ref, p, route)
            self._iterations = route.iterations
            self._note(route)
            return node
        guess = ref.q if self.start == "warm" else self._cold_guess()
        x_ref = path.drivers(ref.p)  # the last pose solved: a failed pose leaves it the reference
        x = path.drivers(p)
        q, self._iterations, _ = solver.close(guess, x)
        try:
            new = path.node(p, q, at_q=True) if solver._cuts else path.node(p, q)
        except _Singular:  # a dead centre: no assembly to name (it escaped as a traceback)
            raise AssemblyError(
                f"{solver.mechanism.source}: a {self.start} start at {solver.describe_drivers(x)} lands on "
                "a singular pose (a dead centre, where no assembly can be told): use the predictor start",
                expected=ref.signs, found=(), drivers=solver.drivers, value=tuple(x.tolist())) from None
        route = Route((ref.p,))
        if solver._cuts and solver.reference is not None and solver.reference.keep:  # as one sign may not tell
            route = check_guessed_pose(solver, q, x, start=(ref.q, x_ref))  # a change point passed: named
        if ref.signs and new.signs != ref.signs and not route.change_points:
            raise AssemblyError(
                f"{solver.mechanism.source}: a {self.start} start at {solver.describe_drivers(x)} "
                f"lands on {solver.structure.change(ref.signs, new.signs, solver.data, whose=_SWEEPS)}: use the "
                "predictor start",
                expected=ref.signs, found=new.signs, drivers=solver.drivers, value=tuple(x.tolist()))
        self._note(route)
        return new

    def _first(self, p: float) -> Node:
        """The first pose: from the solver's reference by continuation, else from the guess
        (which then becomes the reference)."""
        solver = self.solver
        self.q_drv[self.k] = p
        if solver.reference is None:
            solver.set_reference(self.q_drv, self.guess)
        ref = solver.reference
        route = Route(tuple(ref.driver_q.tolist()))
        if ref.keep:
            q = solver.follow(ref.q, ref.driver_q, self.q_drv.copy(), route)
        else:
            q, _, _ = solver.close(self._cold_guess(), self.q_drv)
        self._iterations = route.iterations
        return self.path.node(p, q)

    def _cold_guess(self) -> np.ndarray:
        if self.guess is not None:
            return self.guess
        ref = self.solver.reference
        return ref.q if ref is not None else self.solver.mechanism.neutral()

    def _note(self, route: Route) -> None:
        """Record what a step passed: change points, and folds crossed (values mirrored).
        The core's sweep hands such a step back to the pose-by-pose path, which names
        the pose."""
        if (route.change_points or route.folds) and self._sweeping:
            raise _Fallback
        solver, index = self.solver, self._index
        for x in route.change_points:
            self.notes[index] = f"passed a change point near {solver.describe_drivers(x)} (branch of continuous tangent kept)"
        for x, p in zip(route.folds, route.fold_p):
            a, b = self.mirror
            self.mirror = (-a, 2.0 * p - b)
            self.notes[index] = f"crossed a fold at {solver.describe_drivers(x)}: the driver turns back, the assembly changed"

    def _scaled(self, sol: LoopSolution) -> LoopSolution:
        """Path derivatives -> the scene's rates: v = q' x_dot, a = q'' x_dot^2 + q' x_ddot."""
        w, alpha = float(self.v_drv[self.k]), float(self.a_drv[self.k])
        acc = sol.accuracy
        accuracy = Accuracy(acc.residual, acc.iterations, acc.condition, acc.sigma_min,
                            abs(w) * acc.velocity_residual,
                            w * w * acc.acceleration_residual + abs(alpha) * acc.velocity_residual)
        if max(abs(w), w * w, abs(alpha)) < _SAFE_RATE:  # path derivatives of a regular pose: no overflow
            v, a = sol.v * w, sol.a * (w * w) + sol.v * alpha
        else:
            with np.errstate(over="ignore", invalid="ignore"):
                v, a = sol.v * w, sol.a * (w * w) + sol.v * alpha
        if not math.isfinite(sum(v.tolist()) + sum(a.tolist())):
            raise self.solver._overflow(sol.q, self.v_drv, self.a_drv)
        return LoopSolution(sol.q, v, a, accuracy, sol.drivers)

    def _actual(self, index: int, xs: np.ndarray, q: np.ndarray, d1: np.ndarray, d2: np.ndarray,
                acc: dict[str, np.ndarray], interpolated: np.ndarray) -> RangeChunk:
        """A chunk in the scene's rates, from path derivatives (as `_scaled`); with other
        drivers moving too, the rates of every driver's motion at each pose (the path
        derivatives are the swept driver's share alone)."""
        if not self.alone:
            return self._rated(index, xs, q, acc, interpolated)
        w, alpha = float(self.v_drv[self.k]), float(self.a_drv[self.k])
        with np.errstate(over="ignore", invalid="ignore"):
            v, a = d1 * w, d2 * (w * w) + d1 * alpha
        if not (np.isfinite(v).all() and np.isfinite(a).all()):
            raise self.solver._overflow(q[0], self.v_drv, self.a_drv)
        solution = BatchSolution(
            q, v, a, acc["residual"], acc["iterations"], acc["condition"],
            acc["sigma_min"], abs(w) * acc["velocity_residual"],
            w * w * acc["acceleration_residual"] + abs(alpha) * acc["velocity_residual"], self.solver.drivers,
            interpolation=acc["interpolation"] if interpolated.any() else None)
        return RangeChunk(index, xs, solution, interpolated)

    def _rated(self, index: int, xs: np.ndarray, q: np.ndarray, acc: dict[str, np.ndarray],
               interpolated: np.ndarray) -> RangeChunk:
        """A chunk whose rates are solved at each pose with every driver's speed and
        acceleration (as `_solve` does for the first pose)."""
        solver, n = self.solver, len(xs)
        v, a = np.empty((n, solver.model.nv)), np.empty((n, solver.model.nv))
        numbers = {name: acc[name].copy() for name in _ACCURACY}
        for j in range(n):
            v[j], a[j], rated = solver.rates(q[j], self.v_drv, self.a_drv, closed=not interpolated[j])
            for name in _ACCURACY[2:]:
                numbers[name][j] = getattr(rated, name)
        solution = BatchSolution(q, v, a, *(numbers[name] for name in _ACCURACY), solver.drivers,
                                 interpolation=acc["interpolation"] if interpolated.any() else None)
        return RangeChunk(index, xs, solution, interpolated)
