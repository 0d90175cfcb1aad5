"""The certification dial's trade, measured: time per pose and largest error of
{generic, generated kernel} x {every-pose, every-10, none} on P1 (the R-RTR sweep, every
output), P2 (the arm of 17.110, `RateSolver.solve_many`), the 16-loop chain of
scripts/benchmark_loops.py and a tolerance study of the bundled four-bar; and the five-bar
workspace grid on either kernel (its grid points are solved one by one, each certified: the
dial does not apply there, its map of condition numbers is the study's answer).

One process, interleaved rounds (scripts/interleave.py): each round times every row once,
the order rotated. The table gives the median time per pose (a study: per variant-pose; the grid: per point)
over the rounds with the fastest and slowest round, and the largest error against an
independent reference: P1 and P2 their closed forms (scripts/closed_form.py, as
scripts/benchmark_peers.py), the chain the law of cosines loop after loop
(benchmark_loops.chain_closed_form), the tolerance study's every variant the law-of-cosines
four-bar of that variant's lengths (P and the rocker's angle at every pose), the five-bar's
motors at every grid point reached the law-of-cosines elbows of its working mode.

Targets (exit code 1 when missed, never in the docs' text): every level's largest error
within 1e-9 relative of the reference on P1, P2 and the chain (the dial must not lose
accuracy: every pose keeps its residual checks), within 1e-9 m or rad on the study (its
variants close to 1e-13 of the loop, times a condition number under 1e3), within 1e-8 rad on
the grid (its Newton stops at a residual of 1e-10 of the loop size, and an elbow 1 mm from
its annulus' circle is conditioned ~100).

Run: python scripts/benchmark_dial.py [--poses 3600] [--rounds 7] [--samples 10000] [--grid 31 41]
     [--out dial_trade.md]
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import math
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchmark_loops as bl  # noqa: E402
import closed_form as cf  # noqa: E402
import benchmark_peers as bp  # noqa: E402
from interleave import Timed, machine, time_rounds  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
KERNELS = ("generic", "generated")
LEVELS = ("every-pose", "every-10", "none")
STUDY = ROOT / "models" / "studies" / "four_bar_tolerance.toml"
#: Largest error accepted, relative to the reference's largest magnitude (the exit code).
TARGET = 1e-9
#: The grid's (rad): Newton's stopping residual 1e-10 times the elbows' conditioning (~100).
GRID_TARGET = 1e-8


@dataclasses.dataclass
class Row(Timed):
    problem: str = ""
    kernel: str = ""
    level: str = ""
    error: str = "—"
    relative: float = 0.0  # the error relative to the reference (the target's check)


def _p1(phi: np.ndarray, kernel: str, level: str):
    import pinmech

    bp._pinmech_p1_sweep = lambda: (pinmech, pinmech.Sweep.from_scene(pinmech.Scene.load(
        bp.SCENE_P1, [f'solver.kernel="{kernel}"', f'solver.certify="{level}"'])))
    run, _, _ = bp.pinmech_p1_paths(phi)
    return run


def _p2(th1: np.ndarray, th2: np.ndarray, kernel: str, level: str):
    import pinmech

    original = pinmech.RateSolver
    pinmech.RateSolver = functools.partial(original, kernel=kernel, certify=level)
    try:
        run, _, _ = bp.pinmech_p2(th1, th2, many=True)
    finally:
        pinmech.RateSolver = original
    return run


def _chain(thetas: np.ndarray, kernel: str, level: str):
    mech, solver = bl.chain_solver(16)
    solver.kernel, solver.certify = kernel, level
    return mech, (lambda: bl.sweep(solver, thetas))


def _study(samples: int, kernel: str, level: str):
    """A tolerance study of the bundled four-bar, in this process, its mechanism built in
    set-up (one StudyMechanism a row: the title tells the rows' specs apart); the run gives
    the study's result, its tables made as `pinmech study` makes them."""
    from pinmech.design.cluster import built
    from pinmech.design.study.file import load_study
    from pinmech.design.study.report import table
    from pinmech.design.study.run import study
    from pinmech.solve.core import core_for

    spec = dataclasses.replace(load_study(STUDY), samples=samples, certify=level, title=f"dial {kernel} {level}")
    sm, _ = built(spec)
    sm.solver.kernel = kernel
    core_for(sm.solver)  # the kernel attached to the core the study's cycle follows with

    def run():
        result = study(spec, workers=0)
        table(result)
        return result
    return run, spec.steps


def study_error(result) -> float:
    """The largest difference [m or rad] of any variant's P and rocker angle, at any pose,
    from the law-of-cosines four-bar of that variant's lengths (crank, ground, coupler,
    rocker: the study's params in order; P at (60, 30) mm on the coupler, as the scene)."""
    p, y, causes = result.variants
    worst = 0.0
    for k in range(len(p)):
        if causes[k]:
            continue
        a, d, b, c = p[k]
        fb = cf.four_bar(result.values, 0.0, 0.0, a, b, c, d, +1)
        c3, s3 = np.cos(fb.theta3), np.sin(fb.theta3)
        px = a * np.cos(result.values) + 0.06 * c3 - 0.03 * s3
        py = a * np.sin(result.values) + 0.06 * s3 + 0.03 * c3
        turn = np.angle(np.exp(1j * (y[k, :, 2] - fb.theta4)))  # the rocker's angle, modulo a turn
        worst = max(worst, np.max(np.abs(y[k, :, 0] - px)), np.max(np.abs(y[k, :, 1] - py)), np.max(np.abs(turn)))
    return worst


#: The five-bar of models/five_bar (motors at (0, 0) and (100 mm, 0), links 60 and 90 mm, the
#: motors' zero directions 120 and 60 deg) over the grid of its workspace in mode "+-".
FIVE_BAR = dict(bases=np.array([[0.0, 0.0], [0.1, 0.0]]), l1=0.06, l2=0.09, zero=np.radians([120.0, 60.0]))
def _grid(kernel: str, folder: Path, grid: tuple[int, int]):
    """The five-bar's workspace map in mode "+-" on a grid of nx x ny points (x -60 .. 160 mm,
    y -150 .. 150 mm), from a study file written in `folder`."""
    from pinmech.design.study.run import study

    path = folder / f"five_bar_workspace_{kernel}.toml"
    nx, ny = grid
    path.write_text(f'scene = "{ROOT / "models" / "scenes" / "five_bar.toml"}"\nkind = "workspace"\nbatch = 500\n'
                    f'[workspace]\npoint = "closedloop1_A"\nmodes = ["+-"]\n'
                    f'x = {{ from = "-60 mm", to = "160 mm", count = {nx} }}\n'
                    f'y = {{ from = "-150 mm", to = "150 mm", count = {ny} }}\n', encoding="utf-8")
    return lambda: study(path, kernel=kernel)


def grid_error(result) -> float:
    """The largest difference [rad] of the motors' readings at any grid point reached from
    the law-of-cosines elbows of mode "+-" (points within 1e-3 m of an annulus' circle left
    out: a leg stretched or folded there has no well-conditioned elbow)."""
    mesh = np.stack(np.meshgrid(*result.coords, indexing="ij"), axis=-1)
    worst = 0.0
    for idx in zip(*np.nonzero(result.reached[..., 0])):
        point = mesh[idx]
        gaps = [np.linalg.norm(point - base) for base in FIVE_BAR["bases"]]
        inner, outer = FIVE_BAR["l2"] - FIVE_BAR["l1"], FIVE_BAR["l1"] + FIVE_BAR["l2"]
        if min(min(abs(g - inner), abs(g - outer)) for g in gaps) < 1e-3:
            continue
        want = cf.five_bar_motors(point, "+-", **FIVE_BAR)
        worst = max(worst, float(np.max(np.abs(np.angle(np.exp(1j * (result.motor_q[idx][0] - want)))))))
    return worst


def plan(poses: int, samples: int, grid: tuple[int, int], folder: Path) -> tuple[list[Row], dict]:
    """Every row, built (not yet timed), with the references; `folder`: the grid's study file."""
    phi = bp.p1_angles(poses)
    th1, th2 = bp.p2_angles(poses)
    thetas = np.linspace(0.0, 2 * np.pi, poses, endpoint=False)
    refs = {"P1": bp.p1_closed_form(phi), "P2": bp.p2_closed_form(th1, th2),
            "chain": bl.chain_closed_form(thetas, 16, omega=bl.OMEGA, alpha=bl.ALPHA)}
    rows = []
    for kernel in KERNELS:
        for level in LEVELS:
            rows.append(Row(_p1(phi, kernel, level), poses, problem="P1 R-RTR sweep, every output",
                            kernel=kernel, level=level))
            rows.append(Row(_p2(th1, th2, kernel, level), poses, problem="P2 arm of 17.110, solve_many",
                            kernel=kernel, level=level))
            mech, run = _chain(thetas, kernel, level)
            row = Row(run, poses, problem="16-loop chain sweep", kernel=kernel, level=level)
            row.mech = mech
            rows.append(row)
            run, steps = _study(samples, kernel, level)
            rows.append(Row(run, samples * steps, problem=f"tolerance study, {samples} variants x {steps} poses",
                            kernel=kernel, level=level))
        rows.append(Row(_grid(kernel, folder, grid), math.prod(grid),
                        problem=f"five-bar workspace grid, {grid[0]} x {grid[1]} points",
                        kernel=kernel, level="each point (the dial does not apply)"))
    return rows, refs


def errors(rows: list[Row], refs: dict) -> None:
    """Each row's largest error against its reference (one more call, after the timing)."""
    for row in rows:
        got = row.run()
        if row.problem.startswith("P1"):
            ref = refs["P1"]
            row.relative = bp.largest_error(got, ref, angle_columns=(0,)) / np.abs(ref).max()
            row.error = f"{row.relative:.1e} rel."
        elif row.problem.startswith("P2"):
            ref = refs["P2"]
            row.relative = bp.largest_error(got, ref) / np.abs(ref).max()
            row.error = f"{row.relative:.1e} rel."
        elif row.problem.startswith("16-loop"):
            angle, rate, acc = bl.chain_errors(row.mech, *got, refs["chain"])
            row.relative = max(angle / np.pi, rate, acc)
            row.error = f"{angle:.1e} rad, rates {rate:.1e} rel."
        elif row.problem.startswith("tolerance"):
            row.relative = study_error(got)
            row.error = f"{row.relative:.1e} m or rad"
        else:
            row.relative = grid_error(got)
            row.error = f"{row.relative:.1e} rad"


def markdown(rows: list[Row], poses: int, rounds: int, samples: int) -> str:
    out = [f"One run of `scripts/benchmark_dial.py --poses {poses} --rounds {rounds} --samples {samples}` on "
           f"{machine()}: median time per pose (a study: per variant-pose; the grid: per point) over {rounds} interleaved rounds, "
           "[fastest, slowest round], and the largest error against the reference named.", "",
           "| problem | kernel | certify | time per pose [µs] | largest error |", "|---|---|---|---|---|"]
    order = list(dict.fromkeys(r.problem for r in rows))
    rows = sorted(rows, key=lambda r: (order.index(r.problem), KERNELS.index(r.kernel),
                                       LEVELS.index(r.level) if r.level in LEVELS else 0))
    for row in rows:
        if row.times:
            t = [x * 1e6 for x in row.times]
            time = f"{statistics.median(t):.3g} [{min(t):.3g}, {max(t):.3g}]"
        else:
            time = "—"
        out.append(f"| {row.problem} | {row.kernel} | {row.level} | {time} | {row.error} |")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=3600)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--samples", type=int, default=10000, help="tolerance study variants")
    parser.add_argument("--grid", type=int, nargs=2, default=(31, 41), metavar=("NX", "NY"),
                        help="the five-bar workspace grid's points along x and y")
    parser.add_argument("--out", help="write the markdown table here")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        rows, refs = plan(args.poses, args.samples, tuple(args.grid), Path(folder))
        for row in rows:  # one call each before the timing: kernels built, caches warm
            row.run()
        time_rounds(rows, args.rounds)
        errors(rows, refs)
    text = markdown(rows, args.poses, args.rounds, args.samples)
    print(text)
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    missed = [r for r in rows if not r.relative <= (GRID_TARGET if r.problem.startswith("five-bar") else TARGET)]
    for r in missed:
        print(f"target missed: {r.problem}, {r.kernel}, {r.level}: {r.error}", file=sys.stderr)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
