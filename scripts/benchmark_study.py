"""Speed of a tolerance study: the bundled four-bar's (models/studies/four_bar_tolerance.toml),
in variant-poses a second, in this process, on one Dask worker and on two (LocalClusters
started once, their start-up not timed), in interleaved rounds; medians and spread.

    python scripts/benchmark_study.py --samples 2000 --rounds 3

Needs `pip install "pinmech[study]"` for the Dask rows (they are skipped without it).
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import Timed, time_rounds  # noqa: E402

from pinmech.design.cluster import run_batches  # noqa: E402
from pinmech.design.study_file import load_study  # noqa: E402
from pinmech.design.tolerance import batches  # noqa: E402


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    spec = load_study(ROOT / "models" / "studies" / "four_bar_tolerance.toml")
    spec = spec.__class__(**{**spec.__dict__, "samples": args.samples})
    todo = batches(spec.samples, spec.batch)
    poses = spec.samples * spec.steps
    rows = {"in this process": Timed(lambda: run_batches(spec, todo), poses=poses)}
    clusters = []
    try:
        import distributed
    except ImportError:
        print('Dask rows skipped: pip install "pinmech[study]"')
        distributed = None
    try:
        for n in (1, 2) if distributed else ():
            cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                               dashboard_address="127.0.0.1:0", host="127.0.0.1")
            clusters.append(cluster)
            run_batches(spec, todo[:n], scheduler=cluster.scheduler_address)  # each worker builds the mechanism
            rows[f"Dask, {n} worker{'s' * (n > 1)}"] = Timed(
                lambda a=cluster.scheduler_address: run_batches(spec, todo, scheduler=a), poses=poses)
        time_rounds(list(rows.values()), args.rounds)
    finally:
        for cluster in clusters:
            cluster.close()
    print(f"tolerance study of the four-bar: {spec.samples} variants x {spec.steps} poses, {args.rounds} rounds")
    for name, row in rows.items():
        rates = [1.0 / t for t in row.times]
        print(f"{name:<18} median {statistics.median(rates):>10.0f} variant-poses/s  "
              f"({min(rates):.0f} .. {max(rates):.0f}); {statistics.median(row.times) * 1e6:.2f} us a variant-pose")


if __name__ == "__main__":
    main()
