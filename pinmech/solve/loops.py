"""Close the loops: q, v and a of the dependent joints from the drivers.

Position: Newton on the closure residual from frame placements, with a least-squares
and backtracking safeguard. Velocity: the constraint Jacobian built from frame Jacobians,
J_dep v_dep = -J_drv v_drv. Acceleration: the same Jacobian and the drift term from
classical frame accelerations, J_dep a_dep = -J_drv a_drv - Jdot v. Each is computed by
the compiled core (pinmech/csrc), on the user's own pin.Model; this is its Python face:
assemblies, references, arguments and named errors. Nothing here knows which mechanism
it solves.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Mapping, Sequence

import numpy as np
import pinocchio as pin

from pinmech.arguments import float_array, names
from pinmech.solve.assembly_check import check_guessed_pose
from pinmech.solve.branches import AssemblyStructure
from pinmech.solve.continuation import Path, Route
from pinmech.solve.core import core_for
from pinmech.exceptions import AssemblyError, RateOverflowError, SingularPoseError
from pinmech.model.mechanism import Mechanism
from pinmech.solve.closure_check import (  # noqa: F401  (importers of these names from here)
    ROUNDING_LEVEL,
    describe_joint_values,
    is_closed,
    max_abs,
    not_closed_error,
    open_loops_error,
)
from pinmech.solve.driver_values import check_mobility, index_view, one_coordinate, ordered_values, turn_remainder
from pinmech.solve.results import Accuracy, LoopSolution
from pinmech.solve.solver_options import (  # noqa: F401  (names users and other modules import from here)
    DEFAULT_MAX_CONDITION,
    DEFAULT_TOL,
    MAX_STEP,
    POLISH,
    SOLVER_RANGES,
    Reference,
    SolverOptions,
    checked_option,
    serialized,
)

class LoopSolver(SolverOptions):
    """Solves one mechanism pose after pose, keeping Pinocchio `Data` and buffers alive.

    Assemblies: `set_reference` closes the loops once at given driver values from a
    guess; that pose's assembly signature (branches.py) is the one every later pose must
    have. `solve` without a guess then reaches the asked driver values from the reference
    by continuation (continuation.py), never by a cold Newton solve; with a guess it
    solves from the guess and raises AssemblyError if it lands on another assembly.
    Without `set_reference`, the first pose solved becomes the reference.

    Args:
        mechanism: the model with its loop closures.
        drivers: names of the joints whose motion is given (as many as the mobility).
        tol: closure tolerance, relative to each loop's size (SOLVER_RANGES: 1e-16 to 1e-3).
        max_iterations: Newton iteration cap (1 to 1000).
        max_condition: a constraint Jacobian worse conditioned than this is singular (>= 1).
        kernel: the kinematic passes: "generic" (Pinocchio's algorithms) or "generated"
            (the same algorithms specialised to the model, compiled once and cached;
            needs a compiler and `pinmech[fast]`, else one line says so and "generic" runs).
        certify: which poses of a range get the exact condition number (and the error
            bounds it gives): "every-pose" (default), "every-K" (e.g. "every-10": every K-th pose
            and a range's last), "ends" (a range's last), "none"; every pose gets its
            residuals and its assembly check whatever the level (certify.py). A single `solve`
            certifies its pose at every level.

    After `solve`, `data` holds the joint placements and Jacobians at the solution and
    the placements of the cut frames (call `pin.updateFramePlacements` for the others).

    Threads: the public methods hold `lock` (re-entrant), so threads sharing one solver
    take turns and each gets its own right answer; a thread reading `data` itself holds
    `lock` meanwhile. To solve in parallel, give each thread its own solver.

    Raises:
        FrameNotFound: a driver that is not a joint of the model.
        OptionError: tol, max_iterations or max_condition out of SOLVER_RANGES, or a certify
            level not one of certify.LEVELS (also when set later).
        MobilityError: more or fewer drivers than the mechanism's mobility.
    """

    def __init__(
        self,
        mechanism: Mechanism,
        drivers: Sequence[str],
        *,
        tol: float = DEFAULT_TOL,
        max_iterations: int = 50,
        max_condition: float = DEFAULT_MAX_CONDITION,
        kernel: str = "generic",
        certify: str = "every-pose",
    ) -> None:
        self.mechanism = mechanism
        self.kernel = kernel  # checked when set, also later (SolverOptions)
        self.certify = certify
        self.model = mechanism.model
        self.data = self.model.createData()
        self.drivers = names(drivers, "drivers")
        self.lock = threading.RLock()
        self.tol = tol
        self.max_iterations = max_iterations
        self.max_condition = max_condition
        self._drv_v = np.array([self.mechanism.driver_index(n) for n in self.drivers], dtype=int)
        dependent = np.ones(self.model.nv, dtype=bool)  # not np.setdiff1d: it imports numpy.ma (11 ms)
        dependent[self._drv_v] = False
        self._dep_v = np.flatnonzero(dependent)
        check_mobility(mechanism, self.drivers)
        self._drv, self._dep = index_view(self._drv_v), index_view(self._dep_v)
        self._drv_q = [(mechanism.joint(n).idx_q, mechanism.joint(n).kind == "continuous") for n in self.drivers]
        self._cuts = list(mechanism.closures)  # the loops (their rows: the compiled core's)
        for c in self._cuts:  # what the core's rows are built from stays as it is
            c.__dict__["_in_use"] = True
        self._ground = [c.parent_frame for c in mechanism.closures
                        if self.model.frames[c.parent_frame].parentJoint == 0]
        self._ground_at = [self.model.frames[f].placement.copy() for f in self._ground]
        self._dep_scale = mechanism.velocity_scale()[self._dep_v]  # dimensionless columns
        self._v_scale_inv = 1.0 / mechanism.velocity_scale()
        self.dep_is_scalar = [self._one_coordinate(int(v)) for v in self._dep_v]
        self.structure = AssemblyStructure(self.model, mechanism.closures, self._dep_v, mechanism.plane_normal)
        self.reference: Reference | None = None
        self.iterations = 0  # Newton iterations of the last `correct`
        self.moved = 0.0  # sum of the scaled sizes of its steps: a bound on how far it moved q

    def refresh(self) -> None:
        """Read again the placements of ground cut frames, which the user may have moved in
        the model since the last call (the core reads the model at every call): the
        reference pose, closed for the old placement, is then closed again from itself."""
        now = [self.model.frames[f].placement for f in self._ground]  # by index: frames may be added
        moved = any(a != b for a, b in zip(now, self._ground_at))
        if moved:
            self._ground_at = [m.copy() for m in now]
        ref = self.reference
        if moved and ref is not None:
            q, _, _ = self.close(ref.q, ref.driver_q)
            signs = self._rates(q, np.zeros(len(self.drivers)), np.zeros(len(self.drivers)))[-1]
            self.reference = Reference(ref.driver_q, q, signs, ref.keep)

    def _one_coordinate(self, v: int) -> bool:
        return one_coordinate(self.model, v)

    # ------------------------------------------------------------------ pieces
    def _residual(self, q: np.ndarray) -> np.ndarray:
        """Independent closure rows at q (dimensionless), from the compiled core."""
        compiled = core_for(self)
        return compiled.residual(q) if compiled is not None else np.zeros(0)

    def _full_residual(self) -> float:
        """Largest error over every selected row at the q of the last `_residual`."""
        compiled = core_for(self)
        return compiled.full_residual() if compiled is not None else 0.0

    def _place(self, q: np.ndarray) -> None:
        """self.data at q: joint placements, joint Jacobians and every frame placement."""
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)

    def set_drivers(self, q: np.ndarray, driver_q: Sequence[float]) -> np.ndarray:
        """A copy of q with the drivers' coordinates written in."""
        q = q.copy() if type(q) is np.ndarray and q.dtype == float else np.array(q, dtype=float)
        for (i, continuous), value in zip(self._drv_q, driver_q):
            if continuous:
                q[i], q[i + 1] = math.cos(value), math.sin(value)
            else:
                q[i] = value
        return q

    # ------------------------------------------------------------------ solves
    @serialized
    def close(self, q_guess: np.ndarray, driver_q: Sequence[float]) -> tuple[np.ndarray, int, float]:
        """Newton on the closure residual with the drivers held.

        Returns:
            (q, iterations, residual): the closed configuration, iterations spent, and the
            largest closure error left (dimensionless).

        Raises:
            LoopClosureError: the loops do not close from this guess (out of reach, or a
                residual that stops decreasing).
        """
        q = self.set_drivers(q_guess, driver_q)
        compiled = core_for(self)
        if compiled is None:  # an open chain: the drivers are the pose
            return q, 0, 0.0
        q, ok, residual, iterations = compiled.close(q, np.asarray(driver_q, dtype=float), self._max_iterations, True)
        if not ok:
            self._raise_not_closed(q, residual, iterations, driver_q)
        return q, iterations, residual

    def correct(self, q_guess: np.ndarray, driver_q: np.ndarray, *, max_iterations: int,
                strict: bool = True) -> tuple[np.ndarray, float | None]:
        """Newton from a predicted pose with the drivers held: (q, the closure residual
        left, or None where it did not converge). The solver's data is left at q.

        strict: full Newton steps only, each at least halving the residual (a corrector
        that does not contract is not close to one root); else as `close`, with the
        least-squares and backtracking safeguard."""
        q = self.set_drivers(q_guess, driver_q)
        compiled = core_for(self)
        if compiled is None:
            self.iterations, self.moved = 0, 0.0
            return q, 0.0
        x = np.asarray(driver_q, dtype=float)
        if strict:
            q, residual = compiled.correct(q, x, max_iterations)
        else:
            q, ok, residual, _ = compiled.close(q, x, max_iterations, False)
            residual = residual if ok else None
        self.iterations, self.moved = compiled.iterations, compiled.moved
        return q, residual

    def scaled_norm(self, dv: np.ndarray) -> float:
        """Largest |component| of a velocity-space vector, prismatic parts in mechanism
        sizes (dimensionless)."""
        return max_abs(dv * self._v_scale_inv)

    def describe_drivers(self, values: Sequence[float]) -> str:
        """Driver values as a user reads them: angles in degrees, lengths in metres."""
        return describe_joint_values(self.mechanism, self.drivers, values)

    def _raise_not_closed(self, q: np.ndarray, norm: float, iterations: int, driver_q: Sequence[float]) -> None:
        solved = max_abs(self._residual(q))  # the rows Newton solves
        raise not_closed_error(self.mechanism, q, norm, solved, self.tol, iterations, self.describe_drivers(driver_q))

    @serialized
    def rates(self, q: np.ndarray, driver_v: Sequence[float], driver_a: Sequence[float], *,
              at_q: bool = False, closed: bool = True) -> tuple[np.ndarray, np.ndarray, Accuracy]:
        """Velocities and accelerations at a closed configuration q; the accuracy carries
        q's closure residual (dimensionless, as `Accuracy.residual`).

        Args:
            at_q: q is the solver's own (closed by it): not checked again.
            closed: refuse a q whose loops are open beyond `tol` (False: an interpolated
                pose, whose error the caller states; the residual is still measured).

        Raises:
            LoopClosureError: q's loops are not closed (beyond `tol`, scaled as `close`
                scales it), with how far apart each cut is [m, deg].
            SingularPoseError: the dependent-joint constraint Jacobian is singular.
        """
        if not at_q:  # a user's q: checked (shape, finite, real, unit norms), never cast
            q = self.mechanism.checked_q(q)
        independent, full = max_abs(self._residual(q)), self._full_residual()
        if closed and not is_closed(independent, full, self._tol):
            self._place(q)
            raise open_loops_error(self.mechanism, q, max(independent, full), self._tol,
                                   f"rates at {self.describe_drivers(self._driver_values(q))}")
        v, a, *numbers, _ = self._rates(q, driver_v, driver_a)
        return v, a, Accuracy(max(independent, full), 0, *numbers)

    def _rates(self, q: np.ndarray, driver_v, driver_a, limit: float | None = None) -> tuple:
        """v, a, condition, sigma_min, velocity and acceleration residuals, and the assembly
        signature at a closed q, from the compiled core. A condition number over `limit`
        (default: max_condition) is a SingularPoseError."""
        v = np.zeros(self.model.nv)
        a = np.zeros(self.model.nv)
        compiled = core_for(self)
        if compiled is None:  # an open chain: every joint is a driver
            v[self._drv], a[self._drv] = driver_v, driver_a
            return v, a, 1.0, 1.0, 0.0, 0.0, ()
        v, a, signs, condition, sigma_min, v_res, a_res, _ = compiled.rates_at(
            q, np.asarray(driver_v, dtype=float), np.asarray(driver_a, dtype=float))
        if condition > (self.max_condition if limit is None else limit):
            raise self._singular_error(q, condition, sigma_min)
        if condition <= self.max_condition and not math.isfinite(sum(v.tolist()) + sum(a.tolist())):
            raise self._overflow(q, driver_v, driver_a)  # a regular pose: the driver rates are too large
        return v, a, condition, sigma_min, v_res, a_res, tuple(signs)

    def _singular_error(self, q: np.ndarray, condition: float, sigma_min: float) -> SingularPoseError:
        """The error for a pose whose dependent-joint Jacobian is conditioned worse than
        max_condition: the drivers' values, the condition number and the smallest
        singular value."""
        return SingularPoseError(
            f"{self.mechanism.source}: the loop constraint Jacobian is singular at "
            f"{self.describe_drivers(self._driver_values(q))} "
            f"(condition number {condition:.3g} > {self.max_condition:.3g}, smallest singular "
            f"value {sigma_min:.3g}): the dependent joints' rates are undefined",
            condition=float(condition), sigma_min=float(sigma_min), partial=q)

    def _overflow(self, q: np.ndarray, driver_v, driver_a) -> RateOverflowError:
        return RateOverflowError(
            f"{self.mechanism.source}: at {self.describe_drivers(self._driver_values(q))} the rates overflow "
            f"float64 (driver speeds {', '.join(f'{x:.3g}' for x in np.ravel(driver_v))}, accelerations "
            f"{', '.join(f'{x:.3g}' for x in np.ravel(driver_a))} in rad/s, m/s and their squares): "
            f"nothing finite can be stated; give speeds whose squares stay far below 1e308")

    def _driver_values(self, q: np.ndarray) -> list[float]:
        out = []
        for i, continuous in self._drv_q:
            out.append(math.atan2(q[i + 1], q[i]) if continuous else float(q[i]))
        return out

    @serialized
    def set_reference(self, driver_q: Sequence[float] | Mapping[str, float], guess: np.ndarray | None = None,
                      assembly: Mapping[str, int] | None | str = "keep") -> Reference:
        """Close the loops at `driver_q` from `guess` (default: neutral) and make that pose
        the reference whose assembly later solves keep.

        Args:
            assembly: "keep" (the pose's own assembly), "any" (no check: every later
                solve is a Newton solve from its guess, on whichever assembly it lands),
                or block name -> sign (+1/-1) that the reference must have.

        Raises:
            LoopClosureError: the loops do not close from the guess.
            SingularPoseError: the reference is a singular pose (its assembly has no name).
            AssemblyError: the guess closes on another assembly than `assembly` asks.
        """
        dq = self._ordered(driver_q)
        q, iterations, _ = self.close(self._guess(guess), dq)
        signs = self._rates(q, np.zeros(len(dq)), np.zeros(len(dq)))[-1]
        if isinstance(assembly, Mapping):
            wrong = [n for n, s in zip(self.structure.names, signs) if n in assembly and assembly[n] != s]
            if wrong:
                self._place(q)
                found = self.structure.assembly(signs, self.data)
                raise AssemblyError(
                    f"{self.mechanism.source}: at {self.describe_drivers(dq)} the guess closes on assembly "
                    f"{found.describe()}, not the one asked for loop(s) {', '.join(wrong)}: change [guess] "
                    f"(a guess nearer the assembly asked) or [assembly]",
                    expected=tuple(assembly.get(n, s) for n, s in zip(self.structure.names, signs)),
                    found=signs, drivers=self.drivers, value=tuple(dq.tolist()))
        self.reference = Reference(dq.copy(), q, signs, keep=assembly != "any", iterations=iterations)
        return self.reference

    @serialized
    def solve(
        self,
        driver_q: Sequence[float] | Mapping[str, float],
        driver_v: Sequence[float] | Mapping[str, float] | None = None,
        driver_a: Sequence[float] | Mapping[str, float] | None = None,
        guess: np.ndarray | None = None,
    ) -> LoopSolution:
        """Close the loops and solve the rates for one pose.

        With a reference (`set_reference`) and no guess, the pose is reached from the
        reference by continuation along the straight driver path, on its assembly. With
        a guess (or no reference), Newton starts from the guess; a reference's assembly
        is then checked: the pose must be the one continuation reaches (assembly_check.py),
        which the signature alone cannot tell where a block has more than two assemblies.

        Args:
            driver_q: driver coordinates [rad or m], in the order of `drivers` or by name.
            driver_v: driver velocities [rad/s or m/s] (zero when omitted).
            driver_a: driver accelerations [rad/s^2 or m/s^2] (zero when omitted).
            guess: starting configuration (default: continuation from the reference, or
                the neutral configuration without one).

        Raises:
            LoopClosureError, SingularPoseError: the pose does not close, or is singular.
            AssemblyError: the pose is on another assembly than the reference's.
            DriverLimitError: continuation meets a fold of the drivers before the pose.
        """
        dq, dv, da = (self._ordered(x) for x in (driver_q, driver_v, driver_a))
        ref = self.reference
        if guess is None and ref is not None and ref.keep:
            route = Route(tuple(ref.driver_q.tolist()))
            q = self.follow(ref.q, ref.driver_q, dq, route)
            residual = max(max_abs(self._residual(q)), self._full_residual())
            iterations = route.iterations if route.steps else ref.iterations  # the reference itself: its Newton
            return self._solution(q, dv, da, residual, iterations, route)
        if guess is None and ref is not None:  # assembly "any": Newton from the reference pose
            guess = ref.q
        q, iterations, residual = self.close(self._guess(guess), dq)
        route = None
        if ref is None:  # the first pose solved names the assembly of the later ones
            self.set_reference(dq, q)
        elif ref.keep and self._cuts:  # the pose continuation reaches, or AssemblyError
            passed = check_guessed_pose(self, q, dq)
            route = passed if passed.change_points else None
        return self._solution(q, dv, da, residual, iterations, route)

    @serialized
    def follow(self, q0: np.ndarray, x0: np.ndarray, x1: np.ndarray, route: Route, *,
               through_folds: bool = False) -> np.ndarray:
        """The closed q at driver values x1, followed from the closed pose q0 at x0.

        A single angular driver asked to turn more than once is followed one turn first:
        where that turn brings the mechanism back onto q0 (a closed curve: every later
        turn repeats it exactly), only the rest of the way is followed."""
        x0, x1 = np.asarray(x0, dtype=float), np.asarray(x1, dtype=float)
        if np.array_equal(x0, x1):
            return q0.copy()
        if not self._cuts:  # an open chain: the drivers are the pose
            return self.set_drivers(q0, x1)
        turn = 2.0 * math.pi
        moving = np.flatnonzero(x1 != x0)
        if not through_folds and len(moving) == 1 and abs(x1 - x0)[moving[0]] > turn \
                and self.mechanism.joint(self.drivers[moving[0]]).is_angular:
            k = int(moving[0])
            once = x0.copy()
            once[k] += math.copysign(turn, x1[k] - x0[k])
            q_turn = self.follow(q0, x0, once, route)
            if self.turn_gap(q0, q_turn) <= max(1e3 * self.tol, 1e-10):
                rest = x0.copy()
                rest[k] += turn_remainder(float(x0[k]), float(x1[k]))
                return self.set_drivers(self.follow(q0, x0, rest, route), x1)
            return self.follow(q_turn, once, x1, route)
        path = Path(self, x0, x1 - x0, through_folds=through_folds)
        return path.follow(path.node(0.0, q0), 1.0, route).q

    def turn_gap(self, q0: np.ndarray, q1: np.ndarray) -> float:
        """Largest joint difference between two poses, angles modulo a turn [rad], slides
        in sizes of their loops: 0 where q1 is q0 after whole turns."""
        dv = pin.difference(self.model, q0, q1)
        gap = 0.0
        for joint in self.mechanism.joints.values():
            for i in range(joint.idx_v, joint.idx_v + joint.nv):
                d = float(dv[i])
                d = math.remainder(d, 2 * math.pi) if joint.is_angular else d * float(self._v_scale_inv[i])
                gap = max(gap, abs(d))
        return gap

    def _solution(self, q: np.ndarray, dv: np.ndarray, da: np.ndarray, residual: float, iterations: int,
                  route: Route | None) -> LoopSolution:
        """Rates at a closed q (data at q), the assembly checked against the reference."""
        v, a, *numbers, signs = self._rates(q, dv, da)
        self._place(q)
        ref = self.reference
        if ref is not None and ref.keep and signs != ref.signs and not (route and (route.folds or route.change_points)):
            expected, found = self.structure.assembly(ref.signs), self.structure.assembly(signs, self.data)
            how = ("followed from the reference: the path passes within rounding of the other assembly; set "
                   "assembly = \"any\" to take the pose anyway" if route is not None else
                   "from its guess: solve without a guess to follow the reference, or set assembly = \"any\"")
            raise AssemblyError(
                f"{self.mechanism.source}: at {self.describe_drivers(self._driver_values(q))} the pose is on "
                f"assembly {found.describe()}, not the reference's {expected.describe()} ({how})",
                expected=ref.signs, found=signs, drivers=self.drivers, value=tuple(self._driver_values(q)))
        assembly = self.structure.assembly(signs, self.data) if signs else None
        return LoopSolution(q=q, v=v, a=a, accuracy=Accuracy(residual, iterations, *numbers), drivers=self.drivers,
                            assembly=assembly, route=route)

    def _guess(self, guess: np.ndarray | None) -> np.ndarray:
        if guess is None:
            return self.mechanism.neutral()
        return float_array(guess, "guess", (self.model.nq,), self.mechanism.source)

    def _ordered(self, values: Sequence[float] | Mapping[str, float] | None) -> np.ndarray:
        return ordered_values(values, self.drivers, self.mechanism.mobility)
