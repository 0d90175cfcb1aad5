"""Forces on closed loops: driver torques (or forces), cut forces and joint reactions.

At a solved pose (q, q_dot, q_ddot) the tree's equations of motion, with the loop cuts'
constraint forces and the external loads, read

    M(q) q_ddot + h(q, q_dot) = S^T tau + J_c^T lambda + sum_p J_p^T f_p

h holds the Coriolis, centrifugal and gravity terms, S picks the driven joints, J_c stacks
the cuts' independent constraint rows (the compiled core's Jacobian, the rows the velocity solve
uses) and J_p the loads' frame Jacobians. Pinocchio's RNEA with the loads as external
forces gives b = M q_ddot + h - sum J_p^T f_p, and the square system

    [S^T  J_c^T] [tau; lambda] = b

has the block J_dep^T of the velocity solve, so forces exist wherever velocities do.

Reactions: lambda, mapped back through the cut's rows, is the wrench the cut's parent
link exerts on its child at the cut point. A second RNEA pass with the cut wrenches
applied as external forces leaves in `data.f[i]` the wrench each tree joint's parent
exerts on the child through that joint; its joint-space projection must give back S^T tau
(the `equation_residual`).

Every solution carries a power balance evaluated body by body from Newton-Euler inertial
wrenches (not RNEA's joint projections): sum tau q_dot + P_gravity + P_loads = dT/dt,
along the actual velocities, or along a kinematically admissible virtual velocity when the
mechanism is at rest (statics: the principle of virtual work).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from pinmech.arguments import float_array, names
from pinmech.directions import cross as _cross
from pinmech.model.closure_core import cached_rows
from pinmech.exceptions import BalanceError, IndeterminateForcesError, ModelError, OptionError
from pinmech.model.mechanism import Mechanism
from pinmech.solve.force_results import (ForceSolution, Load, PowerBalance, Reaction, advantage_unit,
                                         mechanical_advantage)
from pinmech.solve.loops import describe_joint_values, serialized
from pinmech.solve.solver_options import SolverOptions

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
#: Default largest condition number of the (dimensionless) force equations: as for velocities.
DEFAULT_MAX_CONDITION = 1e4
#: names kept importable from here (they lived in this module)
__all__ = ["DEFAULT_MAX_CONDITION", "ForceSolution", "ForceSolver", "Load", "PowerBalance", "Reaction",
           "advantage_unit", "mechanical_advantage"]


class ForceSolver:
    """Inverse dynamics of one mechanism, pose after pose (keeps its own `pin.Data`).

    Args:
        mechanism: the model with its loop closures and its links' `<inertial>` data.
        drivers: the driven joints (as many as the mobility).
        gravity: gravity acceleration [m/s^2], world frame (default: none).
        loads: external loads.
        massless: links meant to have no mass (else a moving body without mass is an error).
        minimum_norm: give the smallest reactions that balance the loads where the
            constraint forces are not determined (redundant loops) instead of raising.
        max_condition: worse conditioned force equations are not determined.

    Raises:
        ModelError: a moving body without mass (naming its links), or a driver with
            more than one degree of freedom.
    """

    #: Checked when set, also later (a NaN would turn the dead-centre check off): the
    #: loop and rate solvers' own property, not a copy of it.
    max_condition = SolverOptions.max_condition

    def __init__(
        self,
        mechanism: Mechanism,
        drivers: Sequence[str],
        *,
        gravity: Sequence[float] = (0.0, 0.0, 0.0),
        loads: Sequence[Load] = (),
        massless: Sequence[str] = (),
        minimum_norm: bool = False,
        max_condition: float = DEFAULT_MAX_CONDITION,
    ) -> None:
        self.mechanism = mechanism
        self.model = pin.Model(mechanism.model)  # a copy: its gravity is ours, not the user's
        self.gravity = gravity
        self.lock = threading.RLock()  # one Data: threads sharing the solver take turns
        self.data = self.model.createData()
        self.drivers = names(drivers, "drivers")
        self.loads = tuple(loads)
        for load in self.loads:  # NaN or misshapen loads would give NaN efforts in silence
            vectors = [np.asarray(x, dtype=float) for x in (load.force, load.torque)]
            if any(x.shape != (3,) or not np.all(np.isfinite(x)) for x in vectors) \
                    or not 0 <= load.frame < self.model.nframes:
                raise OptionError(f"load '{load.name}' needs a frame of the model and a force and a torque of "
                                  f"three finite numbers [N, N m], got frame {load.frame!r}, force {load.force!r}, "
                                  f"torque {load.torque!r}", option="loads", value=load)
        self.minimum_norm = minimum_norm
        self.max_condition = max_condition  # checked when set, also later (SolverOptions)
        self._drv_v = np.array([self.mechanism.driver_index(n) for n in self.drivers], dtype=int)
        self._scale = mechanism.velocity_scale()
        self._check_masses(set(massless))

    @property
    def gravity(self) -> np.ndarray:
        """Gravity [m/s^2], world frame (a read-only copy; set it whole)."""
        return self._gravity

    @gravity.setter
    def gravity(self, value) -> None:  # set later, it reached the loads' part and not the model's
        try:
            g = float_array(value, "gravity", (3,))
        except ModelError:
            raise OptionError(f"gravity = {value!r:.80} must be three finite numbers [m/s^2]",
                              option="gravity", value=value) from None
        g = np.array(g, dtype=float)
        g.flags.writeable = False
        self._gravity = g
        self.model.gravity = pin.Motion(g, np.zeros(3))

    def _check_masses(self, massless: set[str]) -> None:
        """The file's masses are the model's (no `force_caveats`), and every moving body
        has a mass, unless all its links are declared massless."""
        model, mech = self.model, self.mechanism
        if mech.force_caveats:
            more = len(mech.force_caveats) - 1
            raise ModelError(f"forces: {mech.force_caveats[0]}" + (f" (and {more} more)" if more else ""),
                             path=mech.source)
        missing = []
        for jid in range(1, model.njoints):
            mass = model.inertias[jid].mass
            if mass < 0 or not np.isfinite(mass):
                raise ModelError(f"forces: the body moved by joint {model.names[jid]} has a mass of {mass:g} kg: a "
                                 "mass must be a positive number", path=mech.source)
            names = [n for n, fid in mech.links.items() if model.frames[fid].parentJoint == jid]
            if mass > 0:
                if names and set(names) <= massless:  # the mass would be used all the same
                    raise ModelError(f"forces: {', '.join(names)} listed in [forces] massless, but the file gives "
                                     f"{'it' if len(names) == 1 else 'them'} {mass:g} kg: drop the mass or the "
                                     "listing", path=mech.source)
                continue
            if not set(names) <= massless | set(mech.massless_links):
                missing += [n for n in names if n not in massless] or [model.names[jid]]
        if missing:
            raise ModelError(f"forces need the masses of the moving links; {', '.join(missing)} "
                             f"have no {mech.mass_source} (give one, or list the links meant to be "
                             "massless: [forces] massless = [...])", path=mech.source)

    @serialized
    def read_placements(self) -> None:
        """Copy the joint and frame placements of the mechanism's model into this solver's
        copy of it (a design study writes each variant's dimensions there in place; the
        copy would otherwise keep the old ones, which the power balance check catches)."""
        source = self.mechanism.model
        for j in range(1, source.njoints):
            self.model.jointPlacements[j] = source.jointPlacements[j]
        for f in range(source.nframes):
            self.model.frames[f].placement = source.frames[f].placement

    # ------------------------------------------------------------------ solve
    @serialized
    def solve(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> ForceSolution:
        """Driver efforts and reactions at a solved pose (q closed, v and a consistent).

        Raises:
            IndeterminateForcesError: the constraint forces are not determined (redundant
                loops, or a dead centre of the drivers), unless `minimum_norm`.
        """
        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        J_c = self._constraint_jacobian(q)
        virtual = v if np.any(v != 0) else self._virtual_velocity(J_c)
        power_terms = self._power_terms(q, v, a, virtual)
        load_wrenches = self._load_wrenches()
        b = pin.rnea(model, data, q, v, a, load_wrenches).copy()
        try:
            x, condition, method = self._solve_system(J_c, b)
        except IndeterminateForcesError as exc:  # name the pose, in the user's units
            at = describe_joint_values(self.mechanism, self.drivers, [self.mechanism.coordinate(q, n) for n in self.drivers])
            said = str(exc).replace("at this pose", f"at {at}") if "at this pose" in str(exc) else f"{exc} (at {at})"
            raise IndeterminateForcesError(said, condition=exc.condition, sigma_min=exc.sigma_min,
                                           unknowns=exc.unknowns, equations=exc.equations) from None
        effort, lam = x[: len(self.drivers)], x[len(self.drivers) :]
        cut_wrenches = self._cut_wrenches(lam)
        total = [f + g for f, g in zip(load_wrenches, self._as_external(cut_wrenches))]
        tau_tree = pin.rnea(model, data, q, v, a, total)
        reactions = self._tree_reactions() | {w.joint: w for w in cut_wrenches}
        solution = ForceSolution(
            drivers=self.drivers,
            effort=effort.copy(),
            reactions=reactions,
            cut_multipliers=lam.copy(),
            power=PowerBalance(float(effort @ virtual[self._drv_v]), *power_terms,
                               "actual" if virtual is v else "virtual"),
            gravity=self.gravity.copy(),
            condition=condition,
            equation_residual=self._equation_residual(tau_tree, effort, b),
            method=method,
        )
        if method == "exact":
            self._check_balance(solution, q)
        return solution

    def _check_balance(self, solution: ForceSolution, q: np.ndarray) -> None:
        """Raise BalanceError where the power balance or the joint equations miss by more
        than rounding at this condition number (1e-9 + 1000 eps kappa, relative; both are
        below 1e-12 in every case tested)."""
        bound = 1e-9 + 1e3 * np.finfo(float).eps * solution.condition
        power, equations = solution.power.residual, solution.equation_residual
        if power <= bound and equations <= bound:
            return
        at = describe_joint_values(self.mechanism, self.drivers, [self.mechanism.coordinate(q, n) for n in self.drivers])
        raise BalanceError(f"the forces at {at} fail their own check: power balance off by {power:.3g} and joint "
                           f"equations by {equations:.3g} (relative; rounding allows {bound:.3g}): the model holds a "
                           "term these forces leave out", power_residual=power, equation_residual=equations,
                           bound=bound)

    def _constraint_jacobian(self, q: np.ndarray) -> np.ndarray:
        """The closure rows' Jacobian (rows, nv) at q on this solver's model (the core's)."""
        return cached_rows(self, self.model, self.mechanism.closures).jacobian(q)

    def _virtual_velocity(self, J_c: np.ndarray) -> np.ndarray:
        """An admissible motion (J_c v = 0) with every driver at unit rate [rad/s or m/s]."""
        nv = self.model.nv
        dep = np.setdiff1d(np.arange(nv), self._drv_v)
        v = np.zeros(nv)
        v[self._drv_v] = 1.0
        if dep.size:
            v[dep] = np.linalg.lstsq(J_c[:, dep], -J_c[:, self._drv_v].sum(axis=1), rcond=None)[0]
        return v

    def _system(self, J_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """[S^T J_c^T] made dimensionless (prismatic rows and driver columns times the size)."""
        nv, nd = self.model.nv, len(self.drivers)
        A = np.zeros((nv, nd + J_c.shape[0]))
        A[self._drv_v, np.arange(nd)] = 1.0
        A[:, nd:] = J_c.T
        columns = np.concatenate((self._scale[self._drv_v], np.ones(J_c.shape[0])))
        return self._scale[:, None] * A / columns[None, :], columns

    def _solve_system(self, J_c: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float, str]:
        A_s, columns = self._system(J_c)
        b_s = self._scale * b
        sigma = np.linalg.svd(A_s, compute_uv=False)
        nv, unknowns = A_s.shape
        square = unknowns == nv
        condition = float(sigma[0] / sigma[-1]) if sigma.size and sigma[-1] > 0 else math.inf
        if square and condition <= self.max_condition:
            return np.linalg.solve(A_s, b_s) / columns, condition, "exact"
        if not self.minimum_norm:
            raise IndeterminateForcesError(self._indeterminate_message(unknowns, nv, condition),
                                           condition=condition, sigma_min=float(sigma[-1]) if sigma.size else 0.0,
                                           unknowns=unknowns, equations=nv)
        x_s = np.linalg.lstsq(A_s, b_s, rcond=1.0 / self.max_condition)[0]
        miss = float(np.max(np.abs(A_s @ x_s - b_s), initial=0.0))
        if miss > 1e-9 * max(float(np.max(np.abs(b_s), initial=0.0)), 1e-300):
            raise IndeterminateForcesError(
                f"{self.mechanism.source}: no finite driver efforts and reactions balance the loads at this "
                f"pose (condition number {condition:.3g}; least-squares miss {miss:.3g}): a dead centre of "
                "the drivers", condition=condition, sigma_min=float(sigma[-1]), unknowns=unknowns, equations=nv)
        return x_s / columns, condition, "minimum_norm"

    def _indeterminate_message(self, unknowns: int, equations: int, condition: float) -> str:
        source = self.mechanism.source
        if unknowns > equations:
            return (f"{source}: the constraint forces are not determined: {unknowns} unknowns "
                    f"({len(self.drivers)} driver efforts and {unknowns - len(self.drivers)} cut rows) for "
                    f"{equations} joint equations, so the loops are redundant (over-constrained); ask for "
                    "the minimum-norm reactions (--minimum-norm, [forces] minimum_norm = true) if they will do")
        return (f"{source}: the driver efforts and constraint forces are not determined at this pose "
                f"(condition number {condition:.3g} > {self.max_condition:.3g}): a dead centre of the drivers "
                "or redundant loops; the minimum-norm reactions (--minimum-norm) are one choice among many")

    # ------------------------------------------------------------------ wrenches
    def _world_to_joint(self, joint: int, point: np.ndarray, force: np.ndarray, moment: np.ndarray) -> pin.Force:
        """A force at `point` and a moment (world frame) as a spatial force in a joint's frame."""
        return self.data.oMi[joint].actInv(pin.Force(force, moment + _cross(point, force)))

    def _load_wrenches(self) -> list[pin.Force]:
        """The loads as RNEA external forces, one per joint, in the joints' local frames."""
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        for load in self.loads:
            joint = self.model.frames[load.frame].parentJoint
            point = self.data.oMf[load.frame].translation
            out[joint] += self._world_to_joint(joint, point, load.force, load.torque)
        return out

    def _cut_wrenches(self, lam: np.ndarray) -> list[Reaction]:
        """Each cut's wrench on its child link (by its parent), world frame, about the child
        cut frame's origin C: the cut's rows measure C's velocity relative to the parent's
        material point at C, so the force acts there on both links (on a slide, the two cut
        frames' origins part along the axis; at a closed pin they coincide)."""
        out, start = [], 0
        for c in self.mechanism.closures:
            f6 = c.rows6.T @ lam[start : start + c.rows]  # relative 6-vector of the cut, in P
            start += c.rows
            R = self.data.oMf[c.parent_frame].rotation
            axis = R @ c.axis if c.cut_type in ("revolute", "prismatic") else np.zeros(3)
            out.append(Reaction(c.name, c.cut_type, c.parent_link, c.child_link,
                                self.data.oMf[c.child_frame].translation.copy(), R @ f6[:3], R @ f6[3:], axis, True))
        return out

    def _as_external(self, cuts: list[Reaction]) -> list[pin.Force]:
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        for cut, c in zip(cuts, self.mechanism.closures):
            for frame, sign in ((c.child_frame, 1.0), (c.parent_frame, -1.0)):
                joint = self.model.frames[frame].parentJoint
                out[joint] += self._world_to_joint(joint, cut.point, sign * cut.force, sign * cut.moment)
        return out

    def _tree_reactions(self) -> dict[str, Reaction]:
        """Wrench of each tree joint's parent link on its child, from `data.f` of the last RNEA."""
        out = {}
        for name, joint in self.mechanism.joints.items():
            M = self.data.oMi[joint.id]
            f = self.data.f[joint.id]
            axis = M.rotation @ joint.axis if joint.nv == 1 else np.zeros(3)
            out[name] = Reaction(name, joint.kind, joint.parent_link, joint.child_link, M.translation.copy(),
                                 M.rotation @ f.linear, M.rotation @ f.angular, axis, False)
        return out

    def _equation_residual(self, tau_tree: np.ndarray, effort: np.ndarray, b: np.ndarray) -> float:
        applied = np.zeros(self.model.nv)
        applied[self._drv_v] = effort
        scale = max(float(np.max(np.abs(self._scale * b), initial=0.0)),
                    float(np.max(np.abs(self._scale * applied), initial=0.0)), 1e-300)
        return float(np.max(np.abs(self._scale * (tau_tree - applied)), initial=0.0)) / scale

    # ------------------------------------------------------------------ power
    def _power_terms(self, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                     virtual: np.ndarray) -> tuple[float, float, float]:
        """Gravity power, load power and kinetic rate (or virtual inertial power) [W], body by body."""
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, q, virtual)
        pin.updateFramePlacements(model, data)
        twists = [data.v[i].copy() for i in range(model.njoints)]
        load_power = 0.0
        for load in self.loads:
            vel = pin.getFrameVelocity(model, data, load.frame, _LWA)
            load_power += float(load.force @ vel.linear + load.torque @ vel.angular)
        pin.forwardKinematics(model, data, q, v, a)
        gravity_power = kinetic = 0.0
        for i in range(1, model.njoints):
            inertia = model.inertias[i]
            g_local = data.oMi[i].rotation.T @ self.gravity
            gravity_power += float(twists[i].dot(inertia * pin.Motion(g_local, np.zeros(3))))
            inertial = inertia * data.a[i] + data.v[i].cross(inertia * data.v[i])
            kinetic += float(twists[i].dot(inertial))
        kinetic += float(virtual @ (model.armature * a))  # rotor inertias (MJCF armature), as rnea has them
        pin.updateFramePlacements(model, data)
        return gravity_power, load_power, kinetic
