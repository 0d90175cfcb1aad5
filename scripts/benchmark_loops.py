"""Chains of k four-bar loops in series, driven by one crank: does a sweep's cost grow
linearly with the number of loops? (The project's target, read by the exit code alone:
the longest chain at most k x one loop, every angle within 1e-12 rad of the closed form.)

The mechanism (`chain_urdf`): k planar four-bars side by side on the x axis, loop i
(i = 0 .. k-1) with its input pivot at G_i = (i d, 0) and its output pivot at G_{i+1}.
Loop 0's input link is the crank, the one driver (joint O0); loop i's output link, which
turns about G_{i+1} (joint O{i+1}), is loop i+1's input link: one rigid body carrying
loop i's output pin B_i at c along its x axis and loop i+1's coupler pin A_{i+1} at a on
the same axis. Each loop: coupler C_i on a revolute joint A_i at a on its input link,
cut at B_i (a `<constraint>` between C_i at b and the output link at c). So the loops
are coupled in series: loop i's two closure rows involve its input link's angle (loop
i-1's output) and its own coupler and output angles, and the dependent Jacobian
(coupler and output joints of every loop) is block lower-triangular with k 2x2 blocks.

Proportions: a Grashof double crank (drag link) by default, a = 0.10 m input,
b = 0.12 m coupler, c = 0.11 m output, d = 0.04 m ground (d shortest, s + l = 0.16 <=
p + q = 0.21): input and output turn fully and the transmission angle stays within
[29.8, 150.2] degrees for every input angle, so every loop of the chain is regular over a
full turn of the crank, and the motion reaches the last loop undamped (the output's
speed ratio stays within 0.6 - 1.7 of the crank's over the chain). A chain of
crank-rockers (`--lengths 0.04 0.12 0.08 0.10`, the README's four-bar) is regular too, but
each rocker swings less than its input, so the motion dies out along the chain (the 16th
output swings 1e-5 rad): a weaker test of the chain.

Sweep: the crank from 0 to 359 degrees, 1 degree apart (`--poses`), at 1 rad/s and no
angular acceleration, from a reference assembled at 0 (the closed form's pose, so the
branch is known). Timing, in this one process, interleaved: after a warm-up, each round
times every (k, path) once, in an order rotated from round to round, garbage collection
paused; the table gives the median time per pose over the rounds and its spread (fastest
and slowest round). One path: pinmech's compiled core (pinmech/solve/core.py), the one
engine.

Correctness: every loop's coupler and output angles (and their rates) against the closed
form of the four-bar (`chain_closed_form`: the law of cosines, loop after loop, numpy
only), largest absolute angle difference over every pose and loop [rad]; rates as the
largest difference relative to the largest rate of the chain.

Optional (`--callgrind`): instructions per pose under valgrind's callgrind (deterministic),
for k = 1 and 16 with and without the core: the slope between a sweep of 121 and one of
361 poses (the start-up, the same in both, cancels), PYTHONHASHSEED=0.

Run: python scripts/benchmark_loops.py [--loops 1 2 4 8 16] [--poses 360] [--rounds 7]
     [--out FILE.md] [--callgrind]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

import numpy as np

from interleave import machine, time_rounds

LOOPS = (1, 2, 4, 8, 16)
#: Drag link: input a, coupler b, output c, ground d [m] (Grashof, ground shortest).
LENGTHS = (0.10, 0.12, 0.11, 0.04)
#: The assembly: +1 puts B_i to the left of the directed line A_i -> G_{i+1}.
BRANCH = +1
OMEGA = 1.0  # crank speed [rad/s]
ALPHA = 0.0  # crank acceleration [rad/s^2]
PATHS = ("core",)

_LINK = ('<link name="{0}"><inertial><mass value="1"/>'
         '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>')
_PIN = '<axis xyz="0 0 1"/>'


# ------------------------------------------------------------------ the mechanism
def chain_urdf(k: int, lengths: tuple[float, float, float, float] = LENGTHS) -> str:
    """URDF text of k four-bar loops in series (see the module docstring): links L0 (the
    crank), L1 .. Lk (each the output of loop i-1 and the input of loop i) and couplers
    C0 .. C{k-1}; joints O0 .. Ok (ground pivots, O0 the driver) and A0 .. A{k-1}
    (couplers on their input links); cuts B0 .. B{k-1}. Every joint is continuous."""
    if k < 1:
        raise ValueError(f"a chain needs at least one loop, got k = {k}")
    a, b, c, d = lengths
    links = [f"L{i}" for i in range(k + 1)] + [f"C{i}" for i in range(k)]
    parts = ['<link name="ground"/>', *(_LINK.format(n) for n in links)]
    for i in range(k + 1):
        parts.append(f'<joint name="O{i}" type="continuous"><parent link="ground"/><child link="L{i}"/>'
                     f'<origin xyz="{i * d!r} 0 0"/>{_PIN}</joint>')
    for i in range(k):
        parts.append(f'<joint name="A{i}" type="continuous"><parent link="L{i}"/><child link="C{i}"/>'
                     f'<origin xyz="{a!r} 0 0"/>{_PIN}</joint>')
        parts.append(f'<constraint name="B{i}" type="revolute">'
                     f'<parent link="C{i}"/> <parent_origin xyz="{b!r} 0 0"/> <parent_axis xyz="0 0 1"/>'
                     f'<child link="L{i + 1}"/> <child_origin xyz="{c!r} 0 0"/> <child_axis xyz="0 0 1"/>'
                     f'</constraint>')
    body = "\n  ".join(parts)
    return f'<?xml version="1.0"?>\n<robot name="four_bar_chain_{k}">\n  {body}\n</robot>\n'


@dataclass(frozen=True)
class ChainMotion:
    """Absolute angles and rates of a chain, (poses, k + 1) for the links L0 .. Lk and
    (poses, k) for the couplers C0 .. C{k-1} [rad, rad/s, rad/s^2]."""

    phi: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    theta3: np.ndarray
    omega3: np.ndarray
    alpha3: np.ndarray


def four_bar_step(phi, omega, alpha, a: float, b: float, c: float, d: float, branch: int = BRANCH):
    """One loop with its input pivot at the origin and its output pivot at (d, 0), the
    input link at angle phi (rate omega, acceleration alpha): (theta3, theta4, omega3,
    omega4, alpha3, alpha4) of the coupler and the output link, numpy only.

    Positions by the law of cosines in the triangle A G B (A = a e(phi), G = (d, 0),
    |GB| = c, |AB| = b): theta4 = angle of G->A + branch * gamma with
    cos gamma = (c^2 + |GA|^2 - b^2) / (2 c |GA|), theta3 = angle of A->B.
    Rates from a e(phi) + b e(theta3) = d x + c e(theta4) differentiated and dotted with
    e(theta3) and e(theta4) (e(x).e(y) = cos(x - y), e'(x).e(y) = sin(y - x)):
        omega4 = a omega sin(theta3 - phi) / (c sin(theta3 - theta4))
        omega3 = a omega sin(theta4 - phi) / (b sin(theta3 - theta4))
        alpha4 = (a alpha sin(theta3 - phi) - a omega^2 cos(theta3 - phi) - b omega3^2
                  + c omega4^2 cos(theta4 - theta3)) / (c sin(theta3 - theta4))
        alpha3 = (a omega^2 cos(theta4 - phi) - a alpha sin(theta4 - phi) + b omega3^2 cos(theta3 - theta4)
                  - c omega4^2) / (b sin(theta4 - theta3))
    """
    ax, ay = a * np.cos(phi), a * np.sin(phi)
    gx, gy = ax - d, ay  # G -> A
    L = np.hypot(gx, gy)
    cos_g = (c * c + L * L - b * b) / (2.0 * c * L)
    if np.any(np.abs(cos_g) > 1.0):
        raise ValueError("the loop cannot close at some input angle")
    th4 = np.arctan2(gy, gx) + branch * np.arccos(cos_g)
    bx, by = d + c * np.cos(th4), c * np.sin(th4)
    th3 = np.arctan2(by - ay, bx - ax)
    w4 = a * omega * np.sin(th3 - phi) / (c * np.sin(th3 - th4))
    w3 = a * omega * np.sin(th4 - phi) / (b * np.sin(th3 - th4))
    al4 = (a * alpha * np.sin(th3 - phi) - a * omega**2 * np.cos(th3 - phi) - b * w3**2
           + c * w4**2 * np.cos(th4 - th3)) / (c * np.sin(th3 - th4))
    al3 = (a * omega**2 * np.cos(th4 - phi) - a * alpha * np.sin(th4 - phi) + b * w3**2 * np.cos(th3 - th4)
           - c * w4**2) / (b * np.sin(th4 - th3))
    return th3, th4, w3, w4, al3, al4


def chain_closed_form(theta, k: int, omega: float = OMEGA, alpha: float = ALPHA,
                      lengths: tuple[float, float, float, float] = LENGTHS, branch: int = BRANCH) -> ChainMotion:
    """The chain at crank angles theta, loop after loop: loop i's output is loop i+1's
    input (the same link; the ground pivots shifted by d do not change the angles)."""
    phi = np.atleast_1d(np.asarray(theta, dtype=float))
    w, al = np.full_like(phi, omega), np.full_like(phi, alpha)
    cols = {name: [] for name in ("phi", "omega", "alpha", "theta3", "omega3", "alpha3")}
    cols["phi"].append(phi), cols["omega"].append(w), cols["alpha"].append(al)
    for _ in range(k):
        th3, phi, w3, w, al3, al = four_bar_step(phi, w, al, *lengths, branch=branch)
        for name, x in (("phi", phi), ("omega", w), ("alpha", al), ("theta3", th3), ("omega3", w3),
                        ("alpha3", al3)):
            cols[name].append(x)
    return ChainMotion(**{name: np.column_stack(x) for name, x in cols.items()})


def wrap(x: np.ndarray) -> np.ndarray:
    """Angles to [-pi, pi)."""
    return (x + math.pi) % (2.0 * math.pi) - math.pi


# ------------------------------------------------------------------ pinmech
def chain_solver(k: int, lengths: tuple[float, float, float, float] = LENGTHS, folder: Path | None = None):
    """(mechanism, LoopSolver driven at O0) of the k-loop chain, its reference assembled at
    crank angle 0 from the closed form's pose."""
    import pinmech

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(folder or tmp) / f"four_bar_chain_{k}.urdf"
        path.write_text(chain_urdf(k, lengths), encoding="utf-8")
        mech = pinmech.Mechanism.from_urdf(path)
    solver = pinmech.LoopSolver(mech, ["O0"])
    solver.set_reference([0.0], chain_guess(mech, chain_closed_form(0.0, k, lengths=lengths), 0))
    return mech, solver


def chain_guess(mech, cf: ChainMotion, pose: int) -> np.ndarray:
    """The configuration of pose `pose` of a closed form (relative joint angles)."""
    q = mech.neutral()
    k = cf.theta3.shape[1]
    for i in range(k + 1):
        mech.set_coordinate(q, f"O{i}", float(cf.phi[pose, i]))
    for i in range(k):
        mech.set_coordinate(q, f"A{i}", float(wrap(cf.theta3[pose, i] - cf.phi[pose, i])))
    return q


def sweep(solver, thetas: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, v, a of every pose of a sweep of the crank through thetas."""
    from pinmech.solve.cycle import solve_range

    chunks = list(solve_range(solver, "O0", thetas, driver_q=np.zeros(1), driver_v=np.array([OMEGA]),
                              driver_a=np.array([ALPHA])))
    for c in chunks:
        if c.errors:
            j, err = next(iter(c.errors.items()))
            raise RuntimeError(f"pose {c.start + j} failed: {err}")
    return tuple(np.concatenate([getattr(c.solution, x) for c in chunks]) for x in ("q", "v", "a"))


def chain_errors(mech, q: np.ndarray, v: np.ndarray, a: np.ndarray, cf: ChainMotion) -> tuple[float, float, float]:
    """Largest |angle - closed form| [rad] over every pose, link and coupler (modulo a turn),
    and the largest rate and acceleration differences relative to the largest
    |omega| (|alpha|) of the closed form."""
    k = cf.theta3.shape[1]
    ang, vel, acc = [], [], []
    for i in range(k + 1):
        j = mech.joint(f"O{i}")
        ang.append(np.arctan2(q[:, j.idx_q + 1], q[:, j.idx_q]) - cf.phi[:, i])
        vel.append(v[:, j.idx_v] - cf.omega[:, i])
        acc.append(a[:, j.idx_v] - cf.alpha[:, i])
    for i in range(k):
        j = mech.joint(f"A{i}")
        rel = np.arctan2(q[:, j.idx_q + 1], q[:, j.idx_q])
        ang.append(rel - (cf.theta3[:, i] - cf.phi[:, i]))
        vel.append(v[:, j.idx_v] - (cf.omega3[:, i] - cf.omega[:, i]))
        acc.append(a[:, j.idx_v] - (cf.alpha3[:, i] - cf.alpha[:, i]))
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v)) and np.all(np.isfinite(a))):
        return math.inf, math.inf, math.inf
    w_max = max(np.abs(cf.omega).max(), np.abs(cf.omega3).max())
    a_max = max(np.abs(cf.alpha).max(), np.abs(cf.alpha3).max(), 1e-300)
    return (float(np.abs(wrap(np.array(ang))).max()), float(np.abs(np.array(vel)).max() / w_max),
            float(np.abs(np.array(acc)).max() / a_max))


# ------------------------------------------------------------------ measuring
@dataclass
class Row:
    """One chain on one path: its solver, and what was measured.

    Attributes:
        times: seconds per pose, one per round.
        errors: largest angle error [rad], relative rate and acceleration errors.
    """

    k: int
    path: str
    poses: int
    run: object = None
    calls: int = 1
    times: list[float] = field(default_factory=list)
    errors: tuple[float, float, float] = (math.nan, math.nan, math.nan)
    set_up: float = math.nan

    @property
    def median_us(self) -> float:
        return statistics.median(self.times) * 1e6 if self.times else math.nan


def make_row(k: int, path: str, poses: int, lengths=LENGTHS) -> Row:
    """Build the chain's solver (timed apart) and a run() that sweeps it on `path`."""
    import pinmech.solve.core as core

    thetas = np.radians(np.arange(poses) * (360.0 / poses))
    t0 = time.perf_counter()
    mech, solver = chain_solver(k, lengths)
    def run():
        return sweep(solver, thetas)
    row = Row(k, path, poses, run)
    row.set_up = time.perf_counter() - t0
    q, v, a = run()  # the first call builds the core (core_for), not timed
    if core.core_for(solver) is None:
        raise RuntimeError("the core does not take this chain")
    row.errors = chain_errors(mech, q, v, a, chain_closed_form(thetas, k, lengths=lengths))
    return row


def warm_up(row: Row, sample_time: float) -> None:
    t0 = time.perf_counter()
    row.run()
    second = time.perf_counter() - t0
    row.calls = max(1, math.ceil(sample_time / max(second, 1e-9)))


def measure(loops=LOOPS, poses: int = 360, rounds: int = 7, sample_time: float = 0.2,
            paths=PATHS, lengths=LENGTHS) -> list[Row]:
    rows = [make_row(k, p, poses, lengths) for k in loops for p in paths]
    for row in rows:
        warm_up(row, sample_time)
    time_rounds(rows, rounds)
    return rows


# ------------------------------------------------------------------ callgrind
def one_sweep(k: int, poses: int, path: str, lengths=LENGTHS) -> None:
    """A whole run in this process (under callgrind): set-up, then one sweep of `poses`
    poses 1 degree apart from 0."""
    _, solver = chain_solver(k, lengths)
    sweep(solver, np.radians(np.arange(poses, dtype=float)))  # 1 degree apart


def callgrind_instructions(k: int, poses: int, path: str, lengths=LENGTHS) -> int:
    """Instructions executed by a whole `--one` child under callgrind."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cg.out")
        env = dict(os.environ, PYTHONHASHSEED="0", OPENBLAS_NUM_THREADS="1")  # idle BLAS threads spin: not deterministic
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, __file__,
               "--one", str(k), str(poses), path, "--lengths", *map(repr, lengths)]
        subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        text = Path(out).read_text(errors="replace")
    match = re.search(r"^(?:summary|totals):\s+(\d+)", text, re.MULTILINE)
    if not match:
        raise RuntimeError("no instruction total in callgrind's output")
    return int(match.group(1))


def callgrind_table(loops=(1, 16), short: int = 121, long: int = 361, paths=PATHS, lengths=LENGTHS) -> str:
    """Instructions per pose: (I(long) - I(short)) / (long - short), both sweeps 1 degree
    apart from 0 (361 poses: a full turn and back to 0), so set-up and start-up cancel."""
    lines = ["| loops k | path | instructions per pose | ratio to k = 1 |", "| --- | --- | --- | --- |"]
    per = {}
    for path in paths:
        for k in loops:
            counts = [callgrind_instructions(k, n, path, lengths) for n in (short, long)]
            per[k, path] = (counts[1] - counts[0]) / (long - short)
            ratio = per[k, path] / per[loops[0], path]
            lines.append(f"| {k} | {path} | {per[k, path]:,.0f} | {ratio:.2f} |")
    return "\n".join(lines)


# ------------------------------------------------------------------ report
def _version(dist: str) -> str:
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "not installed"


def environment() -> str:
    versions = ", ".join(f"{n} {_version(n)}" for n in ("pinmech", "pin", "numpy"))
    return f"Python {platform.python_version()}, {versions}; {machine()}"


def table(rows: list[Row]) -> str:
    base = {r.path: r for r in rows if r.k == min(x.k for x in rows)}
    lines = ["| loops k | path | us per pose (median) | spread (fastest - slowest round) | time(k) / time(1) "
             "| largest angle error [rad] | rate, acceleration error (relative) | set-up |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        ratio = r.median_us / base[r.path].median_us
        spread = f"{min(r.times) * 1e6:.3g} - {max(r.times) * 1e6:.3g}" if r.times else "-"
        lines.append(f"| {r.k} | {r.path} | {r.median_us:.3g} | {spread} | {ratio:.2f} | {r.errors[0]:.1e} | "
                     f"{r.errors[1]:.1e}, {r.errors[2]:.1e} | {r.set_up * 1e3:.0f} ms |")
    return "\n".join(lines)


def summary(rows: list[Row]) -> list[str]:
    """The longest chain measured against one loop: its time per pose, k times one loop's,
    the ratio, and the largest angle error over every chain."""
    out = []
    for path in PATHS:
        mine = {r.k: r for r in rows if r.path == path}
        k = max(mine, default=1)
        if 1 not in mine or k == 1:
            continue
        t1, tk = mine[1].median_us, mine[k].median_us
        worst = max(r.errors[0] for r in mine.values())
        out.append(f"- {path}: time({k}) = {tk:.3g} us per pose, {k} x time(1) = {k * t1:.3g} us: "
                   f"{tk / t1:.2f} x one loop; largest angle error {worst:.1e} rad")
    return out


def missed_targets(rows: list[Row]) -> list[str]:
    """The project's targets this run misses (the exit code; the report states none): the
    longest chain at most k x one loop, every angle within 1e-12 rad of the closed form."""
    missed = []
    for path in PATHS:
        mine = {r.k: r for r in rows if r.path == path}
        k = max(mine, default=1)
        if 1 in mine and mine[k].median_us > k * mine[1].median_us:
            missed.append(f"{path}: time({k}) over {k} x time(1)")
        missed += [f"{path}, k = {r.k}: angle error {r.errors[0]:.1e} rad over 1e-12"
                   for r in mine.values() if r.errors[0] > 1e-12]
    return missed


def markdown(rows: list[Row], poses: int, rounds: int, lengths=LENGTHS, extra: str = "") -> str:
    a, b, c, d = lengths
    head = (f"Chains of k four-bars in series (a = {a}, b = {b}, c = {c}, d = {d} m), one crank at {OMEGA} rad/s "
            f"swept over {poses} poses ({360 / poses:g} degree apart), one process, {rounds} interleaved rounds; "
            f"{environment()}. Angle error: largest over every pose, link and coupler against the closed form; "
            f"rate errors relative to the largest rate of the chain. Set-up (not in the time): URDF text to a "
            f"solver with its reference pose (the first row also pays pinmech's first imports).")
    parts = [head, "", table(rows), "", *summary(rows)]
    if extra:
        parts += ["", extra]
    return "\n".join(parts) + "\n"


def main(argv: list[str] | None = None) -> list[Row]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--loops", type=int, nargs="+", default=list(LOOPS), help="chain lengths k")
    parser.add_argument("--poses", type=int, default=360, help="poses per sweep (360: 1 degree apart)")
    parser.add_argument("--rounds", type=int, default=7, help="interleaved timing rounds")
    parser.add_argument("--sample-time", type=float, default=0.2, help="least time of one timed sample [s]")
    parser.add_argument("--paths", nargs="+", choices=PATHS, default=list(PATHS))
    parser.add_argument("--lengths", type=float, nargs=4, default=list(LENGTHS), metavar=("A", "B", "C", "D"),
                        help="input, coupler, output and ground lengths [m] of every loop")
    parser.add_argument("--callgrind", action="store_true",
                        help="also count instructions per pose under callgrind (k = 1 and 16; minutes)")
    parser.add_argument("--one", nargs=3, metavar=("K", "POSES", "PATH"), help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, help="also write the Markdown report to this file")
    args = parser.parse_args(argv)
    lengths = tuple(args.lengths)
    if args.one:
        one_sweep(int(args.one[0]), int(args.one[1]), args.one[2], lengths)
        return []
    if args.poses < 2 or args.rounds < 1 or min(args.loops) < 1:
        parser.error("--poses must be at least 2, --rounds and every k at least 1")
    loops = sorted(set(args.loops) | {1})
    rows = measure(loops, args.poses, args.rounds, args.sample_time, args.paths, lengths)
    extra = ""
    if args.callgrind:
        extra = ("Instructions per pose under callgrind (PYTHONHASHSEED=0), the slope between sweeps of 121 and "
                 "361 poses 1 degree apart:\n\n" + callgrind_table(paths=args.paths, lengths=lengths))
    report = markdown(rows, args.poses, args.rounds, lengths, extra)
    print(report, end="")
    if args.out:
        args.out.write_text(report)
    return rows


if __name__ == "__main__":
    _missed = missed_targets(main())
    for _line in _missed:
        print(f"target missed: {_line}", file=sys.stderr)
    sys.exit(1 if _missed else 0)
