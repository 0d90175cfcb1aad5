"""Inverse kinematics of a parallel mechanism at one task-space point and working mode,
and what the Jacobians say there: the engine's closure rows with the end point as driver.

Unknowns: every joint coordinate q. Equations, square (nv of them): the loops' closure rows
(dimensionless, the compiled core's) and the end point's grid coordinates minus the target,
over the characteristic length L. Newton from a seed in the asked working mode (each leg
seeded from a table of its own sampled poses, the nearest tip of the right sign), with a
line search that refuses a step changing any leg's mode: a point is reachable in a mode
when Newton converges there (residual below 1e-10, i.e. ~1e-11 m on these mechanisms).

At the solution, with Phi the closure Jacobian (passive columns p, motor columns a) and E
the end point's rows over L:
    K = [Phi; E]            its det -> 0: type I (serial) singularity (inverse kinematics)
    Phi_p                   its det -> 0: type II (parallel) singularity (direct kinematics)
    J = (E_a - E_p Phi_p^-1 Phi_a)   motor rates -> end point velocity / L (dimensionless)
    kappa = cond(J)         2-norm condition number of the dimensionless Jacobian
Prismatic columns are scaled by the loops' size (`Mechanism.velocity_scale`), a prismatic
motor's column of J by L, so every matrix is dimensionless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product

import numpy as np
import pinocchio as pin

from pinmech.design.study.file import spec_scene
from pinmech.design.workspace.file import WorkspaceSpec
from pinmech.design.workspace.legs import Leg, angles, find_legs, mode_sign, passive_conditioning, set_angles
from pinmech.exceptions import SceneError
from pinmech.io.scene_model import load_mechanism, scene_drivers
from pinmech.model.closure_core import closure_rows
from pinmech.solve.kernels import attach, resolved

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
TOL = 1e-10  # Newton's convergence on the dimensionless residual (closure rows / loop size, end rows / L)
_ITERATIONS = 60
_HALVINGS = 9  # line-search steps 1 .. 1/256 of Newton's
_STALL = 20  # Newton gives up when |F| has not halved over this many steps (a leg near its fold takes ~15)
_SAMPLES_FULL = 20  # seed poses over a full turn (18 deg apart): the motor and the first passive joint
_SAMPLES_HALF = 9  # a further hinge (a universal joint's second), reference +- 90 deg: the bar directions
# (a, b) and (a + pi, pi - b) of a universal joint are one pose, so half a turn of b covers them once
_SEED_CONDITIONING = 0.2  # seeds this far from a leg's fold (|m . n| / |m|) and from a gimbal lock of its
# passive joints (their columns' sigma_min / sigma_max): a seed on either has no meaningful mode


@dataclass(frozen=True)
class PointSolution:
    """One grid point in one working mode: reached or not, and (if reached) the motors'
    coordinates [rad or m], det and least singular value of K (type I) and of Phi_p (type
    II), and kappa of the dimensionless Jacobian (inf on a type II singularity)."""

    reached: bool
    motors: np.ndarray
    det1: float = np.nan
    det2: float = np.nan
    sigma1: float = np.nan
    sigma2: float = np.nan
    kappa: float = np.nan


class WorkspaceMechanism:
    """The study's mechanism, its legs, end point and seed tables: built once per process."""

    def __init__(self, spec: WorkspaceSpec) -> None:
        scene = spec_scene(spec)
        self.mechanism = m = load_mechanism(scene)
        self.model, self.data = m.model, m.model.createData()
        if m.closures:  # the closure rows' core runs the passes the scene (or the API) asks
            points = math.prod(axis.count for axis in spec.axes)  # each a Newton solve: poses, for "auto"
            attach(closure_rows(m).core, m.model, resolved(scene.solver_options().get("kernel", "generic"), points))
        where = str(spec.path)
        self.motors = tuple(scene_drivers(scene, m).names)
        self.legs = find_legs(m, self.motors, where)
        _check_axes(spec, self.motors, where)
        self.end = m.frame_id(spec.point)
        self.rows = np.array(spec.task_rows)
        self.length = spec.length or m.length_scale
        self.scale = m.velocity_scale()
        self.q0 = m.neutral()
        in_legs = {j for leg in self.legs for j in leg.joints}
        self.end_leg = next((i for i, leg in enumerate(self.legs) if self.model.frames[self.end].parentJoint
                             in leg.joints), None)
        self.platform = tuple(j for j in range(1, self.model.njoints) if j not in in_legs)
        self.motor_cols = np.array([leg.cols[0] for leg in self.legs])
        self.passive_cols = np.array([c for c in range(self.model.nv) if c not in set(self.motor_cols)])
        self.prismatic_motor = np.array([self.model.joints[leg.joints[0]].shortname().startswith("JointModelP")
                                         for leg in self.legs])
        if self.end_leg is None and len(self.platform) != len(spec.axes):
            raise SceneError(f"the end point '{spec.point}' is on neither a motor's leg nor a platform of "
                             f"{len(spec.axes)} joints", path=where, key="workspace.point")
        self.seeds = [self._seed_table(leg) for leg in self.legs]
        self.modes = resolve_modes(spec, len(self.legs))

    # ---------------------------------------------------------------- seeds
    def _seed_table(self, leg: Leg) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The leg's sampled poses: angles (S, n), cut frame (S, 3) and end point (S, 3)
        positions [m], mode signs (S,)."""
        grids = [self._samples(j, full=(k <= 1)) for k, j in enumerate(leg.joints)]
        theta = np.array(list(product(*grids)))
        tips, ends, signs = (np.zeros((len(theta), 3)), np.zeros((len(theta), 3)), np.zeros(len(theta)))
        q = self.q0.copy()
        for s, t in enumerate(theta):
            set_angles(self.model, q, leg.joints, t)
            self._kinematics(q)
            tips[s], ends[s] = self.data.oMf[leg.frame].translation, self.data.oMf[self.end].translation
            sign = mode_sign(self.mechanism, self.data, leg)
            conditioning = passive_conditioning(self.mechanism, self.data, leg)
            usable = abs(sign) > _SEED_CONDITIONING and conditioning > _SEED_CONDITIONING
            signs[s] = np.sign(sign) if usable else 0.0
        return theta, tips, ends, signs

    def _samples(self, jid: int, full: bool) -> np.ndarray:
        joint = self.model.joints[jid]
        if joint.nq == 2 or full:
            return np.linspace(-np.pi, np.pi, _SAMPLES_FULL, endpoint=False)
        ref = angles(self.model, self.q0, (jid,))[0]
        return ref + np.linspace(-np.pi / 2, np.pi / 2, _SAMPLES_HALF)

    def _seed(self, x: np.ndarray, signs: tuple[float, ...]) -> np.ndarray | None:
        """A start for Newton: the platform placed on x, then each leg in turn from its
        nearest sample of its sign to its own target by a leg-local Newton; None if a leg
        cannot reach its target in its mode."""
        q = self.q0.copy()
        if self.end_leg is None:
            self._place_platform(q, x)
        order = ([self.end_leg] if self.end_leg is not None else []) + \
                [i for i in range(len(self.legs)) if i != self.end_leg]
        for i in order:
            leg, (theta, tips, ends, sample_signs) = self.legs[i], self.seeds[i]
            if i == self.end_leg:
                frame, rows, target, gap = self.end, self.rows, x, np.linalg.norm(ends[:, self.rows] - x, axis=1)
            else:
                self._kinematics(q)
                target = self.data.oMf[leg.partner].translation.copy()
                frame, rows, gap = leg.frame, np.arange(3), np.linalg.norm(tips - target, axis=1)
            gap[sample_signs != signs[i]] = np.inf
            set_angles(self.model, q, leg.joints, theta[int(np.argmin(gap))])
            if not self._leg_newton(q, leg, frame, rows, target, signs[i]):
                return None
        return q

    def _leg_newton(self, q: np.ndarray, leg: Leg, frame: int, rows: np.ndarray, target: np.ndarray,
                    sign: float) -> bool:
        """Move the leg's joints in q (in place) until `frame`'s coordinates `rows` reach
        target [m], keeping the leg's mode sign: Gauss-Newton (a planar leg's third row is
        identically met) with a line search; False if it does not get there."""
        def error(qq: np.ndarray) -> tuple[np.ndarray, bool]:
            self._kinematics(qq)
            kept = np.sign(mode_sign(self.mechanism, self.data, leg)) == sign
            return (self.data.oMf[frame].translation[rows] - target) / self.length, kept

        e, kept = error(q)
        history = [float(np.linalg.norm(e))]
        for _ in range(_ITERATIONS):
            if not kept or (len(history) > _STALL and history[-1] > 0.5 * history[-1 - _STALL]):
                return False
            if history[-1] < TOL:
                return True
            jac = pin.getFrameJacobian(self.model, self.data, frame, _LWA)[:3][rows][:, leg.cols] / self.length
            step = np.zeros(self.model.nv)
            step[leg.cols] = np.linalg.lstsq(jac, -e, rcond=None)[0]
            for alpha in 0.5 ** np.arange(_HALVINGS):
                trial = pin.integrate(self.model, q, alpha * step)
                e2, kept = error(trial)
                if kept and np.linalg.norm(e2) < history[-1]:
                    break
            else:
                return False
            q[:], e = trial, e2
            history.append(float(np.linalg.norm(e)))
            if np.max(np.abs(step)) < 1e-4 and history[-1] > 0.99 * history[-2]:
                return False  # steps of < 1e-4 rad that no longer gain: the nearest the leg gets, short of it
        return False

    def _place_platform(self, q: np.ndarray, x: np.ndarray) -> None:
        cols = np.array([self.model.joints[j].idx_v for j in self.platform])
        for _ in range(20):
            self._kinematics(q)
            error = self.data.oMf[self.end].translation[self.rows] - x
            if np.max(np.abs(error)) < TOL * self.length:
                return
            jac = pin.getFrameJacobian(self.model, self.data, self.end, _LWA)[:3][self.rows][:, cols]
            step = np.zeros(self.model.nv)
            step[cols] = np.linalg.lstsq(jac, -error, rcond=None)[0]
            q[:] = pin.integrate(self.model, q, step)

    # ---------------------------------------------------------------- Newton
    def _kinematics(self, q: np.ndarray) -> None:
        """Place every joint and frame at q, with the joints' Jacobians."""
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)

    def _phi(self, q: np.ndarray) -> np.ndarray:
        """The stacked closure Jacobian (velocity rows, dimensionless) at q."""
        return closure_rows(self.mechanism).jacobian(q)

    def _residual(self, q: np.ndarray, x: np.ndarray, signs: tuple[float, ...]):
        """(F, dF/dq, mode kept) at q: closure rows and end rows over L."""
        self._kinematics(q)
        kept = all(np.sign(mode_sign(self.mechanism, self.data, leg)) == s for leg, s in zip(self.legs, signs))
        rows = closure_rows(self.mechanism)
        F = np.concatenate([rows.residual(q), (self.data.oMf[self.end].translation[self.rows] - x) / self.length])
        dF = np.vstack([rows.jacobian(q, newton=True), self._end_rows()])
        return F, dF, kept

    def _end_rows(self) -> np.ndarray:
        return pin.getFrameJacobian(self.model, self.data, self.end, _LWA)[:3][self.rows] / self.length

    def inverse(self, x: np.ndarray, mode: str) -> np.ndarray | None:
        """q reaching end point coordinates x [m] in working mode `mode`, or None."""
        signs = tuple(1.0 if s == "+" else -1.0 for s in mode)
        q = self._seed(x, signs)
        if q is None:
            return None
        F, dF, kept = self._residual(q, x, signs)
        if not kept:
            return None
        history = [float(np.linalg.norm(F))]
        for _ in range(_ITERATIONS):
            if float(np.max(np.abs(F))) < TOL:
                return q
            if len(history) > _STALL and history[-1] > 0.5 * history[-1 - _STALL]:
                return None  # no longer converging: a least-squares point outside the mode's workspace
            try:
                step = np.linalg.solve(dF, -F)
            except np.linalg.LinAlgError:
                step = np.linalg.lstsq(dF, -F, rcond=None)[0]
            for alpha in 0.5 ** np.arange(_HALVINGS):
                trial = pin.integrate(self.model, q, alpha * step)
                F2, dF2, kept = self._residual(trial, x, signs)
                if kept and np.linalg.norm(F2) < np.linalg.norm(F):  # Newton's step descends |F|^2
                    break
            else:
                return None
            q, F, dF = trial, F2, dF2
            history.append(float(np.linalg.norm(F)))
        return q if float(np.max(np.abs(F))) < TOL else None

    # ---------------------------------------------------------------- measures
    def solve(self, x: np.ndarray, mode: str) -> PointSolution:
        """The point's inverse kinematics in `mode` and its Jacobians' measures."""
        q = self.inverse(x, mode)
        if q is None:
            return PointSolution(False, np.full(len(self.legs), np.nan))
        return self.measures(q)

    def measures(self, q: np.ndarray) -> PointSolution:
        """The Jacobians' measures at a closed pose q (any working and assembly mode)."""
        self._kinematics(q)
        phi, end = self._phi(q), self._end_rows()
        K = np.vstack([phi, end]) * self.scale
        a, p = self.motor_cols, self.passive_cols
        phi_p = phi[:, p] * self.scale[p]
        det2, sigma2 = float(np.linalg.det(phi_p)), float(np.linalg.svd(phi_p, compute_uv=False)[-1])
        try:
            J = end[:, a] - end[:, p] @ np.linalg.solve(phi[:, p], phi[:, a])
            J[:, self.prismatic_motor] *= self.length
            kappa = float(np.linalg.cond(J))
        except np.linalg.LinAlgError:
            kappa = np.inf
        motors = np.array([angles(self.model, q, (leg.joints[0],))[0] for leg in self.legs])
        return PointSolution(True, motors, float(np.linalg.det(K)), det2,
                             float(np.linalg.svd(K, compute_uv=False)[-1]), sigma2, kappa)


