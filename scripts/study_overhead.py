"""How much of a tolerance study's time is spent outside the per-pose solve (issue 23, item 2).

The bundled four-bar tolerance study (models/studies/four_bar_tolerance.toml) with
`--steps` poses over the crank's turn and `--samples` variants, run in this process
through `design/tolerance.py`'s per-variant loop (`solve_variants`: check the batch's
bounds, write each variant's dimensions into the model, close its start pose, follow the
cycle, read the outputs at every pose).

Two kinds of run alternate in interleaved rounds (scripts/interleave.py): a plain run, and
a run with the compiled per-pose calls wrapped in timers (time.perf_counter):
- the core's solve calls: `Core.correct` (pose 0 closed from the nominal's), `Core.node`
  (its tangent and assembly signature) and `Core.follow` (every other pose);
- the outputs' kinematics over the cycle: `_core.frames_along` (the outputs at each pose).
Each round's shares are the wrapped run's time inside those calls over the plain run's
total, so the timers' own cost (reported: the wrapped run's extra time a wrapped call) is
kept out of both shares:
(a) outside the core's solve calls, (b) outside every compiled per-pose call (the solve
and the outputs' kinematics). Medians over the rounds, and their spread (min .. max).

    python scripts/study_overhead.py --samples 10000 --steps 360 --rounds 5
"""

from __future__ import annotations

import argparse
import cProfile
import contextlib
import os
import pstats
import statistics
import sys
import time
import timeit
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import Timed, time_rounds  # noqa: E402

from pinmech.design.study_file import load_study  # noqa: E402
from pinmech.design.study_outputs import StudyOutputs  # noqa: E402
from pinmech.design.study_variant import StudyMechanism  # noqa: E402
from pinmech.design.tolerance import batches, run_batch  # noqa: E402
from pinmech.solve.core import _core  # noqa: E402

SOLVE = ("correct", "node", "follow")  # the core's calls that solve poses (Core methods)


class Timers:
    """Seconds spent inside the core's solve calls and inside `frames_along`, and how many
    calls were timed, while `installed` (the wrappers replace the compiled functions)."""

    def __init__(self) -> None:
        self.solve, self.kinematics = 0.0, 0.0
        self.calls = {"solve": 0, "kinematics": 0}

    @contextlib.contextmanager
    def installed(self):
        originals = {name: getattr(_core.Core, name) for name in SOLVE}
        kinematics = _core.frames_along
        try:
            for name, method in originals.items():
                setattr(_core.Core, name, self._timed(method, "solve"))
            _core.frames_along = self._timed(kinematics, "kinematics")
            yield self
        finally:
            for name, method in originals.items():
                setattr(_core.Core, name, method)
            _core.frames_along = kinematics

    def _timed(self, call, total: str):
        def timed(*args):
            t0 = time.perf_counter()
            try:
                return call(*args)
            finally:
                setattr(self, total, getattr(self, total) + time.perf_counter() - t0)
                self.calls[total] += 1
        return timed

    @staticmethod
    def cost(n: int = 200_000) -> tuple[float, float]:
        """The timers' own cost a call [s]: the part outside the timed interval and the part
        inside it, from n calls of a wrapped no-op (the builtin abs) against n bare ones
        (the fastest of 5 tries each)."""
        bare = min(timeit.repeat(lambda: abs(1.0), number=n, repeat=5)) / n
        tries = []
        for _ in range(5):
            probe = Timers()
            wrapped = probe._timed(abs, "solve")
            tries.append((timeit.timeit(lambda: wrapped(1.0), number=n) / n, probe.solve / n))
        total, inside = min(tries)
        return total - inside, inside - bare


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10000, help="variants")
    parser.add_argument("--steps", type=int, default=360, help="poses over the crank's turn")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds (a plain and a timed run each)")
    parser.add_argument("--profile", action="store_true", help="also profile one batch with cProfile")
    args = parser.parse_args(argv)
    spec = load_study(ROOT / "models" / "studies" / "four_bar_tolerance.toml")
    spec = spec.__class__(**{**spec.__dict__, "samples": args.samples, "steps": args.steps})
    sm = StudyMechanism(spec)
    outputs = StudyOutputs(sm)
    todo = batches(spec.samples, spec.batch)
    poses = spec.samples * spec.steps
    timers: list[Timers] = []
    solved: list[int] = []

    def plain() -> None:
        results = [run_batch(sm, outputs, b) for b in todo]
        solved.append(sum(not c for r in results for c in r.causes))

    def timed() -> None:
        with Timers().installed() as t:
            [run_batch(sm, outputs, b) for b in todo]
        timers.append(t)

    plain()  # warm-up, not timed
    rows = [Timed(plain), Timed(timed)]
    load = os.getloadavg()[0]
    time_rounds(rows, args.rounds)
    totals = rows[0].times  # seconds a plain run (Timed with poses=1)
    wrapped = rows[1].times
    shares_a = [1 - t.solve / total for t, total in zip(timers, totals)]
    shares_b = [1 - (t.solve + t.kinematics) / total for t, total in zip(timers, totals)]
    cost = [(w - total) / sum(t.calls.values()) for t, w, total in zip(timers, wrapped, totals)]
    outside_b = [(total - t.solve - t.kinematics) / spec.samples for t, total in zip(timers, totals)]
    out_cost, in_cost = Timers.cost()  # the same run's own estimate: its timers' cost taken off
    same_run = [1 - (t.solve + t.kinematics - sum(t.calls.values()) * in_cost)
                / (w - sum(t.calls.values()) * (out_cost + in_cost)) for t, w in zip(timers, wrapped)]

    def spread(xs: list[float], fmt: str) -> str:
        return f"median {format(statistics.median(xs), fmt)} ({format(min(xs), fmt)} .. {format(max(xs), fmt)})"

    print(f"{spec.samples} variants x {spec.steps} poses ({solved[-1]} solved), {args.rounds} interleaved rounds; "
          f"load average (1 min) {load:.1f} before, {os.getloadavg()[0]:.1f} after, on {os.cpu_count()} CPUs\n"
          f"- plain run: {spread([t / poses * 1e6 for t in totals], '.3f')} us a variant-pose\n"
          f"- (a) outside the core's solve calls ({', '.join('Core.' + n for n in SOLVE)}): "
          f"{spread([s * 100 for s in shares_a], '.1f')} % of the time\n"
          f"- (b) outside every compiled per-pose call (those and the outputs' kinematics, frames_along): "
          f"{spread([s * 100 for s in shares_b], '.1f')} % of the time, "
          f"{spread([x * 1e6 for x in outside_b], '.1f')} us a variant\n"
          f"- the timers' own cost a wrapped call: {(out_cost + in_cost) * 1e6:.2f} us ({in_cost * 1e6:.2f} us of it "
          f"inside the timed interval) by a wrapped no-op; timed run - plain run: "
          f"{spread([c * 1e6 for c in cost], '.2f')} us\n"
          f"- (b) from the timed run alone, the no-op's cost taken off: {spread([s * 100 for s in same_run], '.1f')} %")
    if args.profile:
        profile = cProfile.Profile()
        profile.runcall(run_batch, sm, outputs, todo[0])
        pstats.Stats(profile).sort_stats("tottime").print_stats(15)


if __name__ == "__main__":
    main()
