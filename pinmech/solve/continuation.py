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

from pinmech.solve.core import _core, core_for
from pinmech.exceptions import AssemblyError, DriverLimitError, PinmechError, SingularPoseError

# The rules' constants, as the compiled core holds them (pinmech/csrc/core.hpp): the core
# follows every path; these names are what users and tests read.
#: Largest step, in radians or mechanism sizes of driver motion.
MAX_STEP = _core.MAX_STEP
#: The corrector may move at most this fraction of the predicted move (plus a floor of
#: 1e3 tol), and at most 2|h| of it on a step h: on one smooth branch the second-order
#: predictor is off by a share O(h^2) of the move; a root on another branch through a
#: nearby crossing by a share that does not shrink with h.
TRUST = _core.TRUST
#: Largest turn of the extended tangent (q', 1) over one step [rad] (30 deg).
MAX_TURN = _core.MAX_TURN
#: Steps below this (radians or sizes of driver motion) switch to a joint parameter.
PIVOT_BELOW = _core.PIVOT_BELOW
#: A signature change on a step this small, tangent continuous, is a bifurcation.
BIFURCATION_STEP = _core.BIFURCATION_STEP
#: Newton iterations allowed to a corrector.
CORRECTOR_ITERATIONS = _core.CORRECTOR_ITERATIONS
#: A fold is located to this, in its pivot joint's coordinate (the driver is then right
#: to about its square: the driver is quadratic in the pivot at a fold).
FOLD_TOL = _core.FOLD_TOL
#: A pose conditioned worse than this is no place to stand on: its tangent is noise (it
#: sits on a crossing or a fold to within 1e-10), so a step does not end there.
SINGULAR_NODE = _core.SINGULAR_NODE
#: Landing on a target from the pivot-parametrized curve: bisection along it until the
#: bracket is this small in driver motion (radians or sizes).
LAND_TOL = _core.LAND_TOL
#: Pivot-parameter steps taken at most before giving up.
MAX_PIVOT_STEPS = _core.MAX_PIVOT_STEPS
# The core's path statuses (pivot.cpp: PathStatus) and reasons for being stuck (StuckWhy).
_DONE, _STUCK, _FOLD, _SINGULAR_AT = 0, 1, 2, 3
_WHY = {1: "the corrector did not converge",
        2: "the corrector left the trust region (another root nearer than the path's)",
        3: "a singular pose",
        4: "the path turned too sharply",
        6: "no one-coordinate joint to follow the path by",
        8: "the pose at the target did not close",
        9: "the pose at the target is on another assembly"}


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
        """The path derivatives and signature at a closed q (numerically regular), from
        the compiled core. With `at_q`, `residual` is the closure residual measured at q
        (by the corrector that closed it)."""
        solver = self.solver
        compiled = core_for(solver)
        if compiled is None:  # an open chain: the drivers are the pose
            d1, d2, condition, sigma_min, v_res, a_res, signs = solver._rates(q, self.d, self.zero)
            return Node(p, q, d1, d2, signs, condition, sigma_min, v_res, a_res, 0.0)
        d1, d2, signs, condition, sigma_min, v_res, a_res, res = compiled.node(q, self.d)
        signs = tuple(signs)
        if not condition <= SINGULAR_NODE or 0 in signs:
            raise self._singular(q, condition, sigma_min)
        if not math.isfinite(sum(d1.tolist()) + sum(d2.tolist())):  # a regular pose: rates too large
            raise solver._overflow(q, self.d, self.zero)
        return Node(p, q, d1, d2, signs, condition, sigma_min, v_res, a_res,
                    res if not at_q or residual is None else residual)

    def _singular(self, q: np.ndarray, condition: float, sigma_min: float) -> _Singular:
        solver = self.solver
        return _Singular(
            f"{solver.mechanism.source}: at {solver.describe_drivers(solver._driver_values(q))} the pose is too near "
            f"a singular one to follow a path from (condition number {condition:.3g} > {SINGULAR_NODE:g}: its "
            f"tangent is rounding noise, whatever max_condition allows); start from a pose farther from it",
            condition=float(condition), sigma_min=float(sigma_min), partial=q)

    # ------------------------------------------------------------------ following
    def follow(self, node: Node, p_target: float, route: Route) -> Node:
        """From `node` to p_target (to its mirror image past a fold with through_folds),
        in the compiled core (pinmech/csrc/pivot.cpp): predictor-corrector steps, halved
        after a failure, doubled after a success; a change point kept on the branch of
        continuous tangent; below PIVOT_BELOW the curve with a dependent joint as its
        parameter, through folds.

        Raises:
            DriverLimitError: a fold of the driver lies before p_target (its value located).
            AssemblyError: no step keeps the assembly (the message says where).
            SingularPoseError: the pose at the target is singular.
        """
        solver = self.solver
        if node.p == p_target:
            return node
        compiled = core_for(solver)
        if compiled is None:  # an open chain: the drivers are the pose
            return self.node(p_target, solver.set_drivers(node.q, self.drivers(p_target)))
        scalar = [int(v) for v, ok in zip(solver._dep_v, solver.dep_is_scalar) if ok]
        out, p, q, d1, d2, signs, condition, sigma_min, v_res, a_res, residual = compiled.follow_path(
            node.p, node.q, node.d1, node.d2, list(node.signs), node.condition, self.x0, self.d, self.unit,
            float(p_target), self.through_folds, scalar)
        route.steps += out["steps"]
        route.iterations += out["iterations"]
        route.change_points.extend(tuple(self.drivers(c).tolist()) for c in out["change_points"])
        route.folds.extend(tuple(self.drivers(f).tolist()) for f in out["folds"])
        route.fold_p.extend(out["folds"])
        reached = Node(p, q, d1, d2, tuple(signs), condition, sigma_min, v_res, a_res, residual)
        status = out["status"]
        if status == _DONE:
            return reached
        if status == _FOLD:
            x_fold = self.drivers(out["fold"])
            raise DriverLimitError(
                f"{solver.mechanism.source}: the drivers cannot go past {solver.describe_drivers(x_fold)} (a fold: "
                f"the loops do not close beyond it on this assembly, {self._words(node.signs)}); asked for "
                f"{solver.describe_drivers(self.drivers(out['p_target']))}",
                limit=tuple(x_fold.tolist()), drivers=solver.drivers)
        if status == _SINGULAR_AT:
            if condition > solver.max_condition:
                raise solver._singular_error(q, condition, sigma_min)
            raise self._singular(q, condition, sigma_min)
        raise self._stuck(reached, self._why(out))

    def _why(self, out: dict) -> str:
        """The words for the core's reason a path is stuck."""
        why = out["why"]
        if why == 5:
            return f"the assembly changed ({self._words(tuple(out['signs_a']))} -> {self._words(tuple(out['signs_b']))})"
        if why == 7:
            return (f"the path comes within rounding of another assembly here and would land on it "
                    f"({self._words(tuple(out['signs_a']))} -> {self._words(tuple(out['signs_b']))}): the two cannot "
                    "be told apart")
        return _WHY.get(why, "no step keeps it")

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
