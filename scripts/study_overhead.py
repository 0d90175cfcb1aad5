"""How much of a tolerance study's time is spent outside the per-pose solve (issue 23, item 2).

The bundled four-bar tolerance study (models/studies/four_bar_tolerance.toml) with
`--steps` poses over the crank's turn and `--samples` variants, run in this process
through `design/tolerance.py`'s per-variant loop (`solve_variants`: write the variant's
dimensions into the model, re-read them, close the reference pose, sweep the cycle, read
the outputs at every pose). The time inside `Sweep.chunks` (the per-pose solve: the
compiled continuation, every pose's q, v, a) is measured around each chunk with
time.perf_counter; everything else is "outside". Reported: total, inside, outside and the
outside fraction, and a cProfile of the outside's largest items with `--profile`.

    python scripts/study_overhead.py --samples 10000 --steps 360
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pinmech.design.study_file import load_study  # noqa: E402
from pinmech.design.sensitivity import StudyOutputs  # noqa: E402
from pinmech.design.study_variant import StudyMechanism  # noqa: E402
from pinmech.design.tolerance import batches, run_batch  # noqa: E402


class _TimedChunks:
    """Sweep.chunks with the time spent producing each chunk added up [s]."""

    def __init__(self, chunks) -> None:
        self.chunks, self.seconds = chunks, 0.0

    def __call__(self, *args, **kwargs):
        it = self.chunks(*args, **kwargs)
        while True:
            t0 = time.perf_counter()
            try:
                chunk = next(it)
            except StopIteration:
                self.seconds += time.perf_counter() - t0
                return
            self.seconds += time.perf_counter() - t0
            yield chunk


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10000, help="variants")
    parser.add_argument("--steps", type=int, default=360, help="poses over the crank's turn")
    parser.add_argument("--profile", action="store_true", help="also profile one batch with cProfile")
    args = parser.parse_args(argv)
    spec = load_study(ROOT / "models" / "studies" / "four_bar_tolerance.toml")
    spec = spec.__class__(**{**spec.__dict__, "samples": args.samples, "steps": args.steps})
    sm = StudyMechanism(spec)
    outputs = StudyOutputs(sm)
    timed = _TimedChunks(sm.sweep.chunks)
    sm.sweep.chunks = timed
    todo = batches(spec.samples, spec.batch)
    t0 = time.perf_counter()
    results = [run_batch(sm, outputs, b) for b in todo]
    total = time.perf_counter() - t0
    solved = sum(not c for r in results for c in r.causes)
    poses = spec.samples * spec.steps
    print(f"{spec.samples} variants x {spec.steps} poses ({solved} solved): total {total:.3g} s "
          f"({total / poses * 1e6:.3g} us a variant-pose); per-pose solve (Sweep.chunks) {timed.seconds:.3g} s; "
          f"outside it {total - timed.seconds:.3g} s = {(total - timed.seconds) / total:.1%} of the time")
    if args.profile:
        profile = cProfile.Profile()
        profile.runcall(run_batch, sm, outputs, todo[0])
        pstats.Stats(profile).sort_stats("tottime").print_stats(15)


if __name__ == "__main__":
    main()
