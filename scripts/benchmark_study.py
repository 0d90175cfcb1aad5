"""Speed of a tolerance study: the bundled four-bar's (models/studies/four_bar_tolerance.toml)
at 360 poses a turn, in microseconds a variant-pose (variant changes and assembly checks
included), in this process, on one Dask worker and on two (LocalClusters started once,
their start-up not timed), in interleaved rounds; medians and spread. Also: the share of
the time spent in the compiled core's per-pose follow, and the ratio two workers / one.

    python scripts/benchmark_study.py --samples 2000 --rounds 3
    python scripts/benchmark_study.py --full      # also the whole 100,000 x 360 study on 2 workers, once

The project's targets: 100,000 variants x 360 poses in <= 60 s on 2 cores; a variant-pose in
<= 0.714 us (pylinkage-numba's time a pose); two workers >= 1.8 x one. The machine's load
average is printed beside the numbers: other processes on the 2 cores slow the Dask rows.
Needs `pip install "pinmech[study]"` for the Dask rows (they are skipped without it).
"""

from __future__ import annotations

import argparse
import logging
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import Timed, machine, time_rounds  # noqa: E402

from pinmech.design.cluster import built, local_cluster, run_batches  # noqa: E402
from pinmech.design.study.file import load_study  # noqa: E402
from pinmech.design.study.tolerance import batches  # noqa: E402

STEPS = 360  # poses a turn


def _spec(samples: int, batch: int):
    spec = load_study(ROOT / "models" / "studies" / "four_bar_tolerance.toml")
    return spec.__class__(**{**spec.__dict__, "samples": samples, "steps": STEPS, "batch": batch})


def core_share(spec, todo) -> tuple[float, float]:
    """The share of a serial run's time spent inside the compiled core's follow (the
    per-pose solve), measured by wrapping it; and the run's CPU time a variant-pose [s]
    (what other processes' load does not inflate)."""
    sm, _ = built(spec)
    core, spent = sm.core.core, [0.0]

    class Timing:
        def __getattr__(self, name):
            return getattr(core, name)

        def follow(self, *args):
            t0 = time.perf_counter()
            try:
                return core.follow(*args)
            finally:
                spent[0] += time.perf_counter() - t0

    sm.core.core = Timing()
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        run_batches(spec, todo)
        total, cpu = time.perf_counter() - t0, time.process_time() - c0
    finally:
        sm.core.core = core
    return spent[0] / total, cpu / (spec.samples * spec.steps)


def task_stream_shares(distributed, address: str, spec, todo) -> dict[str, float]:
    """One run on the cluster at `address`, read from Dask's task stream: the wall time [s],
    each worker's share of it spent computing (1: never idle), the tasks' compute time
    summed over the workers [s], and the CPU time each worker process used over the wall
    time. (Wall - compute / workers) is what batching, scheduling, result transfer and the
    client cost, plus any imbalance; a CPU share below the computing share is other
    processes taking the core, above it the worker's own overhead beside its task."""
    with distributed.Client(address, timeout="20s") as client, distributed.get_task_stream(client) as stream:
        cpu0 = client.run(time.process_time)
        t0 = time.perf_counter()
        run_batches(spec, todo, scheduler=address)
        wall = time.perf_counter() - t0
        cpu1 = client.run(time.process_time)
    busy: dict[str, float] = {}
    for task in stream.data:
        for part in task["startstops"]:
            if part["action"] == "compute":
                busy[task["worker"]] = busy.get(task["worker"], 0.0) + part["stop"] - part["start"]
    return {"wall": wall, "shares": sorted(b / wall for b in busy.values()), "compute": sum(busy.values()),
            "cpu": sorted((cpu1[w] - cpu0[w]) / wall for w in cpu0)}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2000)
    parser.add_argument("--batch", type=int, default=250, help="variants a Dask task (~0.2 s of work)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--full", action="store_true", help="also the 100,000-variant study on 2 workers, once")
    args = parser.parse_args(argv)
    spec = _spec(args.samples, args.batch)
    todo = batches(spec.samples, spec.batch)
    poses = spec.samples * spec.steps
    built(spec)  # this process's mechanism, built before the timing
    rows = {"in this process": Timed(lambda: run_batches(spec, todo), poses=poses)}
    clusters = []
    try:
        import distributed
    except ImportError:
        print('Dask rows skipped: pip install "pinmech[study]"')
        distributed = None
    try:
        for n in (1, 2) if distributed else ():
            cluster = local_cluster(n, silence_logs=logging.ERROR)  # as `pinmech study --workers n` starts it
            clusters.append(cluster)
            run_batches(spec, todo[:n], scheduler=cluster.scheduler_address)  # each worker builds the mechanism
            rows[f"Dask, {n} worker{'s' * (n > 1)}"] = Timed(
                lambda a=cluster.scheduler_address: run_batches(spec, todo, scheduler=a), poses=poses)
        loads = [os.getloadavg()[0]]
        time_rounds(list(rows.values()), args.rounds)
        loads.append(os.getloadavg()[0])
        streams = {len(c.workers): task_stream_shares(distributed, c.scheduler_address, spec, todo)
                   for c in clusters}
        share, cpu = core_share(spec, todo)
        full = None
        if args.full and len(clusters) == 2:
            big = _spec(100_000, 500)
            t0 = time.perf_counter()
            run_batches(big, batches(big.samples, big.batch), scheduler=clusters[1].scheduler_address)
            full = time.perf_counter() - t0
    finally:
        for cluster in clusters:
            cluster.close()
    print(f"tolerance study of the four-bar: {spec.samples} variants x {spec.steps} poses, batches of "
          f"{spec.batch} ({len(todo)} tasks), {args.rounds} rounds; load average (1 min) {loads[0]:.1f} before, "
          f"{loads[1]:.1f} after; {machine()}")
    for name, row in rows.items():
        us = [t * 1e6 for t in row.times]
        print(f"{name:<18} median {statistics.median(us):6.3f} us a variant-pose  ({min(us):.3f} .. {max(us):.3f})")
    if "Dask, 2 workers" in rows:
        ratios = [a / b for a, b in zip(rows["Dask, 1 worker"].times, rows["Dask, 2 workers"].times)]
        print(f"two workers / one: median {statistics.median(ratios):.2f} x ({min(ratios):.2f} .. {max(ratios):.2f})")
    for n, t in sorted(streams.items()):
        shares = ", ".join(f"{x:.0%}" for x in t["shares"])
        got = ", ".join(f"{x:.0%}" for x in t["cpu"])
        print(f"task stream, {n} worker{'s' * (n > 1)}: wall {t['wall']:.2f} s, computing {shares} of it "
              f"(compute {t['compute']:.2f} s in all); CPU a worker used: {got} of the wall")
    print(f"CPU time a variant-pose in this process: {cpu * 1e6:.3f} us")
    print(f"time in the core's per-pose follow: {share:.0%} of a serial run; outside it "
          f"(variant writes, assembly check, outputs, batching): {1 - share:.0%}")
    if full is not None:
        print(f"100,000 variants x {STEPS} poses on 2 workers: {full:.1f} s")


if __name__ == "__main__":
    main()
