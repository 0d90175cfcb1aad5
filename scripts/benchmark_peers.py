"""pinmech against the kinematics tools a user could pick instead, on two textbook problems.

P1, the R-RTR of Problem Chapter I.9 (A = (0, 0), C = (0.05, 0) m, AB = 0.10 m, CD = 0.15 m,
crank at -50 rpm, no angular acceleration): link 3's angle, angular velocity and
acceleration, the slide rate and acceleration s', s'' of the block along link 3
(s = |CB|), and D's velocity and acceleration, at `--poses` crank angles spread evenly
over a turn from 0 (360: 1 degree apart).

P2, the arm of text 17.110 (AB = BC = 0.3 m, CD = 0.17 m, CD vertical, D moving at 1 m/s
along x with zero acceleration): the angular velocities and accelerations of AB and BC at
`--poses` poses theta1 = 50 deg + k deg, theta2 = theta1 - 65 deg + 40 deg sin(k deg),
k = 0, 360/poses, ... (360: k = 0, 1, ..., 359 degrees; k = 0 is the textbook pose).

Every method solves the whole set of poses in one call and is timed in this one process,
interleaved: after a warm-up, each round times every method once (in an order rotated
from round to round, garbage collection paused as timeit does), a method's sample being
as many calls as fill `--sample-time`. The table gives the median over the rounds of the
time per pose and its spread (fastest and slowest round), and next to it the largest
absolute difference from the closed form (scripts/closed_form.py, vectorized numpy, the
reference) over every pose and output, in SI units (rad, rad/s, rad/s^2, m/s, m/s^2).

Methods (the optional peers come with `pip install "pinmech[bench]"`; a missing one is a
row saying "not installed", never a crash):
- closed form, vectorized numpy: the nine (four) outputs written out, the lower bound;
  checked against scripts/closed_form.py like the others;
- pylinkage 1.3 with numba, `Linkage.step_fast_with_kinematics` (analytic point rates; link
  3's rates from D and B by the two-point formulas, in the timing): its first call compiles
  the numba kernels (or loads them from numba's cache), reported apart and not timed;
  `--numba-cold` points NUMBA_CACHE_DIR at an empty folder so that first call compiles;
- sympy.physics.mechanics: vector loop differentiated with .dt(N), the velocity and
  acceleration equations solved symbolically, `lambdify(cse=True)`; P1's positions by
  Newton on the lambdified loop residual; per pose with modules="math", and for P2 also
  one vectorized call with modules="numpy";
- Pinocchio from a plain Python script (the peers' way): a URDF tree, the loop closed by
  hand with frame Jacobians (Newton), rates from J v = 0 and J a = -drift, the drift from
  classical frame accelerations;
- pinmech's compiled core: its `follow` alone (the C++ loop, from the sweep's first pose);
- Pinocchio's passes alone, in C++ (`Core.pinocchio_passes`, on the solved poses): the
  fewest Pinocchio calls any certified answer needs at a pose, with nothing else. P1: the
  joint Jacobians twice (the Newton step at the predicted q; the certifying residual and
  the velocity Jacobian at the corrected q) and the kinematics at (q, v, 0) once (the
  acceleration drift); P2: the joint Jacobians and the kinematics once each. A cost, not
  an answer (no error): the report says how much of the fastest peer's time it leaves;
- pinmech: `Sweep.chunks` with `frame_paths` of link 3 and D on each chunk (every output,
  in the timing);
- pinmech: `Sweep.chunks` of the bundled scene (q, v, a of every joint) alone and with
  `evaluate_motion` of link 3 and D per pose, at `--poses` and at ten times as many;
  P2 with `RateSolver.solve_many` on every pose at once, and `RateSolver.solve` per pose.

Run: python scripts/benchmark_peers.py [--poses 360] [--rounds 7] [--out FILE.md]

The report states what was measured; the project's speed targets (pinmech's full answer
faster than every peer at <= 1e-13, and the limits of RATIOS) are read by the exit code
alone: 1, each missed target named on stderr, when the run misses one.
"""

from __future__ import annotations

import argparse
import atexit
import functools
import importlib
import math
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

import numpy as np

from interleave import machine, time_rounds

sys.path.insert(0, str(Path(__file__).resolve().parent))
import closed_form

ROOT = Path(__file__).resolve().parents[1]
SCENE_P1 = ROOT / "models" / "scenes" / "r_rtr.toml"
URDF_P2 = ROOT / "models" / "planar_arm.urdf"

# P1: the R-RTR [m, rad/s, rad/s^2]
AB, AC, CD = 0.10, 0.05, 0.15
OMEGA1 = -50.0 * math.pi / 30.0
ALPHA1 = 0.0
# P2: the 3R arm [m, m/s, m/s^2]
R1, R2, R3 = 0.3, 0.3, 0.17
TH_CD = -math.pi / 2
VD = (1.0, 0.0)
AD = (0.0, 0.0)

P1_OUTPUTS = "phi3, omega3, alpha3, s', s'', vD, aD"
#: pinmech's rows that give every output as the peers do (the comparisons read these), and
#: the compiled core's loop alone (the C++ floor of the first).
ANSWERS = ("pinmech Sweep.chunks + frame_paths (every output)", "pinmech RateSolver.solve_many")
FLOOR = "pinmech compiled core's follow alone (C++ floor)"
#: Pinocchio's own passes alone, in C++ (Core.pinocchio_passes): a cost, not an answer.
PASSES = "Pinocchio's passes alone, C++"
P2_OUTPUTS = "omega_AB, omega_BC, alpha_AB, alpha_BC"
BENCH_EXTRA = 'pip install "pinmech[bench]"'


# ------------------------------------------------------------------ problems
def p1_angles(poses: int) -> np.ndarray:
    """Crank angles [rad]: `poses` of them, evenly over one turn from 0."""
    return np.radians(np.arange(poses) * (360.0 / poses))


