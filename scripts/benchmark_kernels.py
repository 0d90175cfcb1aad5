"""Generic against generated kinematic passes, on the peers' problems and the 16-loop chain.

Rows (each with kernel = "generic" and kernel = "generated", same process, interleaved
rounds, a sample repeating a call until it fills `--sample-time`): P1 (the R-RTR of
scripts/benchmark_peers.py) every output through `Sweep.chunks` + `frame_paths`, the core's
`follow` alone and the passes alone (`Core.pinocchio_passes`); P2 (the arm of 17.110)
`RateSolver.solve_many` and its passes alone; the 16-loop chain of scripts/benchmark_loops.py
swept; the four-bar's tolerance study (models/studies/four_bar_tolerance.toml, `--variants`
variants x 360 poses, in this process: a time per variant-pose). The peers the targets name
run in the same rounds: pylinkage's numba kernel on P1 and sympy's lambdified functions
called once on all of P2's poses (`pip install "pinmech[bench]"`; rows skipped without).
The table gives the median time per pose over the rounds, the fastest and slowest round,
and the largest difference between the generic and generated answers (every pose and
output; the peers script checks the answers against the closed forms). It also gives each
model's kernel: time to write the C and to compile it, and the library's size. With
`--synthesis`, the 10-point four-bar path synthesis (models/synthesis/four_bar_path.toml)
is timed once (10-60 s).

The exit code is the number of the project's speed targets this run misses (the report
lists them): P1 every output, generated, at most pylinkage's numba kernel's time; P2 at most
sympy's vectorized time; a tolerance-study variant-pose at most 0.5 us; with --synthesis,
the path synthesis in at most 3 s.

Run: python scripts/benchmark_kernels.py [--poses 360] [--rounds 7] [--variants 200] [--out kernels.md]
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


def _study(variants: int, kernel: str):
    """The tolerance study's variants run in this process, and the poses they solve."""
    import dataclasses

    from pinmech.design.cluster import built, run_batches
    from pinmech.design.study.file import load_study
    from pinmech.design.study.tolerance import batches

    spec = load_study(Path(__file__).resolve().parents[1] / "models" / "studies" / "four_bar_tolerance.toml")
    spec = dataclasses.replace(spec, samples=variants, steps=360, batch=variants, kernel=kernel)
    todo = batches(spec.samples, spec.batch)
    built(spec)
    return (lambda: np.zeros(1) if run_batches(spec, todo) else None), spec.samples * spec.steps


def _peer(make):
    try:
        return make()
    except ImportError:
        return None


def plan(poses: int, variants: int) -> list[tuple[str, str, object, int]]:
    """(row, kernel or "peer", a maker of (run, ...), poses a call)."""
    phi = bp.p1_angles(poses)
    th1, th2 = bp.p2_angles(poses)
    out = [("P1 pylinkage + numba (peer)", "peer", lambda: _peer(lambda: bp.pylinkage_p1(poses)), poses),
           ("P2 sympy lambdified, vectorized (peer)", "peer", lambda: _peer(lambda: bp.sympy_p2_vectorized(th1, th2)),
            poses)]
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
        out = [(*row, poses) if len(row) == 3 else row for row in out]
        study = _study(variants, kernel)
        out.append(("tolerance study, a variant-pose (one core)", kernel, lambda s=study: (s[0],), study[1]))
    return out


def _answer(value) -> np.ndarray:
    if isinstance(value, list):  # follow's [(Q, V, A)]
        return np.concatenate([np.concatenate(t, axis=1) for t in value])
    return np.asarray(value, dtype=float)


def measure(poses: int, rounds: int, sample_time: float, variants: int) -> list[dict]:
    rows = []
    for name, kernel, make, count in plan(poses, variants):
        made = make()
        if made is None:  # a peer that is not installed
            continue
        run = made[0]
        answer = _answer(run())
        calls = max(1, int(sample_time / max(_once(run), 1e-6)))
        rows.append({"name": name, "kernel": kernel, "run": run, "calls": calls, "answer": answer, "times": [],
                     "poses": count})
    for r in range(rounds):
        for row in rows[r % len(rows):] + rows[:r % len(rows)]:
            start = time.perf_counter()
            for _ in range(row["calls"]):
                row["run"]()
            row["times"].append((time.perf_counter() - start) / row["calls"] / row["poses"])
    generic = {row["name"]: row["answer"] for row in rows if row["kernel"] == "generic"}
    for row in rows:
        a, b = generic.get(row["name"]), row["answer"]
        row["difference"] = float(np.max(np.abs(a - b))) if a is not None and a.shape == b.shape else float("nan")
    return rows


