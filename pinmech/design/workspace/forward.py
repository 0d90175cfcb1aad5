"""Forward kinematics of a parallel mechanism with its motors held: every assembly mode the
engine's closure rows reach at one actuator-space point, for an actuator-space workspace
study.

With the motors held, the unknowns are the passive joints (as many as closure rows: the
compiled core's closure residual, dimensionless). Each solution is reached by Newton from a pose
of a seed table, the motors moved from the seed's values to the target in steps of at most
10 deg (or 0.05 L) with the loops closed at every step (a short continuation), and every
line search refusing a step that changes the sign of det Phi_p: the assembly mode. The seed
table is a set of closed poses drawn once per process, the same in every process (a fixed
random stream): random joint values brought onto the closure manifold by a minimum-norm
Gauss-Newton. A universal joint's second hinge is kept within 90 deg of its reference, as
in the task-space seeds (one parametrisation of each bar direction, so det Phi_p's sign
names one assembly).

For each sign the nearest seeds (in the motors' values) of that sign are tried, up to
`TRIES`, until one reaches the target: one assembly a sign. The five-bar (two circles) and
the Delta (three spheres) have at most two assemblies, of opposite signs; a mechanism with
several assemblies of one sign (a 3-RPR's up to six) shows the one reached from the
nearest seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.design.workspace.legs import angles, mode_sign, set_angles
from pinmech.design.workspace.solve import TOL, PointSolution, WorkspaceMechanism
from pinmech.model.closure_core import closure_rows

TRIES = 8  # nearest seeds tried per assembly sign, until one reaches the target
_ITERATIONS = 40
_HALVINGS = 9
_STEP_ANGLE = math.radians(10.0)  # motors moved at most this much a continuation step [rad]
_STEP_LENGTH = 0.05  # ... or this share of L (a prismatic motor)
_TABLE = {2: 600, 3: 2000}  # seed poses kept, by number of motors
_DRAWS = 4  # random draws tried a kept seed pose, at most


@dataclass(frozen=True)
class ForwardSolution:
    """One assembly of the mechanism at the held motors: its pose q, its end point's task
    coordinates x [m], its assembly mode (the sign of det Phi_p, +1 or -1), its legs'
    working modes ("+-", a sign a leg) and the Jacobians' measures there."""

    q: np.ndarray
    x: np.ndarray
    sign: int
    modes: str
    point: PointSolution