def resolve_modes(spec: WorkspaceSpec, legs: int) -> tuple[str, ...]:
    """The working modes asked, checked against the number of legs (all 2**legs if none)."""
    if not spec.modes:
        return tuple("".join(s) for s in product("+-", repeat=legs))
    bad = [m for m in spec.modes if len(m) != legs]
    if bad:
        raise SceneError(f"working mode {bad[0]!r} has {len(bad[0])} signs; the mechanism has {legs} legs "
                         f"(one sign a leg, in the motors' order)", path=str(spec.path), key="workspace.modes")
    return spec.modes


def _check_axes(spec: WorkspaceSpec, motors: tuple[str, ...], where: str) -> None:
    """As many task axes as motors, or (an actuator-space grid) one axis a motor, named."""
    if spec.space == "actuator":
        names = tuple(a.name for a in spec.axes)
        if sorted(names) != sorted(motors):
            raise SceneError(f"the actuator grid's axes ({', '.join(names)}) must be the motors "
                             f"({', '.join(motors)}), one each", path=where, key="workspace.actuators")
        return
    if len(spec.axes) != len(motors):
        raise SceneError(f"{len(motors)} motors need {len(motors)} grid axes "
                         f"({'x, y' if len(motors) == 2 else 'x, y, z'}); the file gives {len(spec.axes)}",
                         path=where, key="workspace")