def p2_angles(poses: int) -> tuple[np.ndarray, np.ndarray]:
    """Absolute angles of AB and BC [rad] at the P2 poses."""
    k = np.arange(poses) * (360.0 / poses)
    th1 = np.radians(50.0 + k)
    return th1, np.radians(50.0 + k - 65.0 + 40.0 * np.sin(np.radians(k)))


def p1_closed_form(phi: np.ndarray) -> np.ndarray:
    """(poses, 9): phi3, omega3, alpha3, s', s'', vD (x, y), aD (x, y) from the closed form."""
    r = closed_form.r_rtr(phi, OMEGA1, ALPHA1, AB=AB, AC=AC, CD=CD)
    return np.column_stack([r.phi3, r.omega3, r.alpha3, r.s_dot, r.s_ddot, r.vD, r.aD])


def p2_closed_form(th1: np.ndarray, th2: np.ndarray) -> np.ndarray:
    """(poses, 4): omega_AB, omega_BC, alpha_AB, alpha_BC from the closed form."""
    r = closed_form.planar_arm_rates(th1, th2, TH_CD, R1, R2, R3, np.array(VD), np.array(AD))
    return np.column_stack([r.omega_AB, r.omega_BC, r.alpha_AB, r.alpha_BC])


def largest_error(got: np.ndarray, ref: np.ndarray, angle_columns: tuple[int, ...] = ()) -> float:
    """Largest |got - ref| over every pose and output (angles modulo a turn); inf if any
    output is missing or not finite."""
    got = np.asarray(got, dtype=float)
    if got.shape != ref.shape or not np.all(np.isfinite(got)):
        return math.inf
    d = got - ref
    for j in angle_columns:
        d[:, j] = (d[:, j] + math.pi) % (2 * math.pi) - math.pi
    return float(np.max(np.abs(d)))


# ------------------------------------------------------------------ rows
@dataclass
class Row:
    """One method on one problem: how it is called, and what was measured.

    Attributes:
        run: one call solving every pose; returns what `read` turns into outputs.
        read: raw result -> (poses, outputs) array, not timed (default: as is).
        times: seconds per pose, one per round.
        error: largest absolute difference from the closed form [SI units].
        one_off: costs not in the time (set-up, first call), as text.
        status: why there is no time ("not installed: ...", "failed: ...").
    """

    problem: str
    method: str
    poses: int
    run: Callable[[], object] | None = None
    read: Callable[[object], np.ndarray] = np.asarray
    calls: int = 1
    times: list[float] = field(default_factory=list)
    error: float = math.nan
    one_off: str = ""
    status: str = ""
    is_pinmech: bool = False
    #: Pinocchio's share of any answer (PASSES), timed like the methods but no answer itself.
    is_bound: bool = False

    @property
    def median_us(self) -> float:
        return statistics.median(self.times) * 1e6 if self.times else math.nan


def _seconds(t: float) -> str:
    if t < 1e-3:
        return f"{t * 1e6:.0f} us"
    return f"{t * 1e3:.3g} ms" if t < 1 else f"{t:.1f} s"


def build(row: Row, package: str | None, make: Callable[[], tuple]) -> Row:
    """Fill `row` from make() -> (run, read or None, set-up note), timing the first import
    of `package` and the set-up apart; a missing optional package or a failing peer
    becomes the row's status."""
    imported = ""
    try:
        if package and package not in sys.modules:
            t0 = time.perf_counter()
            importlib.import_module(package)
            imported = f"import {_seconds(time.perf_counter() - t0)}; "
        t0 = time.perf_counter()
        run, read, note = make()
    except ImportError as exc:
        row.status = f"not installed ({exc.name or exc}; {BENCH_EXTRA})"
        return row
    except Exception as exc:  # noqa: BLE001 (a peer's own failure is reported, not raised)
        row.status = f"failed: {type(exc).__name__}: {exc}"
        return row
    row.run = run
    row.read = read or np.asarray
    row.one_off = imported + f"set-up {_seconds(time.perf_counter() - t0)}" + (f"; {note}" if note else "")
    return row


# ------------------------------------------------------------------ closed form
def lean_p1(phi: np.ndarray) -> np.ndarray:
    """The P1 outputs and nothing else, written out for speed (the lower bound): with
    s u = B - C, n = k x u: s' = vB.u, omega3 = vB.n / s, s'' = aB.u + s omega3^2,
    alpha3 = (aB.n - 2 s' omega3) / s, D = C + CD u."""
    c, s_ = np.cos(phi), np.sin(phi)
    bx, by = AB * c - AC, AB * s_
    s = np.hypot(bx, by)
    ux, uy = bx / s, by / s
    vbx, vby = -OMEGA1 * AB * s_, OMEGA1 * AB * c
    abx = -ALPHA1 * AB * s_ - OMEGA1**2 * AB * c
    aby = ALPHA1 * AB * c - OMEGA1**2 * AB * s_
    s_dot = vbx * ux + vby * uy
    om3 = (vby * ux - vbx * uy) / s
    s_ddot = abx * ux + aby * uy + s * om3**2
    al3 = (aby * ux - abx * uy - 2 * s_dot * om3) / s
    return np.column_stack([np.arctan2(uy, ux), om3, al3, s_dot, s_ddot, -CD * om3 * uy, CD * om3 * ux,
                            CD * (-al3 * uy - om3**2 * ux), CD * (al3 * ux - om3**2 * uy)])