#: The targets: (what, the generated row, the bound's row or a time [us a pose], at most this ratio).
TARGETS = [("P1 every output, generated, <= pylinkage + numba", "P1 Sweep.chunks + frame_paths (every output)",
            "P1 pylinkage + numba (peer)"),
           ("P2, generated, <= sympy vectorized", "P2 RateSolver.solve_many", "P2 sympy lambdified, vectorized (peer)"),
           ("tolerance study variant-pose, generated, <= 0.5 us", "tolerance study, a variant-pose (one core)", 0.5)]


def missed(rows: list[dict], synthesis_seconds: float | None) -> list[str]:
    """The targets this run misses, each with its numbers."""
    median = {(r["name"], r["kernel"]): statistics.median(r["times"]) * 1e6 for r in rows}
    out = []
    for what, ours, bound in TARGETS:
        mine = median.get((ours, "generated"))
        limit = bound if isinstance(bound, float) else median.get((bound, "peer"))
        if mine is None or limit is None:
            out.append(f"{what}: not measured (a row is missing)")
        elif mine > limit:
            out.append(f"{what}: {mine:.3g} us against {limit:.3g} us ({mine / limit:.2f} x)")
    if synthesis_seconds is not None and synthesis_seconds > 3.0:
        out.append(f"10-point four-bar path synthesis <= 3 s: {synthesis_seconds:.1f} s")
    return out


def synthesis_seconds() -> float:
    """The 10-point four-bar path synthesis once, in this process [s]."""
    from pinmech.design.synthesis.search import synthesise

    start = time.perf_counter()
    synthesise(Path(__file__).resolve().parents[1] / "models" / "synthesis" / "four_bar_path.toml")
    return time.perf_counter() - start


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
    from interleave import machine

    lines = [f"{poses} poses, median of {rounds} rounds (fastest - slowest), time per pose; {machine()}", "",
             "| problem, method | generic [us] | generated [us] | ratio | largest difference |",
             "|---|---|---|---|---|"]
    by = {(r["name"], r["kernel"]): r for r in rows}
    for name in dict.fromkeys(r["name"] for r in rows):
        if (name, "peer") in by:
            p = by[(name, "peer")]["times"]
            lines.append(f"| {name} | {statistics.median(p) * 1e6:.3f} ({min(p) * 1e6:.3f} - {max(p) * 1e6:.3f}) "
                         f"| | | |")
            continue
        g, k = by[(name, "generic")], by[(name, "generated")]
        cell = [f"{statistics.median(x['times']) * 1e6:.2f} ({min(x['times']) * 1e6:.2f} - "
                f"{max(x['times']) * 1e6:.2f})" for x in (g, k)]
        ratio = statistics.median(k["times"]) / statistics.median(g["times"])
        lines.append(f"| {name} | {cell[0]} | {cell[1]} | {ratio:.2f} | {k['difference']:.1e} |")
    lines += ["", "| model | C written [s] | compiled [s] | C [kB] | library [kB] |", "|---|---|---|---|---|"]
    lines += [f"| {n} | {g:.2f} | {c:.2f} | {cb / 1024:.0f} | {lb / 1024:.0f} |" for n, g, c, cb, lb in costs]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=360)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--sample-time", type=float, default=0.05)
    parser.add_argument("--variants", type=int, default=200, help="the tolerance study's variants (x 360 poses)")
    parser.add_argument("--synthesis", action="store_true", help="also time the 10-point path synthesis once")
    parser.add_argument("--out", type=Path)
    args = parser.parse_args(argv)
    rows = measure(args.poses, args.rounds, args.sample_time, args.variants)
    text = markdown(rows, kernel_costs(), args.poses, args.rounds)
    seconds = synthesis_seconds() if args.synthesis else None
    if seconds is not None:
        text += f"\n10-point four-bar path synthesis (seed of the file, one process): {seconds:.1f} s\n"
    print(text)
    if args.out:
        args.out.write_text(text, encoding="utf-8")
    misses = missed(rows, seconds)
    for line in misses:
        print(f"target missed: {line}", file=sys.stderr)
    return len(misses)


if __name__ == "__main__":
    sys.exit(main())
