"""Generic against generated kinematic passes, on the peers' problems and the 16-loop chain.

Rows (each with kernel = "generic" and kernel = "generated", same process, interleaved
rounds, a sample repeating a call until it fills `--sample-time`): P1 (the R-RTR of
scripts/benchmark_peers.py) every output through `Sweep.chunks` + `frame_paths`, the core's
`follow` alone and the passes alone (`Core.pinocchio_passes`); P2 (the arm of 17.110)
`RateSolver.solve_many` and its passes alone; the 16-loop chain of scripts/benchmark_loops.py
swept. The table gives the median time per pose over the rounds, the fastest and slowest
round, and the largest difference between the generic and generated answers (every pose
and output; the peers script checks the answers against the closed forms). It also gives
each model's kernel: time to write the C and to compile it, and the library's size.

Run: python scripts/benchmark_kernels.py [--poses 360] [--rounds 7] [--out kernels.md]
"""

from __future__ import annotations

import argparse
import functools
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchmark_loops as bl  # noqa: E402
import benchmark_peers as bp  # noqa: E402


def _p2(th1, th2, kernel: str, passes: bool):
    import pinmech

    original = pinmech.RateSolver
    pinmech.RateSolver = functools.partial(original, kernel=kernel)
    try:
        return bp.pinocchio_passes_p2(th1, th2) if passes else bp.pinmech_p2(th1, th2, many=True)
    finally:
        pinmech.RateSolver = original


def _p1(make, phi, kernel: str):
    import pinmech

    bp._pinmech_p1_sweep = lambda: (pinmech, pinmech.Sweep.from_scene(
        pinmech.Scene.load(bp.SCENE_P1, [f'solver.kernel="{kernel}"'])))
    return make(phi)


def _chain(k: int, poses: int, kernel: str):
    _, solver = bl.chain_solver(k)
    solver.kernel = kernel
    thetas = np.linspace(0.0, 2 * np.pi, poses, endpoint=False)
    return (lambda: np.concatenate(bl.sweep(solver, thetas), axis=1)), solver


def plan(poses: int) -> list[tuple[str, int, object]]:
    phi = bp.p1_angles(poses)
    th1, th2 = bp.p2_angles(poses)
    out = []
    for kernel in ("generic", "generated"):
        out += [
            ("P1 Sweep.chunks + frame_paths (every output)", kernel, lambda k=kernel: _p1(bp.pinmech_p1_paths, phi, k)),
            ("P1 core follow alone", kernel, lambda k=kernel: _p1(bp.pinmech_p1_core_follow, phi, k)),
            ("P1 passes alone (2 Jacobians + 1 kinematics)", kernel,
             lambda k=kernel: _p1(bp.pinocchio_passes_p1, phi, k)),
            ("P2 RateSolver.solve_many", kernel, lambda k=kernel: _p2(th1, th2, k, False)),
            ("P2 passes alone (1 Jacobian + 1 kinematics)", kernel, lambda k=kernel: _p2(th1, th2, k, True)),
            ("16-loop chain sweep", kernel, lambda k=kernel: _chain(16, poses, k)[:1] + (None, "")),
        ]
    return out


def _answer(value) -> np.ndarray:
    if isinstance(value, list):  # follow's [(Q, V, A)]
        return np.concatenate([np.concatenate(t, axis=1) for t in value])
    return np.asarray(value, dtype=float)


def measure(poses: int, rounds: int, sample_time: float) -> list[dict]:
    rows = []
    for name, kernel, make in plan(poses):
        run = make()[0]
        answer = _answer(run())
        calls = max(1, int(sample_time / max(_once(run), 1e-6)))
        rows.append({"name": name, "kernel": kernel, "run": run, "calls": calls, "answer": answer, "times": []})
    for r in range(rounds):
        for row in rows[r % len(rows):] + rows[:r % len(rows)]:
            start = time.perf_counter()
            for _ in range(row["calls"]):
                row["run"]()
            row["times"].append((time.perf_counter() - start) / row["calls"] / poses)
    generic = {row["name"]: row["answer"] for row in rows if row["kernel"] == "generic"}
    for row in rows:
        a, b = generic[row["name"]], row["answer"]
        row["difference"] = float(np.max(np.abs(a - b))) if a.shape == b.shape else float("nan")
    return rows


def _once(run) -> float:
    start = time.perf_counter()
    run()
    return time.perf_counter() - start


def kernel_costs() -> list[tuple[str, float, float, int, int]]:
    """Per model: seconds to write the C, seconds to compile it, C bytes, library bytes
    (built afresh in a temporary folder, whatever the cache holds)."""
    import pinmech
    from pinmech.solve import kernel_build

    models = {"P1 (R-RTR)": pinmech.Scene.load(bp.SCENE_P1), "P2 (arm 17.110)": None, "16-loop chain": None}
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in models:
            if name.startswith("P1"):
                model = pinmech.Sweep.from_scene(models[name]).mechanism.model
            elif name.startswith("P2"):
                model = pinmech.Mechanism.from_urdf(bp.URDF_P2).model
            else:
                model = bl.chain_solver(16)[0].model
            out.append((name, *kernel_build.make_kernel(model, Path(tmp) / "k.so")))
    return out


def markdown(rows: list[dict], costs, poses: int, rounds: int) -> str:
    lines = [f"{poses} poses, median of {rounds} rounds (fastest - slowest), time per pose", "",
             "| problem, method | generic [us] | generated [us] | ratio | largest difference |",
             "|---|---|---|---|---|"]
    by = {(r["name"], r["kernel"]): r for r in rows}
    for name in dict.fromkeys(r["name"] for r in rows):
        g, k = by[(name, "generic")], by[(name, "generated")]
        cell = [f"{statistics.median(x['times']) * 1e6:.2f} ({min(x['times']) * 1e6:.2f} - "
                f"{max(x['times']) * 1e6:.2f})" for x in (g, k)]
        ratio = statistics.median(k["times"]) / statistics.median(g["times"])
        lines.append(f"| {name} | {cell[0]} | {cell[1]} | {ratio:.2f} | {k['difference']:.1e} |")
    lines += ["", "| model | C written [s] | compiled [s] | C [kB] | library [kB] |", "|---|---|---|---|---|"]
    lines += [f"| {n} | {g:.2f} | {c:.2f} | {cb / 1024:.0f} | {lb / 1024:.0f} |" for n, g, c, cb, lb in costs]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=360)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--sample-time", type=float, default=0.05)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args(argv)
    text = markdown(measure(args.poses, args.rounds, args.sample_time), kernel_costs(), args.poses, args.rounds)
    print(text)
    if args.out:
        args.out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