def lean_p2(th1: np.ndarray, th2: np.ndarray) -> np.ndarray:
    """The P2 outputs written out for speed: C moves as D (CD does not turn), so
    omega_AB r1 k x e1 + omega_BC r2 k x e2 = vD, solved by Cramer's rule, and the same
    matrix for the accelerations with aD + omega_AB^2 r1 e1 + omega_BC^2 r2 e2."""
    c1, s1, c2, s2 = np.cos(th1), np.sin(th1), np.cos(th2), np.sin(th2)
    det = R1 * R2 * (c1 * s2 - s1 * c2)
    w1 = R2 * (VD[0] * c2 + VD[1] * s2) / det
    w2 = -R1 * (VD[0] * c1 + VD[1] * s1) / det
    rx = AD[0] + w1**2 * R1 * c1 + w2**2 * R2 * c2
    ry = AD[1] + w1**2 * R1 * s1 + w2**2 * R2 * s2
    return np.column_stack([w1, w2, R2 * (rx * c2 + ry * s2) / det, -R1 * (rx * c1 + ry * s1) / det])


def closed_form_p1(phi: np.ndarray):
    return (lambda: lean_p1(phi)), None, ""


def closed_form_p2(th1: np.ndarray, th2: np.ndarray):
    return (lambda: lean_p2(th1, th2)), None, ""


# ------------------------------------------------------------------ pylinkage
def pylinkage_p1(poses: int):
    """R-RTR as Crank + FixedDyad (D on the line C -> B); link 3 from its points."""
    from pylinkage._numba_compat import HAS_NUMBA
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad
    from pylinkage.simulation import Linkage

    if not HAS_NUMBA:
        raise ImportError("numba is not installed", name="numba")
    step = 2 * math.pi / poses  # crank angle per step [rad]
    ground_a, ground_c = Ground(0.0, 0.0, name="A"), Ground(AC, 0.0, name="C")
    crank = Crank(anchor=ground_a, radius=AB, angular_velocity=step, initial_angle=-step, name="crank")
    point_d = FixedDyad(anchor1=ground_c, anchor2=crank.output, distance=CD, angle=0.0, name="D")
    linkage = Linkage([ground_a, ground_c, crank, point_d], name="R-RTR")
    linkage.set_input_velocity(crank, omega=OMEGA1, alpha=ALPHA1)
    linkage.compile()
    b0 = (AB * math.cos(-step), AB * math.sin(-step))
    u0 = np.subtract(b0, (AC, 0.0)) / math.dist(b0, (AC, 0.0))
    start = [(0.0, 0.0), (AC, 0.0), b0, (AC + CD * u0[0], CD * u0[1])]

    def run() -> np.ndarray:
        linkage.set_coords(start)
        P, V, A = linkage.step_fast_with_kinematics(iterations=poses)
        return _links_from_points(P, V, A)
    return run, None, ""


def _links_from_points(P: np.ndarray, V: np.ndarray, A: np.ndarray) -> np.ndarray:
    """pylinkage's points (poses, [A, C, B, D], 2) -> the P1 outputs; C is fixed.
    omega3 = r x vD / |r|^2 with r = D - C (likewise alpha3); s' = e.vB and
    s'' = e.aB + (|vB|^2 - s'^2) / s with s e = B - C."""
    r, vd, ad = P[:, 3] - P[:, 1], V[:, 3], A[:, 3]
    rr = r[:, 0] ** 2 + r[:, 1] ** 2
    b, vb, ab = P[:, 2] - P[:, 1], V[:, 2], A[:, 2]
    s = np.hypot(b[:, 0], b[:, 1])
    s_dot = (b[:, 0] * vb[:, 0] + b[:, 1] * vb[:, 1]) / s
    s_ddot = (b[:, 0] * ab[:, 0] + b[:, 1] * ab[:, 1]) / s + (vb[:, 0] ** 2 + vb[:, 1] ** 2 - s_dot**2) / s
    return np.column_stack([np.arctan2(r[:, 1], r[:, 0]), (r[:, 0] * vd[:, 1] - r[:, 1] * vd[:, 0]) / rr,
                            (r[:, 0] * ad[:, 1] - r[:, 1] * ad[:, 0]) / rr, s_dot, s_ddot, vd, ad])


# ------------------------------------------------------------------ sympy
def sympy_p1(phi: np.ndarray):
    """Loop A->B = A->C + s L3.x; positions by Newton on the lambdified residual."""
    import sympy as sp
    import sympy.physics.mechanics as me

    t = me.dynamicsymbols._t
    phi1, phi3, s = me.dynamicsymbols("phi1 phi3 s")
    N = me.ReferenceFrame("N")
    L1, L3 = N.orientnew("L1", "Axis", [phi1, N.z]), N.orientnew("L3", "Axis", [phi3, N.z])
    A = me.Point("A")
    C = A.locatenew("C", AC * N.x)
    loop = A.locatenew("B1", AB * L1.x).pos_from(A) - C.locatenew("B3", s * L3.x).pos_from(A)
    f = sp.Matrix([loop.dot(N.x), loop.dot(N.y)])
    x1, x3, xs, w1, w3, sd, a1, a3, sdd = sp.symbols("x1 x3 xs w1 w3 sd a1 a3 sdd")
    to_plain = [({phi1.diff(t, 2): a1, phi3.diff(t, 2): a3, s.diff(t, 2): sdd}),
                ({phi1.diff(t): w1, phi3.diff(t): w3, s.diff(t): sd}), ({phi1: x1, phi3: x3, s: xs})]

    def plain(e):
        for sub in to_plain:
            e = e.subs(sub)
        return e
    fq = plain(f)
    vel = sp.solve(list(plain(f.diff(t))), [w3, sd], dict=True)[0]
    acc = sp.solve(list(plain(f.diff(t, 2))), [a3, sdd], dict=True)[0]
    acc = {k: v.subs(vel) for k, v in acc.items()}
    vD = C.locatenew("D", CD * L3.x).pos_from(A).dt(N)
    aD = vD.dt(N)
    d_rates = [plain(vec.dot(e)) for vec in (vD, aD) for e in (N.x, N.y)]
    opts = {"modules": "math", "cse": True}
    f_res = sp.lambdify((x1, x3, xs), list(fq), **opts)
    f_jac = sp.lambdify((x1, x3, xs), fq.jacobian([x3, xs]).tolist(), **opts)
    f_vel = sp.lambdify((x1, x3, xs, w1), [vel[w3], vel[sd]], **opts)
    f_acc = sp.lambdify((x1, x3, xs, w1, a1), [acc[a3], acc[sdd]], **opts)
    f_d = sp.lambdify((x3, w3, a3), d_rates, **opts)
    angles = phi.tolist()

    def run() -> np.ndarray:
        out = np.empty((len(angles), 9))
        p3, sl = 0.0, AB - AC  # the pose at phi = 0, from a sketch
        for k, p in enumerate(angles):
            for _ in range(50):
                r0, r1 = f_res(p, p3, sl)
                if max(abs(r0), abs(r1)) < 1e-13:
                    break
                d3, ds = np.linalg.solve(np.array(f_jac(p, p3, sl)), np.array([r0, r1]))
                p3, sl = p3 - d3, sl - ds
            else:
                raise RuntimeError(f"Newton did not converge at {p} rad")
            om3, s_dot = f_vel(p, p3, sl, OMEGA1)
            al3, s_ddot = f_acc(p, p3, sl, OMEGA1, ALPHA1)
            out[k] = (p3, om3, al3, s_dot, s_ddot, *f_d(p3, om3, al3))
        return out
    return run, None, ""