class ForwardKinematics:
    """The study's mechanism with its seed table of closed poses: built once per process."""

    def __init__(self, wm: WorkspaceMechanism) -> None:
        self.wm = wm
        self.motor_joints = tuple(leg.joints[0] for leg in wm.legs)
        self.step = np.array([_STEP_LENGTH * wm.length if p else _STEP_ANGLE for p in wm.prismatic_motor])
        self.hinges = [j for leg in wm.legs for j in leg.joints[2:]]  # a universal joint's further hinges
        self.hinge_ref = angles(wm.model, wm.q0, tuple(self.hinges))
        self.table_q, self.table_motors, self.table_signs = self._table(_TABLE.get(len(wm.legs), 2000))

    # ---------------------------------------------------------------- closed poses
    def _table(self, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(poses (S, nq), motors (S, motors) [rad or m], assembly signs (S,))."""
        rng = np.random.default_rng(20251126)
        poses, motors, signs = [], [], []
        for _ in range(count * _DRAWS):
            if len(poses) == count:
                break
            q = self._project(self._draw(rng))
            if q is None or not self._canonical(q):
                continue
            sign = self._sign(q)
            if sign:
                poses.append(q)
                motors.append(angles(self.wm.model, q, self.motor_joints))
                signs.append(sign)
        return np.array(poses), np.array(motors), np.array(signs)

    def _draw(self, rng: np.random.Generator) -> np.ndarray:
        """Random joint values: turns in [-pi, pi) (a further hinge within 90 deg of its
        reference), slides within 2 loop sizes of zero."""
        model, q = self.wm.model, self.wm.q0.copy()
        for j in range(1, model.njoints):
            if j in self.hinges:
                value = self.hinge_ref[self.hinges.index(j)] + rng.uniform(-0.45 * np.pi, 0.45 * np.pi)
            elif model.joints[j].shortname().startswith("JointModelP"):
                value = rng.uniform(-2.0, 2.0) * self.wm.mechanism.length_scale
            else:
                value = rng.uniform(-np.pi, np.pi)
            set_angles(model, q, (j,), np.array([value]))
        return q

    def _project(self, q: np.ndarray) -> np.ndarray | None:
        """The nearest closed pose to q by minimum-norm Gauss-Newton over every joint, or None."""
        F, J = self._closure(q)
        history = [float(np.linalg.norm(F))]
        for _ in range(_ITERATIONS):
            if float(np.max(np.abs(F))) < TOL:
                return q
            if len(history) > 6 and history[-1] > 0.5 * history[-7]:
                return None  # stalled: a draw that does not reach the manifold soon is not worth keeping
            step = np.linalg.lstsq(J, -F, rcond=None)[0]
            for alpha in 0.5 ** np.arange(_HALVINGS):
                trial = pin.integrate(self.wm.model, q, alpha * step)
                F2, J2 = self._closure(trial)
                if np.linalg.norm(F2) < np.linalg.norm(F):
                    break
            else:
                return None
            q, F, J = trial, F2, J2
            history.append(float(np.linalg.norm(F)))
        return None

    def _canonical(self, q: np.ndarray) -> bool:
        """Every further hinge within 90 deg of its reference (one parametrisation a bar)."""
        if not self.hinges:
            return True
        gap = angles(self.wm.model, q, tuple(self.hinges)) - self.hinge_ref
        return bool(np.all(np.abs((gap + np.pi) % (2 * np.pi) - np.pi) < 0.5 * np.pi))

    # ---------------------------------------------------------------- Newton, motors held
    def _closure(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Closure rows F (the compiled core's) and their exact derivative dF/dq at q."""
        rows = closure_rows(self.wm.mechanism)
        return rows.residual(q), rows.jacobian(q, newton=True)

    def _sign(self, q: np.ndarray) -> int:
        """sign(det Phi_p) at q (0 on a type II singularity): the assembly mode."""
        wm = self.wm
        p = wm.passive_cols
        return int(np.sign(np.linalg.det(wm._phi(q)[:, p] * wm.scale[p])))

    def _hold(self, q: np.ndarray, sign: int) -> np.ndarray | None:
        """Close the loops over the passive joints (the motors as in q), keeping the assembly
        sign; None if Newton does not get there."""
        p = self.wm.passive_cols
        F, J = self._closure(q)
        for _ in range(_ITERATIONS):
            if float(np.max(np.abs(F))) < TOL:
                return q
            step = np.zeros(self.wm.model.nv)
            try:
                step[p] = np.linalg.solve(J[:, p], -F)
            except np.linalg.LinAlgError:
                step[p] = np.linalg.lstsq(J[:, p], -F, rcond=None)[0]
            for alpha in 0.5 ** np.arange(_HALVINGS):
                trial = pin.integrate(self.wm.model, q, alpha * step)
                F2, J2 = self._closure(trial)
                if np.linalg.norm(F2) < np.linalg.norm(F) and self._sign(trial) == sign:
                    break
            else:
                return None
            q, F, J = trial, F2, J2
        return None

    def _follow(self, q: np.ndarray, target: np.ndarray, sign: int) -> np.ndarray | None:
        """From the closed pose q, the motors moved to target [rad or m] in short steps,
        the loops closed in the same assembly at each; None if a step fails."""
        start = angles(self.wm.model, q, self.motor_joints)
        gap = target - start
        turn = ~self.wm.prismatic_motor
        gap[turn] = (gap[turn] + np.pi) % (2 * np.pi) - np.pi
        steps = max(1, int(np.ceil(np.max(np.abs(gap) / self.step))))
        q = q.copy()
        for k in range(1, steps + 1):
            set_angles(self.wm.model, q, self.motor_joints, start + gap * (k / steps))
            q = self._hold(q, sign)
            if q is None:
                return None
        return q if self._canonical(q) else None

    # ---------------------------------------------------------------- all assemblies
    def solve(self, target: np.ndarray) -> list[ForwardSolution]:
        """The assemblies found at motors `target` [rad or m] (motors' order): at most one
        a sign of det Phi_p, + first."""
        gap = self.table_motors - target
        turn = ~self.wm.prismatic_motor
        gap[:, turn] = (gap[:, turn] + np.pi) % (2 * np.pi) - np.pi
        order = np.argsort(np.max(np.abs(gap) / self.step, axis=1), kind="stable")
        found: list[ForwardSolution] = []
        for sign in (1, -1):
            for i in order[self.table_signs[order] == sign][:TRIES]:
                q = self._follow(self.table_q[i], target, sign)
                if q is not None:
                    found.append(self._solution(q, sign))
                    break
        return found

    def _solution(self, q: np.ndarray, sign: int) -> ForwardSolution:
        wm = self.wm
        wm._kinematics(q)
        x = wm.data.oMf[wm.end].translation[wm.rows].copy()
        modes = "".join("+" if mode_sign(wm.mechanism, wm.data, leg) > 0 else "-" for leg in wm.legs)
        return ForwardSolution(q, x, sign, modes, wm.measures(q))
