"""Continuation: from a solved pose to another driver value without leaving its assembly.

The drivers move along a straight path in driver space, x(p) = x0 + p d (d a direction,
p the path parameter). Each step from a solved pose (p, q) to p + h:

1. predicts q(p + h) = q (+) (q' h + q'' h^2 / 2) on the configuration manifold, where q'
   and q'' are the pose's rates at driver velocity d and zero driver acceleration;
2. corrects by Newton with the drivers held, full steps only, each one at least halving
   the residual (a corrector that does not contract is not near one root);
3. accepts the step when the correction stays in a trust region (at most TRUST of the
   predicted move, plus a rounding floor), the assembly signature (branches.py) is the
   same, and the extended tangent (q', 1) has turned less than MAX_TURN.

A step that fails is halved and tried again. Where the steps shrink below PIVOT_BELOW,
the path is followed with a dependent joint as its parameter instead (the driver joins
the unknowns), which stays regular through a fold of the driver: there the driver's
rate along the curve changes sign, which is how a limit (a non-Grashof crank's limit
angle, a rocker's extreme, a piston's stroke) is found and located to rounding.

Where the signature changes on a small step whose tangent is continuous, the path
crossed a bifurcation (a parallelogram's change point): the step is kept, on the branch
of continuous tangent, and recorded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from pinmech.solve.core import core_for
from pinmech.exceptions import AssemblyError, DriverLimitError, PinmechError, SingularPoseError

#: Largest step, in radians or mechanism sizes of driver motion.
MAX_STEP = 0.25
#: The corrector may move at most this fraction of the predicted move (plus a floor),
#: and at most 2|h| of it on a step h (`Path._trust`).
TRUST = 0.25
#: Largest turn of the extended tangent over one step [rad] (30 deg).
MAX_TURN = math.radians(30.0)
#: Steps below this (radians or sizes of driver motion) switch to a joint parameter.
PIVOT_BELOW = 1e-4
#: A signature change on a step this small, tangent continuous, is a bifurcation.
BIFURCATION_STEP = 1e-3
#: Newton iterations allowed to a corrector.
CORRECTOR_ITERATIONS = 8
#: A fold is located to this, in its pivot joint's coordinate (the driver is then right
#: to about its square: the driver is quadratic in the pivot at a fold).
FOLD_TOL = 1e-12
#: A pose conditioned worse than this is no place to stand on: its tangent is noise (it
#: sits on a crossing or a fold to within 1e-10), so a step does not end there.
SINGULAR_NODE = 1e10
#: Landing on a target from the pivot-parametrized curve: bisection along it until the
#: bracket is this small in driver motion (radians or sizes).
LAND_TOL = 1e-12
#: Pivot-parameter steps taken at most before giving up.
MAX_PIVOT_STEPS = 20000


@dataclass
class Node:
    """A solved pose on a driver path: the path parameter, q, the path derivatives
    q' = dq/dp and q'' (rates at driver velocity d, zero driver acceleration), the
    assembly signature and the condition number of the dependent Jacobian."""

    p: float
    q: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    signs: tuple[int, ...]
    condition: float
    sigma_min: float = 1.0
    velocity_residual: float = 0.0
    acceleration_residual: float = 0.0
    residual: float = 0.0  # closure residual left at q (dimensionless)
    tangent: tuple[np.ndarray, float] | None = None  # (q' scaled, |(q', unit)|): see Path._turn


@dataclass
class Route:
    """How a pose was reached: from which driver values, in how many steps, and what
    was passed on the way (driver values where the signature changed at a bifurcation,
    and folds crossed with `through_folds`)."""

    start: tuple[float, ...]
    steps: int = 0
    iterations: int = 0  # Newton iterations of the correctors of the steps taken
    change_points: list[tuple[float, ...]] = field(default_factory=list)
    folds: list[tuple[float, ...]] = field(default_factory=list)
    fold_p: list[float] = field(default_factory=list)


class Path:
    """A straight driver path x(p) = x0 + p d of one `LoopSolver`, followed step by step.

    Args:
        solver: the LoopSolver (it owns the model, data and closure rows).
        x0: driver values at p = 0 [rad or m].
        direction: d, driver motion per unit of p [rad or m].
        through_folds: at a fold, go on onto the other branch (the driver turns back)
            instead of raising DriverLimitError.
    """

    def __init__(self, solver, x0: np.ndarray, direction: np.ndarray, *, through_folds: bool = False) -> None:
        self.solver = solver
        self.x0 = np.asarray(x0, dtype=float)
        self.d = np.asarray(direction, dtype=float)
        self.zero = np.zeros_like(self.d)
        drv_scale = solver.mechanism.velocity_scale()[solver._drv_v]
        self.unit = float(np.max(np.abs(self.d / drv_scale), initial=0.0)) or 1.0  # p -> rad or sizes
        self.through_folds = through_folds

    def drivers(self, p: float) -> np.ndarray:
        return self.x0 + p * self.d

    # ------------------------------------------------------------------ nodes
    def node(self, p: float, q: np.ndarray, *, at_q: bool = False, residual: float | None = None) -> Node:
        """The path derivatives and signature at a closed q (numerically regular). With
        `at_q` the solver's data already holds q's placements and Jacobians, and
        `residual` is the closure residual measured there."""
        solver = self.solver
        compiled = core_for(solver)
        if compiled is not None:  # the same numbers from the compiled core (tests/test_core.py)
            d1, d2, signs, condition, sigma_min, v_res, a_res, res = compiled.node(q, self.d)
            if math.isfinite(sum(d1.tolist()) + sum(d2.tolist())):  # else the Python path names the overflow
                signs = tuple(signs)
                if not condition <= SINGULAR_NODE or 0 in signs:
                    raise self._singular(q, condition, sigma_min)
                return Node(p, q, d1, d2, signs, condition, sigma_min, v_res, a_res,
                            res if not at_q or residual is None else residual)
        if not at_q or residual is None:
            residual = max(max(map(abs, solver._residual(q).tolist()), default=0.0), solver._full_residual())
        d1, d2, condition, sigma_min, v_res, a_res, signs = solver._rates(q, self.d, self.zero, limit=math.inf)
        if not condition <= SINGULAR_NODE or 0 in signs:
            raise self._singular(q, condition, sigma_min)
        return Node(p, q, d1, d2, signs, condition, sigma_min, v_res, a_res, residual)

    def _singular(self, q: np.ndarray, condition: float, sigma_min: float) -> _Singular:
        solver = self.solver
        return _Singular(
            f"{solver.mechanism.source}: at {solver.describe_drivers(solver._driver_values(q))} the pose is too near "
            f"a singular one to follow a path from (condition number {condition:.3g} > {SINGULAR_NODE:g}: its "
            f"tangent is rounding noise, whatever max_condition allows); start from a pose farther from it",
            condition=float(condition), sigma_min=float(sigma_min), partial=q)

    # ------------------------------------------------------------------ following
    def follow(self, node: Node, p_target: float, route: Route) -> Node:
        """From `node` to p_target (to its mirror image past a fold with through_folds).

        Raises:
            DriverLimitError: a fold of the driver lies before p_target (its value located).
            AssemblyError: no step keeps the assembly (the message says where).
            LoopClosureError: no pose at all beyond some point.
        """
        h = self._first_step(node, p_target)
        while node.p != p_target:
            remaining = p_target - node.p
            h = math.copysign(min(abs(h), abs(remaining)), remaining)
            new, why = self.step(node, node.p + h if abs(h) < abs(remaining) else p_target)
            if new is not None:
                if new.signs != node.signs:
                    route.change_points.append(tuple(self.drivers(0.5 * (node.p + new.p))))
                node = new
                route.steps += 1
                route.iterations += self.solver.iterations
                h *= 2.0
                continue
            if abs(h) * self.unit > PIVOT_BELOW:
                h *= 0.5
                continue
            node, p_target = self._pivot_follow(node, p_target, route, why)
            h = p_target - node.p
        return node

    def _first_step(self, node: Node, p_target: float) -> float:
        return math.copysign(min(abs(p_target - node.p), MAX_STEP / self.unit), p_target - node.p)

    def step(self, node: Node, p: float) -> tuple[Node | None, str]:
        """One predictor-corrector step to p: the new node, or None and why it failed."""
        solver, h = self.solver, p - node.p
        move = node.d1 * h + node.d2 * (0.5 * h * h)
        q_pred = pin.integrate(solver.model, node.q, move)
        q, residual = solver.correct(q_pred, self.drivers(p), max_iterations=CORRECTOR_ITERATIONS)
        if residual is None:
            return None, "the corrector did not converge"
        # the corrector's steps bound its displacement from the prediction (triangle inequality)
        if solver.moved > self._trust(h) * solver.scaled_norm(move) + 1e3 * solver.tol:
            return None, "the corrector left the trust region (another root nearer than the path's)"
        try:
            new = self.node(p, q, at_q=True, residual=residual)
        except _Singular:
            return None, "a singular pose"
        turn = self._turn(node, new)
        if turn > MAX_TURN:
            return None, "the path turned too sharply"
        if new.signs != node.signs:
            small = abs(h) * self.unit <= BIFURCATION_STEP
            if not (small and turn < 0.1 * MAX_TURN):
                return None, f"the assembly changed ({self._words(node.signs)} -> {self._words(new.signs)})"
        return new, ""

    def _trust(self, h: float) -> float:
        """The share of the predicted move the corrector may add on a step h. On one
        smooth branch the second-order predictor is off by O(h^3), a share O(h^2) of the
        move; a root on another branch through a nearby crossing is off by a share that
        does not shrink with h. A limit of 2|h| (in radians or sizes), at most TRUST,
        keeps the first and, once the step is small enough, refuses the second."""
        return min(TRUST, 2.0 * abs(h) * self.unit)

    def _turn(self, a: Node, b: Node) -> float:
        """Angle between the extended tangents (q', 1) of two nodes, q' in radians or sizes
        per unit of p and the 1 as `unit` (radians or sizes of driver motion)."""
        (ta, na), (tb, nb) = self._tangent(a), self._tangent(b)
        cos = (float(ta @ tb) + self.unit * self.unit) / (na * nb)
        return math.acos(max(-1.0, min(1.0, cos)))

    def _tangent(self, node: Node) -> tuple[np.ndarray, float]:
        if node.tangent is None:
            t = node.d1 * self.solver._v_scale_inv
            node.tangent = (t, math.sqrt(float(t @ t) + self.unit * self.unit))
        return node.tangent

    # ------------------------------------------------------------------ pivot
    def _pivot_follow(self, node: Node, p_target: float, route: Route, why: str) -> tuple[Node, float]:
        """Follow the curve with a dependent joint as parameter, to p_target or a fold.

        Returns the node reached and the (possibly mirrored) target."""
        curve = _Curve(self, node)
        sense = 1.0 if p_target > node.p else -1.0
        state = curve.start(sense)
        folded = False
        for _ in range(MAX_PIVOT_STEPS):
            nxt = curve.advance(state)
            if nxt is None:
                raise self._stuck(node, why)
            if nxt.dp * state.dp <= 0:  # the driver turned back: a fold in between
                fold = curve.locate_fold(state, nxt)
                if (fold.p - p_target) * sense >= 0:  # the target comes before the fold
                    return self._kept(node, self._land(curve, state, fold, p_target), folded), p_target
                x_fold = self.drivers(fold.p)
                if not self.through_folds:
                    raise DriverLimitError(
                        f"{self.solver.mechanism.source}: the drivers cannot go past "
                        f"{self.solver.describe_drivers(x_fold)} (a fold: the loops do not close "
                        f"beyond it on this assembly, {self._words(node.signs)}); asked for "
                        f"{self.solver.describe_drivers(self.drivers(p_target))}",
                        limit=tuple(x_fold.tolist()), drivers=self.solver.drivers)
                route.folds.append(tuple(x_fold.tolist()))
                route.fold_p.append(fold.p)
                p_target = 2.0 * fold.p - p_target
                sense = -sense
                folded = True
            elif (nxt.p - p_target) * sense >= 0:  # passed the target: close there
                return self._kept(node, self._land(curve, state, nxt, p_target), folded), p_target
            state = curve.repivot(nxt)
        raise self._stuck(node, why)

    def _kept(self, start: Node, landed: Node, folded: bool) -> Node:
        """`landed`, where the pivot-parametrized curve kept `start`'s assembly: with no
        fold crossed (through_folds turns onto the mirrored branch there), the signature
        must be start's. The curve can cross from one branch to another where the two
        come within rounding of each other (a linkage a nanometre from a parallelogram):
        that is a named error, never the other branch's answer."""
        if folded or landed.signs == start.signs:
            return landed
        raise self._stuck(start, f"the path comes within rounding of another assembly here and would land on it "
                                 f"({self._words(start.signs)} -> {self._words(landed.signs)}): the two cannot be told apart")

    def _land(self, curve: _Curve, a: _CurvePoint, b: _CurvePoint, p_target: float) -> Node:
        """The pose at p_target between two curve points that bracket it (p monotonic
        between them): bisection along the curve until the driver is within LAND_TOL
        of the target, then Newton with the drivers held, from a pose that close to
        one root only (near a fold the other root is only sqrt(distance) away)."""
        for _ in range(60):
            if abs(b.p - a.p) * self.unit <= LAND_TOL:
                break
            mid = curve.point_at(a, 0.5 * (a.s + b.s))
            if mid is None:
                break
            if (mid.p - p_target) * (a.p - p_target) > 0:
                a = mid
            else:
                b = mid
        w = (p_target - a.p) / (b.p - a.p) if b.p != a.p else 0.0
        model = self.solver.model
        guess = pin.integrate(model, a.q, w * pin.difference(model, a.q, b.q))
        q, residual = self.solver.correct(guess, self.drivers(p_target), max_iterations=50, strict=False)
        if residual is None:
            raise self._stuck(self._plain(a), "the pose at the target did not close")
        try:
            node = self.node(p_target, q, at_q=True, residual=residual)
        except _Singular:
            self.solver._residual(q)
            self.solver._rates(q, self.d, self.zero)  # raises SingularPoseError, naming the pose
            raise
        before = self._plain(a)
        if node.signs != before.signs:
            raise self._stuck(before, "the pose at the target is on another assembly")
        return node

    def _plain(self, point: _CurvePoint) -> Node:
        """A curve point as a node (its signature unknown where it is singular)."""
        try:
            return self.node(point.p, point.q)
        except _Singular:
            return Node(point.p, point.q, np.zeros(self.solver.model.nv), np.zeros(self.solver.model.nv), (), math.inf)

    def _words(self, signs: tuple[int, ...]) -> str:
        """An assembly as reports print it, loop by loop ("B: +"), not a bare sign tuple."""
        return self.solver.structure.assembly(signs).describe()

    def _stuck(self, node: Node, why: str) -> PinmechError:
        x = self.solver.describe_drivers(self.drivers(node.p))
        return AssemblyError(
            f"{self.solver.mechanism.source}: cannot go on from {x} without leaving the assembly "
            f"{self.solver.structure.assembly(node.signs).describe()}: {why}", expected=node.signs, found=(),
            drivers=self.solver.drivers,
            value=tuple(self.drivers(node.p).tolist()))


class _Singular(SingularPoseError):
    """The dependent Jacobian is numerically singular at a node (condition number over
    SINGULAR_NODE): no path goes on from there. Caught inside, where another step is tried;
    where it leaves pinmech it is the SingularPoseError it derives from, named."""


@dataclass
class _CurvePoint:
    """A point of the solution curve in (q, p): its unit tangent (dq in velocity space,
    then dp), oriented along the travel, the pivot joint (a velocity index) it was found
    with, and s, the pivot's displacement since the last change of pivot."""

    p: float
    q: np.ndarray
    s: float
    tangent: np.ndarray
    pivot: int

    @property
    def dp(self) -> float:
        """The path parameter's share of the tangent: it changes sign at a fold."""
        return float(self.tangent[-1])


class _Curve:
    """The solution curve near a node, followed with one dependent joint's coordinate as
    its parameter (the one moving fastest): regular through folds of the driver."""

    def __init__(self, path: Path, node: Node) -> None:
        self.path, self.solver, self.node = path, path.solver, node
        solver = self.solver
        self.scalar = [int(v) for v, ok in zip(solver._dep_v, solver.dep_is_scalar) if ok]
        if not self.scalar:
            raise path._stuck(node, "no one-coordinate joint to follow the path by")
        self.d_hat = path.d / path.unit  # drivers' motion per radian or size along the path
        self._ds = 1e-3

    def _cos(self, a: np.ndarray, b: np.ndarray) -> float:
        """Cosine of the angle between two tangents, each made dimensionless (joint rates
        over their velocity scales, the last entry in radians or sizes already): the
        angle a mechanism scaled in size keeps. (As stored, a prismatic joint's entry is
        in metres: the raw dot product of two tangents was 0.73 for equal ones at a 0.1 m
        size, and any turn passed at 100 m.)"""
        scale = np.append(self.solver._v_scale_inv, 1.0)
        ua, ub = a * scale, b * scale
        return float(ua @ ub) / float(np.linalg.norm(ua) * np.linalg.norm(ub))

    def _pivot(self, tangent: np.ndarray) -> int:
        scaled = np.abs(tangent[:-1] * self.solver._v_scale_inv)
        return max(self.scalar, key=lambda v: scaled[v])

    def _tangent(self, q: np.ndarray) -> np.ndarray:
        """Unit tangent of the curve at a closed q, unoriented: dq in velocity space and,
        last, the drivers' motion along the path in radians or mechanism sizes (p times
        the path's unit), so that every component is of one scale."""
        solver, d_hat = self.solver, self.d_hat
        solver._residual(q)
        J = solver._jacobian()
        A = np.hstack([J[:, solver._dep_v] * solver._dep_scale, (J[:, solver._drv_v] @ d_hat)[:, None]])
        t = np.linalg.svd(A)[2][-1]
        out = np.zeros(solver.model.nv + 1)
        out[solver._dep_v] = t[:-1] * solver._dep_scale
        out[solver._drv_v] = t[-1] * d_hat
        out[-1] = t[-1]
        return out

    def start(self, sense: float) -> _CurvePoint:
        """The node as a curve point, its tangent oriented as the path's travel (or as
        the node's q' where the driver is at a fold already)."""
        n = self.node
        t = self._tangent(n.q)
        along = np.append(n.d1 / self.path.unit, 1.0) * sense
        if self._cos(t, along) < 0:
            t = -t
        return _CurvePoint(n.p, n.q, 0.0, t, self._pivot(t))

    def _close_at(self, q_guess: np.ndarray, p_guess: float, pivot: int) -> tuple[np.ndarray, float] | None:
        """Newton on (the other dependent joints, p) with the pivot held where the guess
        has it; each iteration must halve the residual."""
        solver, path = self.solver, self.path
        others = [int(v) for v in solver._dep_v if v != pivot]
        p = p_guess
        q = solver.set_drivers(q_guess, path.drivers(p))
        r = solver._residual(q)
        norm = float(np.max(np.abs(r), initial=0.0))
        for _ in range(CORRECTOR_ITERATIONS + 4):
            if norm <= solver.tol:
                return q, p
            Jn = solver._residual_jacobian()
            A = np.hstack([Jn[:, others], (Jn[:, solver._drv_v] @ self.d_hat)[:, None]])
            try:
                step = np.linalg.solve(A, -r)
            except np.linalg.LinAlgError:
                return None
            dv = np.zeros(solver.model.nv)
            dv[others] = step[:-1]
            p = p + float(step[-1]) / path.unit
            q = solver.set_drivers(pin.integrate(solver.model, q, dv), path.drivers(p))
            r_new = solver._residual(q)
            new_norm = float(np.max(np.abs(r_new), initial=0.0))
            if new_norm > 0.5 * norm and new_norm > solver.tol:
                return None
            r, norm = r_new, new_norm
        return (q, p) if norm <= solver.tol else None

    def advance(self, a: _CurvePoint) -> _CurvePoint | None:
        """The next curve point, with an adaptive pivot step (None where none is found)."""
        ds = self._ds
        while ds >= 1e-14:
            b = self.point_at(a, a.s + math.copysign(ds, a.tangent[a.pivot]))
            if b is not None:
                self._ds = min(ds * 1.5, 0.05)
                return b
            ds *= 0.5
        return None

    def point_at(self, a: _CurvePoint, s: float) -> _CurvePoint | None:
        """The curve point with a's pivot at s (a's pivot moved by s - a.s), or None."""
        solver, model = self.solver, self.solver.model
        scale = (s - a.s) / a.tangent[a.pivot]
        move = a.tangent[:-1] * scale
        guess = pin.integrate(model, a.q, move)
        out = self._close_at(guess, a.p + a.tangent[-1] * scale / self.path.unit, a.pivot)
        if out is None:
            return None
        q, p = out
        if solver.scaled_norm(pin.difference(model, guess, q)) > TRUST * solver.scaled_norm(move) + 1e3 * solver.tol:
            return None
        t = self._tangent(q)
        cos = self._cos(t, a.tangent)
        if cos < 0:
            t, cos = -t, -cos
        if cos < math.cos(MAX_TURN):
            return None
        return _CurvePoint(p, q, s, t, a.pivot)

    def repivot(self, a: _CurvePoint) -> _CurvePoint:
        """a with the fastest-moving joint as its pivot (s restarts at 0) when that is
        no longer the current one by a clear margin."""
        best = self._pivot(a.tangent)
        scaled = np.abs(a.tangent[:-1] * self.solver._v_scale_inv)
        if best != a.pivot and scaled[a.pivot] < 0.5 * scaled[best]:
            return _CurvePoint(a.p, a.q, 0.0, a.tangent, best)
        return a

    def locate_fold(self, a: _CurvePoint, b: _CurvePoint) -> _CurvePoint:
        """The curve point between a and b (same pivot) where dp changes sign, by
        bisection in the pivot's coordinate to FOLD_TOL."""
        while abs(b.s - a.s) > FOLD_TOL:
            mid = self.point_at(a, 0.5 * (a.s + b.s))
            if mid is None:
                break
            if mid.dp * a.dp > 0:
                a = mid
            else:
                b = mid
        return a if abs(a.dp) < abs(b.dp) else b