def _sympy_p2_functions(modules: str):
    """Lambdified (th1, th2, vx, vy) -> (omega_AB, omega_BC) and
    (th1, th2, omega_AB, omega_BC, ax, ay) -> (alpha_AB, alpha_BC), CD fixed in angle."""
    import sympy as sp

    args_v, vel, args_a, acc = _sympy_p2_solved()
    opts = {"modules": modules, "cse": True}
    return sp.lambdify(args_v, vel, **opts), sp.lambdify(args_a, acc, **opts)


@functools.lru_cache(maxsize=1)
def _sympy_p2_solved() -> tuple:
    """The symbolic rates of P2 (derived once for both lambdified variants)."""
    import sympy as sp
    import sympy.physics.mechanics as me

    t = me.dynamicsymbols._t
    th1, th2, th3 = me.dynamicsymbols("th1 th2 th3")
    N = me.ReferenceFrame("N")
    A = me.Point("A")
    B = A.locatenew("B", R1 * N.orientnew("L1", "Axis", [th1, N.z]).x)
    C = B.locatenew("C", R2 * N.orientnew("L2", "Axis", [th2, N.z]).x)
    D = C.locatenew("D", R3 * N.orientnew("L3", "Axis", [th3, N.z]).x)
    x1, x2, w1, w2, a1, a2, vx, vy, ax, ay = sp.symbols("x1 x2 w1 w2 a1 a2 vx vy ax ay")
    sub = {th3.diff(t, 2): 0, th3.diff(t): 0, th1.diff(t, 2): a1, th2.diff(t, 2): a2,
           th1.diff(t): w1, th2.diff(t): w2}
    vD = D.pos_from(A).dt(N)
    aD = vD.dt(N)
    ev = [(vD.dot(N.x) - vx).subs(sub).subs({th1: x1, th2: x2}),
          (vD.dot(N.y) - vy).subs(sub).subs({th1: x1, th2: x2})]
    ea = [(aD.dot(N.x) - ax).subs(sub).subs({th1: x1, th2: x2}),
          (aD.dot(N.y) - ay).subs(sub).subs({th1: x1, th2: x2})]
    vel = sp.solve(ev, [w1, w2], dict=True)[0]
    acc = sp.solve(ea, [a1, a2], dict=True)[0]
    return (x1, x2, vx, vy), [vel[w1], vel[w2]], (x1, x2, w1, w2, ax, ay), [acc[a1], acc[a2]]


def sympy_p2(th1: np.ndarray, th2: np.ndarray):
    f_vel, f_acc = _sympy_p2_functions("math")
    poses = list(zip(th1.tolist(), th2.tolist()))

    def run() -> np.ndarray:
        out = np.empty((len(poses), 4))
        for k, (a, b) in enumerate(poses):
            w1, w2 = f_vel(a, b, *VD)
            out[k] = (w1, w2, *f_acc(a, b, w1, w2, *AD))
        return out
    return run, None, ""


def sympy_p2_vectorized(th1: np.ndarray, th2: np.ndarray):
    f_vel, f_acc = _sympy_p2_functions("numpy")

    def run() -> np.ndarray:
        w1, w2 = f_vel(th1, th2, *VD)
        return np.column_stack([w1, w2, *f_acc(th1, th2, w1, w2, *AD)])
    return run, None, ""


# ------------------------------------------------------------------ Pinocchio
_REVOLUTE = '<axis xyz="0 0 1"/><limit lower="-1e3" upper="1e3" effort="0" velocity="1e3"/>'
_JOINT = ('<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
          '<origin xyz="{x!r} 0 0"/>{axis}</joint>')


def _urdf(name: str, joints: list[tuple[str, str, str, str, float]]) -> str:
    """URDF text of a tree given as (joint, kind, parent, child, x offset [m]) rows."""
    links = {"world"} | {j[3] for j in joints}
    body = "".join(f'<link name="{n}"/>' for n in sorted(links))
    for joint, kind, parent, child, x in joints:
        axis = {"revolute": _REVOLUTE, "prismatic": _REVOLUTE.replace("0 0 1", "1 0 0"), "fixed": ""}[kind]
        body += _JOINT.format(name=joint, kind=kind, parent=parent, child=child, x=x, axis=axis)
    return f'<?xml version="1.0"?><robot name="{name}">{body}</robot>'


