"""How much of a tolerance study's time is spent outside the per-pose solve.

The bundled four-bar tolerance study (models/studies/four_bar_tolerance.toml) with
`--steps` poses over the crank's turn and `--samples` variants, run in this process
through `design/study/tolerance.py`'s per-variant loop (`solve_variants`: check the batch's
bounds, write each variant's dimensions into the model, close its start pose, follow the
cycle, read the outputs at every pose).

Two kinds of run alternate in interleaved rounds (scripts/interleave.py): a plain run, and
a run with the compiled per-pose calls wrapped in timers (time.perf_counter):
- the core's solve calls: `Core.correct` (pose 0 closed from the nominal's), `Core.node`
  (its tangent and assembly signature) and `Core.follow` (every other pose);
- the outputs' kinematics over the cycle: `_core.frames_along` (the outputs at each pose).
Shares of the time outside (a) the core's solve calls, (b) every compiled per-pose call
(the solve and the outputs' kinematics), with the timers' own cost kept out: within the
timed run, less its timers' cost measured on a wrapped no-op (the builtin abs; its part
inside the timed interval taken off the inside times too); and, as a check, over the plain
run of the same round (paired: noisier, as the two runs' times differ by whatever load
other processes put on the machine). Medians over the rounds and their spread (min .. max).

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

from pinmech.design.study.file import load_study  # noqa: E402
from pinmech.design.study.outputs import StudyOutputs  # noqa: E402
from pinmech.design.study.variant import StudyMechanism  # noqa: E402
from pinmech.design.study.tolerance import batches, run_batch  # noqa: E402
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


def shares(t: Timers, plain: float, wrapped: float, cost: tuple[float, float]) -> dict[str, float]:
    """One round's shares of the time outside (a) the solve calls and (b) every compiled
    per-pose call: over the plain run's total [s] (paired) and over the timed run's own
    total [s] less its timers' cost (same run); the inside times less the timers' part
    inside their intervals (cost: outside, inside the interval, a call [s])."""
    out_c, in_c = cost
    solve = t.solve - t.calls["solve"] * in_c
    both = solve + t.kinematics - t.calls["kinematics"] * in_c
    own = wrapped - sum(t.calls.values()) * (out_c + in_c)
    return {"a": 1 - solve / plain, "b": 1 - both / plain, "a same run": 1 - solve / own,
            "b same run": 1 - both / own, "outside b": plain - both,
            "timers": (wrapped - plain) / sum(t.calls.values())}


def _spread(xs: list[float], scale: float, fmt: str) -> str:
    xs = [x * scale for x in xs]
    return f"median {format(statistics.median(xs), fmt)} ({format(min(xs), fmt)} .. {format(max(xs), fmt)})"


def report(rounds: list[dict[str, float]], plain: list[float], cost: tuple[float, float], samples: int,
           poses: int) -> str:
    """The medians and spreads (min .. max) over the rounds."""
    col = {k: [r[k] for r in rounds] for k in rounds[0]}
    solve = ", ".join("Core." + n for n in SOLVE)
    return (f"- plain run: {_spread(plain, 1e6 / poses, '.3f')} us a variant-pose\n"
            f"- (a) outside the core's solve calls ({solve}): {_spread(col['a same run'], 100, '.1f')} % of the "
            f"time (paired with the plain run: {_spread(col['a'], 100, '.1f')} %)\n"
            f"- (b) outside every compiled per-pose call (those and the outputs' kinematics, frames_along): "
            f"{_spread(col['b same run'], 100, '.1f')} % of the time (paired with the plain run: "
            f"{_spread(col['b'], 100, '.1f')} %, {_spread(col['outside b'], 1e6 / samples, '.1f')} us a variant)\n"
            f"- the timers' own cost a wrapped call, taken off: {sum(cost) * 1e6:.2f} us ({cost[1] * 1e6:.2f} us of "
            f"it inside the timed interval), by a wrapped no-op; timed run - plain run: "
            f"{_spread(col['timers'], 1e6, '.2f')} us a wrapped call (the paired figures are as good as this "
            f"agrees: other processes' load moves the plain and the timed runs apart)")


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
    rows = [Timed(plain), Timed(timed)]  # seconds a run (poses=1)
    load = os.getloadavg()[0]
    time_rounds(rows, args.rounds)
    cost = Timers.cost()
    rounds = [shares(t, p, w, cost) for t, p, w in zip(timers, rows[0].times, rows[1].times)]
    print(f"{spec.samples} variants x {spec.steps} poses ({solved[-1]} solved), {args.rounds} interleaved rounds; "
          f"load average (1 min) {load:.1f} before, {os.getloadavg()[0]:.1f} after, on {os.cpu_count()} CPUs")
    print(report(rounds, rows[0].times, cost, spec.samples, spec.samples * spec.steps))
    if args.profile:
        profile = cProfile.Profile()
        profile.runcall(run_batch, sm, outputs, todo[0])
        pstats.Stats(profile).sort_stats("tottime").print_stats(15)


if __name__ == "__main__":
    main()