def pinocchio_p1(phi: np.ndarray):
    """q = (crank, link 3, slide s along link 3); the cut: the crank's B on the slider's B."""
    import pinocchio as pin

    model = pin.buildModelFromXML(_urdf("rrtr", [
        ("jA", "revolute", "world", "crank", 0.0), ("B_fix", "fixed", "crank", "B_crank", AB),
        ("jC", "revolute", "world", "link3", AC), ("js", "prismatic", "link3", "slider", 0.0),
        ("D_fix", "fixed", "link3", "D", CD)]))
    data = model.createData()
    fb, fs, fd = (model.getFrameId(n) for n in ("B_crank", "slider", "D"))
    lwa = pin.LOCAL_WORLD_ALIGNED
    dep = [1, 2]
    angles = phi.tolist()

    def close(q: np.ndarray) -> np.ndarray:
        for _ in range(50):
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
            r = data.oMf[fb].translation[:2] - data.oMf[fs].translation[:2]
            J = (pin.getFrameJacobian(model, data, fb, lwa) - pin.getFrameJacobian(model, data, fs, lwa))[:2]
            if np.max(np.abs(r)) < 1e-13:
                return J
            q[dep] -= np.linalg.solve(J[:, dep], r)
        raise RuntimeError(f"Newton did not converge at {q[0]} rad")

    def run() -> np.ndarray:
        out = np.empty((len(angles), 9))
        q = np.array([0.0, 0.0, AB - AC])  # the pose at phi = 0, from a sketch
        for k, p in enumerate(angles):
            q[0] = p
            J = close(q)
            v = np.array([OMEGA1, 0.0, 0.0])
            v[dep] = np.linalg.solve(J[:, dep], -J[:, 0] * OMEGA1)
            a = np.array([ALPHA1, 0.0, 0.0])
            pin.forwardKinematics(model, data, q, v, a)
            drift = (pin.getFrameClassicalAcceleration(model, data, fb, lwa).linear[:2]
                     - pin.getFrameClassicalAcceleration(model, data, fs, lwa).linear[:2])
            a[dep] = np.linalg.solve(J[:, dep], -drift)
            pin.forwardKinematics(model, data, q, v, a)
            vd = pin.getFrameVelocity(model, data, fd, lwa).linear
            ad = pin.getFrameClassicalAcceleration(model, data, fd, lwa).linear
            out[k] = (q[1], v[1], a[1], v[2], a[2], vd[0], vd[1], ad[0], ad[1])
        return out
    return run, None, ""


def pinocchio_p2(th1: np.ndarray, th2: np.ndarray):
    """Serial 3R arm; rows vx, vy, wz of D's frame Jacobian; the drift from D's classical
    acceleration at zero joint acceleration."""
    import pinocchio as pin

    model = pin.buildModelFromXML(_urdf("arm", [
        ("jA", "revolute", "world", "AB", 0.0), ("jB", "revolute", "AB", "BC", R1),
        ("jC", "revolute", "BC", "CD", R2), ("D_fix", "fixed", "CD", "D", R3)]))
    data = model.createData()
    fd = model.getFrameId("D")
    lwa = pin.LOCAL_WORLD_ALIGNED
    rows = [0, 1, 5]
    qs = [np.array([a, b - a, TH_CD - b]) for a, b in zip(th1.tolist(), th2.tolist())]
    v_task, a_task, zero = np.array([VD[0], VD[1], 0.0]), np.array([AD[0], AD[1], 0.0]), np.zeros(3)

    def run() -> np.ndarray:
        out = np.empty((len(qs), 4))
        for k, q in enumerate(qs):
            J = pin.computeFrameJacobian(model, data, q, fd, lwa)[rows]
            v = np.linalg.solve(J, v_task)
            pin.forwardKinematics(model, data, q, v, zero)
            acc = pin.getFrameClassicalAcceleration(model, data, fd, lwa)
            a = np.linalg.solve(J, a_task - np.array([acc.linear[0], acc.linear[1], acc.angular[2]]))
            out[k] = (v[0], v[0] + v[1], a[0], a[0] + a[1])
        return out
    return run, None, ""


# ------------------------------------------------------------------ pinmech
def _pinmech_p1_sweep():
    import pinmech

    return pinmech, pinmech.Sweep.from_scene(pinmech.Scene.load(SCENE_P1))


def _pinmech_p1_row(motion) -> tuple:
    """P1 outputs from a pinmech Motion (B_slider's coordinate is -s)."""
    link3, d, slider = motion.links["link3"], motion.points["D"], motion.joints["B_slider"]
    return (link3.angle, link3.angular_velocity[2], link3.angular_acceleration[2], -slider.v, -slider.a,
            d.velocity[0], d.velocity[1], d.acceleration[0], d.acceleration[1])


def pinmech_p1_chunks(phi: np.ndarray):
    """`Sweep.chunks`: q, v, a of every joint as arrays; link 3 and D read after the timing."""
    pinmech, sweep = _pinmech_p1_sweep()

    def run():
        return [(c.solution.q, c.solution.v, c.solution.a) for c in sweep.chunks(phi)]

    def read(chunks) -> np.ndarray:
        data = sweep.mechanism.model.createData()
        return np.array([_pinmech_p1_row(pinmech.evaluate_motion(
            sweep.mechanism, data, q, v, a, points=["D"], links=["link3"]))
            for Q, V, A in chunks for q, v, a in zip(Q, V, A)])
    return run, read, ""


def pinmech_p1_paths(phi: np.ndarray):
    """`Sweep.chunks` and `frame_paths` of link 3 and D on each chunk: every P1 output,
    computed in the timing, through the public API."""
    pinmech, sweep = _pinmech_p1_sweep()
    mechanism = sweep.mechanism
    slide = mechanism.joint("B_slider").idx_v

    def run() -> np.ndarray:
        rows = []
        for c in sweep.chunks(phi):
            s = c.solution
            f = pinmech.frame_paths(mechanism, ["link3", "D"], s.q, s.v, s.a)
            R = f.rotation[:, 0]
            rows.append(np.column_stack([np.arctan2(R[:, 1, 0], R[:, 0, 0]), f.angular_velocity[:, 0, 2],
                                         f.angular_acceleration[:, 0, 2], -s.v[:, slide], -s.a[:, slide],
                                         f.velocity[:, 1, :2], f.acceleration[:, 1, :2]]))
        return np.concatenate(rows)
    return run, None, ""


def pinmech_p1_core_follow(phi: np.ndarray):
    """The compiled core's `follow` alone, from the sweep's first pose: the C++ loop
    (Pinocchio's kinematics, the closure rows, the corrector, rates, signature, condition
    number) with no Python between poses. Its time is the floor the Python layer adds to."""
    from pinmech.solve.core import core_for
    from pinmech.solve.cycle import _Cycle

    pinmech, sweep = _pinmech_p1_sweep()
    solver = sweep.solver
    compiled = core_for(solver)
    if compiled is None:
        raise RuntimeError("the compiled core does not take this model")
    cycle = _Cycle(solver, sweep.driver, sweep.drivers.q.copy(), sweep.drivers.v.copy(), sweep.drivers.a.copy(),
                   None, "predictor", True, 1)
    first = cycle.chunk(0, phi[:1])
    ref, path = cycle.ref, cycle.path
    w, alpha = float(sweep.drivers.v[0]), float(sweep.drivers.a[0])

    def run():
        done, _, Q, D1, D2, _ = compiled.follow(ref.p, ref.q, ref.d1, ref.d2, list(ref.signs), ref.condition,
                                                path.x0, path.d, path.unit, phi[1:], solver.max_condition)
        return [(np.vstack([first.solution.q, Q]), np.vstack([first.solution.v, D1 * w]),
                 np.vstack([first.solution.a, D2 * (w * w) + D1 * alpha]))]

    _, read, _ = pinmech_p1_chunks(phi)
    return run, read, "from the sweep's first pose (solved in set-up)"


def pinocchio_passes_p1(phi: np.ndarray):
    """Pinocchio's passes alone at every P1 pose (its solved q and v), through the compiled
    core: joint Jacobians twice (the Newton step at the predicted q, then the certifying
    residual and the velocity Jacobian at the corrected q) and the kinematics at (q, v, 0)
    once (the acceleration drift). No certified closed-loop answer calls Pinocchio less."""
    from pinmech.solve.core import core_for

    pinmech, sweep = _pinmech_p1_sweep()
    compiled = core_for(sweep.solver)
    if compiled is None:
        raise RuntimeError("the compiled core does not take this model")
    chunks = list(sweep.chunks(phi))
    Q = np.concatenate([c.solution.q for c in chunks])
    V = np.concatenate([c.solution.v for c in chunks])
    return (lambda: compiled.pinocchio_passes(Q, V, 2)), None, "q and v solved in set-up"


def pinmech_p1_motion(phi: np.ndarray):
    """`Sweep.chunks` and `evaluate_motion(points=[D], links=[link3])` at every pose."""
    pinmech, sweep = _pinmech_p1_sweep()
    mechanism, data = sweep.mechanism, sweep.solver.data

    def run() -> np.ndarray:
        rows = []
        for c in sweep.chunks(phi):
            s = c.solution
            rows += [_pinmech_p1_row(pinmech.evaluate_motion(
                mechanism, data, q, v, a, points=["D"], links=["link3"])) for q, v, a in zip(s.q, s.v, s.a)]
        return np.array(rows)
    return run, None, ""


def pinmech_p2(th1: np.ndarray, th2: np.ndarray, many: bool = False):
    """`RateSolver.solve(q)` pose by pose, or `RateSolver.solve_many` on every pose at once
    (`many`): D's x, y at (1, 0) m/s, CD's wz at 0."""
    import pinmech

    mechanism = pinmech.Mechanism.from_urdf(URDF_P2)
    solver = pinmech.RateSolver(mechanism, [
        pinmech.Task("D", ("x", "y"), np.array(VD), np.array(AD)),
        pinmech.Task("CD", ("wz",), np.zeros(1), np.zeros(1))])
    ja, jb, jc = (mechanism.joint(n) for n in "ABC")
    qs = []
    for a, b in zip(th1.tolist(), th2.tolist()):
        q = mechanism.neutral()
        rel = (np.array([a, b - a, TH_CD - b]) + math.pi) % (2 * math.pi) - math.pi  # URDF limits +-pi
        q[ja.idx_q], q[jb.idx_q], q[jc.idx_q] = rel
        qs.append(q)
    ia, ib = ja.idx_v, jb.idx_v

    def run() -> np.ndarray:
        out = np.empty((len(qs), 4))
        for k, q in enumerate(qs):
            r = solver.solve(q)
            out[k] = (r.v[ia], r.v[ia] + r.v[ib], r.a[ia], r.a[ia] + r.a[ib])
        return out

    def run_many() -> np.ndarray:
        r = solver.solve_many(Q)
        return np.column_stack([r.v[:, ia], r.v[:, ia] + r.v[:, ib], r.a[:, ia], r.a[:, ia] + r.a[:, ib]])

    Q = np.array(qs)
    return (run_many if many else run), None, ""


def pinocchio_passes_p2(th1: np.ndarray, th2: np.ndarray):
    """Pinocchio's passes alone at every P2 pose, through the compiled core: the joint
    Jacobians once (the rate problem's matrix) and the kinematics at (q, v, 0) once (the
    acceleration drift). No answer to the rate problem calls Pinocchio less."""
    run_many, _, _ = pinmech_p2(th1, th2, many=True)
    cells = {type(c.cell_contents).__name__: c.cell_contents for c in run_many.__closure__}
    solver, Q = cells["RateSolver"], cells["ndarray"]
    compiled = solver._compiled()
    V = solver.solve_many(Q).v
    return (lambda: compiled.pinocchio_passes(Q, V, 1)), None, "v solved in set-up"


# ------------------------------------------------------------------ measuring
def rows_for(poses: int) -> tuple[list[Row], dict]:
    """Every method on P1 and P2, built (not yet timed), and the closed forms."""
    phi, fine = p1_angles(poses), p1_angles(10 * poses)
    th1, th2 = p2_angles(poses)
    refs = {("P1", poses): p1_closed_form(phi), ("P1", 10 * poses): p1_closed_form(fine),
            ("P2", poses): p2_closed_form(th1, th2)}
    plan = [
        ("P1", "closed form, vectorized numpy (lower bound)", poses, None, lambda: closed_form_p1(phi)),
        ("P1", "pylinkage + numba, step_fast_with_kinematics", poses, "pylinkage", lambda: pylinkage_p1(poses)),
        ("P1", "sympy.physics.mechanics, lambdify(cse) math, Newton", poses, "sympy", lambda: sympy_p1(phi)),
        ("P1", "Pinocchio from a Python script", poses, "pinocchio", lambda: pinocchio_p1(phi)),
        ("P1", "pinmech Sweep.chunks (q, v, a)", poses, "pinmech", lambda: pinmech_p1_chunks(phi)),
        ("P1", "pinmech Sweep.chunks + frame_paths (every output)", poses, None, lambda: pinmech_p1_paths(phi)),
        ("P1", "pinmech Sweep.chunks + evaluate_motion", poses, None, lambda: pinmech_p1_motion(phi)),
        ("P1", "pinmech compiled core's follow alone (C++ floor)", poses, None, lambda: pinmech_p1_core_follow(phi)),
        ("P1", f"{PASSES} (2 joint Jacobians + 1 kinematics a pose)", poses, None,
         lambda: pinocchio_passes_p1(phi)),
        ("P1", "pinmech Sweep.chunks (q, v, a)", 10 * poses, None, lambda: pinmech_p1_chunks(fine)),
        ("P1", "pinmech Sweep.chunks + evaluate_motion", 10 * poses, None, lambda: pinmech_p1_motion(fine)),
        ("P2", "closed form, vectorized numpy (lower bound)", poses, None,
         lambda: closed_form_p2(th1, th2)),
        ("P2", "sympy.physics.mechanics, lambdify(cse) math, per pose", poses, None, lambda: sympy_p2(th1, th2)),
        ("P2", "sympy.physics.mechanics, lambdify(cse) numpy, vectorized", poses, None,
         lambda: sympy_p2_vectorized(th1, th2)),
        ("P2", "Pinocchio from a Python script", poses, None, lambda: pinocchio_p2(th1, th2)),
        ("P2", "pinmech RateSolver.solve_many", poses, None, lambda: pinmech_p2(th1, th2, many=True)),
        ("P2", "pinmech RateSolver.solve", poses, None, lambda: pinmech_p2(th1, th2)),
        ("P2", f"{PASSES} (1 joint Jacobian + 1 kinematics a pose)", poses, None,
         lambda: pinocchio_passes_p2(th1, th2)),
    ]
    rows = [build(Row(p, m, n, is_pinmech=m.startswith("pinmech"), is_bound=m.startswith(PASSES)), package, make)
            for p, m, n, package, make in plan]
    rows.insert(2, Row("P2", "pylinkage", poses, status="no inverse-rate API (forward-driven points only)"))
    rows.sort(key=lambda r: r.problem)
    return rows, refs


def warm_up(row: Row, ref: np.ndarray, sample_time: float) -> None:
    """First call (numba compiles here) reported apart; the error from a second call;
    the number of calls per timed sample from its time."""
    try:
        t0 = time.perf_counter()
        row.run()
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        raw = row.run()
        second = time.perf_counter() - t0
        if not row.is_bound:  # a bound gives no answer to compare
            row.error = largest_error(row.read(raw), ref, angle_columns=(0,) if row.problem == "P1" else ())
    except Exception as exc:  # noqa: BLE001 (a peer that fails is a row that says so)
        row.run, row.status = None, f"failed: {type(exc).__name__}: {exc}"
        return
    row.calls = max(1, math.ceil(sample_time / max(second, 1e-9)))
    if first > 2 * second + 0.01:  # compiling (numba), loading caches, first imports
        row.one_off += f"; first call {_seconds(first)} (then {_seconds(second)})"


def measure(poses: int = 360, rounds: int = 7, sample_time: float = 0.05) -> list[Row]:
    """Build, warm up and time every method on P1 and P2 in this process."""
    rows, refs = rows_for(poses)
    for row in rows:
        if row.run is not None:
            warm_up(row, refs[row.problem, row.poses], sample_time)
    time_rounds(rows, rounds)
    return rows


# ------------------------------------------------------------------ report
def _version(dist: str) -> str:
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "not installed"


def environment() -> str:
    names = ("pinmech", "pin", "numpy", "pylinkage", "numba", "sympy")
    versions = ", ".join(f"{n} {_version(n)}" for n in names)
    return f"Python {platform.python_version()}, {versions}; {machine()}"


def _cell_time(row: Row) -> tuple[str, str]:
    if not row.times:
        return "-", "-"
    return f"{row.median_us:.3g}", f"{min(row.times) * 1e6:.3g} - {max(row.times) * 1e6:.3g}"


def table(rows: list[Row]) -> str:
    lines = [("| problem | method | poses | us per pose (median) | spread (fastest - slowest round) "
             "| largest error vs closed form | not in the time |"),
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        median, spread = _cell_time(r)
        error = "-" if math.isnan(r.error) else f"{r.error:.1e}"
        lines.append(f"| {r.problem} | {r.method} | {r.poses} | {median} | {spread} | {error} "
                     f"| {r.status or r.one_off} |")
    return "\n".join(lines)


def comparisons(rows: list[Row], poses: int) -> list[str]:
    """Where pinmech stands against the fastest peer, per problem, at `poses`: its time
    and error beside the peer's, and how much of that peer's time Pinocchio's passes take."""
    out = []
    for problem in ("P1", "P2"):
        timed = [r for r in rows if r.problem == problem and r.poses == poses and r.times]
        peers = [r for r in timed if not (r.is_pinmech or r.is_bound or r.method.startswith("closed form"))]
        ours = [r for r in timed if r.method in ANSWERS]  # the full answer, as the peers give it
        if not peers or not ours:
            out.append(f"- {problem}: no peer or no pinmech time to compare")
            continue
        best = min(peers, key=lambda r: r.median_us)
        ours = ours[0]
        out.append(f"- {problem}, {poses} poses: pinmech ({ours.method}) {ours.median_us:.3g} us per pose at "
                   f"{ours.error:.1e}; fastest peer {best.method} {best.median_us:.3g} us at {best.error:.1e}: "
                   f"pinmech takes {ours.median_us / best.median_us:.3g} x its time")
        bound = [r for r in timed if r.is_bound]
        if bound:
            share = bound[0].median_us
            room = (f"pinmech's own work above Pinocchio's would have to fit in {best.median_us - share:.3g} us"
                    if share < best.median_us else "no pinmech answer can be faster: Pinocchio's share alone "
                    "is slower than the peer's whole answer")
            out.append(f"  Pinocchio's passes alone take {share:.3g} us per pose, {share / best.median_us:.3g} x "
                       f"the fastest peer's whole answer: {room}.")
    return out + [line for line, _ in ratios(rows, poses)]


#: One row's time against another's, as the report states it: (problem, pinmech's row, the
#: reference row, the reference's name, and the project's limit on the ratio, which only
#: the exit code reads).
RATIOS = (
    ("P1", ANSWERS[0], lambda r: r.method.startswith("pylinkage + numba"), "pylinkage + numba", 1.0),
    ("P2", ANSWERS[1], lambda r: r.is_bound, "Pinocchio's passes alone", 1.5),
    ("P1", ANSWERS[0], lambda r: r.method == FLOOR, "the compiled core's C++ loop alone", 3.0),
)


def ratios(rows: list[Row], poses: int) -> list[tuple[str, float]]:
    """Each of RATIOS at `poses`: the report's line (pinmech's time over the reference's),
    and the project's limit on that ratio when the ratio is over it (else 0)."""
    out = []
    for problem, method, is_reference, name, limit in RATIOS:
        timed = [r for r in rows if r.problem == problem and r.poses == poses and r.times]
        ours = [r for r in timed if r.method == method]
        reference = [r for r in timed if is_reference(r)]
        if ours and reference:
            ratio = ours[0].median_us / reference[0].median_us
            out.append((f"- {problem}, {poses} poses: {method} {ours[0].median_us:.3g} us per pose, "
                        f"{ratio:.3g} x {name} ({reference[0].median_us:.3g} us)", limit if ratio > limit else 0.0))
    return out


def missed_targets(rows: list[Row], poses: int) -> list[str]:
    """The project's speed targets this run misses (the exit code; the report states none):
    pinmech's full answer faster than every peer at <= 1e-13 absolute, and each of RATIOS."""
    missed = []
    for problem in ("P1", "P2"):
        timed = [r for r in rows if r.problem == problem and r.poses == poses and r.times]
        peers = [r for r in timed if not (r.is_pinmech or r.is_bound or r.method.startswith("closed form"))]
        ours = [r for r in timed if r.method in ANSWERS]
        if peers and ours:
            best = min(peers, key=lambda r: r.median_us)
            if not (ours[0].median_us < best.median_us and ours[0].error <= 1e-13):
                missed.append(f"{problem}: not faster than every peer at <= 1e-13 ({best.method})")
    return missed + [f"{line[2:]}: over {over:g} x" for line, over in ratios(rows, poses) if over]


def markdown(rows: list[Row], poses: int, rounds: int) -> str:
    p1 = np.max(np.abs(p1_closed_form(p1_angles(poses))[:, 1:]))
    p2 = np.max(np.abs(p2_closed_form(*p2_angles(poses))))
    head = (f"P1 and P2 at {poses} poses (P1 also at {10 * poses} for pinmech), one process, {rounds} "
            f"interleaved rounds; {environment()}. Errors are absolute, in SI units; the rates reach "
            f"{p1:.3g} (P1) and {p2:.3g} (P2).")
    return "\n".join([head, "", table(rows), "", *comparisons(rows, poses), ""])


def main(argv: list[str] | None = None) -> list[Row]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=360, help="poses per problem (360: 1 degree apart)")
    parser.add_argument("--rounds", type=int, default=7, help="interleaved timing rounds")
    parser.add_argument("--sample-time", type=float, default=0.05,
                        help="least time of one timed sample [s] (fast methods repeat their call)")
    parser.add_argument("--numba-cold", action="store_true",
                        help="empty numba cache: pylinkage's first call compiles its kernels")
    parser.add_argument("--out", type=Path, help="also write the Markdown report to this file")
    args = parser.parse_args(argv)
    if args.poses < 2 or args.rounds < 1 or args.sample_time < 0:
        parser.error("--poses must be at least 2, --rounds at least 1, --sample-time not negative")
    if args.numba_cold:
        cache = tempfile.mkdtemp(prefix="pinmech-bench-numba-")
        atexit.register(shutil.rmtree, cache, ignore_errors=True)
        os.environ["NUMBA_CACHE_DIR"] = cache  # read when numba is first imported
    rows = measure(args.poses, args.rounds, args.sample_time)
    report = markdown(rows, args.poses, args.rounds)
    print(report)
    if args.out:
        args.out.write_text(report)
    return rows


if __name__ == "__main__":
    _rows = main()
    _missed = missed_targets(_rows, max(r.poses for r in _rows if r.problem == "P2"))
    for _line in _missed:
        print(f"target missed: {_line}", file=sys.stderr)
    sys.exit(1 if _missed else 0)
