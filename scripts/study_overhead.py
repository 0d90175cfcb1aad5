"""How much of a tolerance study's time is spent outside the per-pose solve (issue 23, item 2).

The bundled four-bar tolerance study (models/studies/four_bar_tolerance.toml) with
`--steps` poses over the crank's turn and `--samples` variants, run in this process
through `design/tolerance.py`'s per-variant loop (`solve_variants`: write the variant's
dimensions into the model, re-read them, close the reference pose, sweep the cycle, read
the outputs at every pose). Two shares are measured with time.perf_counter: the time inside
the compiled core's own sweep calls (`Core.follow` and `Core.node`: the per-pose solve proper), and those with the
outputs' compiled kinematics over the cycle (`_core.frames_along`). Reported: total, each
share and what lies outside it, and with `--profile` a cProfile of one batch.

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
from pinmech.design.study_outputs import StudyOutputs  # noqa: E402
from pinmech.design.study_variant import StudyMechanism  # noqa: E402
from pinmech.design.tolerance import batches, run_batch  # noqa: E402


class _TimedCore:
    """The compiled core's sweep calls (Core.follow, Core.node, wrapped on the class) and
    its kinematics over a cycle (`frames_along`, the outputs' poses), their times added up [s]."""

    def __init__(self) -> None:
        from pinmech.solve.core import _core

        self.seconds, self.kinematics = 0.0, 0.0
        for name in ("follow", "node"):
            setattr(_core.Core, name, self._timed(getattr(_core.Core, name), "seconds"))
        _core.frames_along = self._timed(_core.frames_along, "kinematics")

    def _timed(self, method, total: str):
        def timed(*args):
            t0 = time.perf_counter()
            try:
                return method(*args)
            finally:
                setattr(self, total, getattr(self, total) + time.perf_counter() - t0)
        return timed


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
    compiled = _TimedCore()
    todo = batches(spec.samples, spec.batch)
    t0 = time.perf_counter()
    results = [run_batch(sm, outputs, b) for b in todo]
    total = time.perf_counter() - t0
    solved = sum(not c for r in results for c in r.causes)
    poses = spec.samples * spec.steps
    print(f"{spec.samples} variants x {spec.steps} poses ({solved} solved): total {total:.3g} s "
          f"({total / poses * 1e6:.3g} us a variant-pose)\n"
          f"- inside the compiled core's sweep calls (Core.follow, Core.node) {compiled.seconds:.3g} s; outside "
          f"them {total - compiled.seconds:.3g} s = {(total - compiled.seconds) / total:.1%} of the time\n"
          f"- inside those and the outputs' compiled kinematics (frames_along) {compiled.seconds + compiled.kinematics:.3g}"
          f" s; outside every compiled per-pose call {total - compiled.seconds - compiled.kinematics:.3g} s = "
          f"{(total - compiled.seconds - compiled.kinematics) / total:.1%} of the time")
    if args.profile:
        profile = cProfile.Profile()
        profile.runcall(run_batch, sm, outputs, todo[0])
        pstats.Stats(profile).sort_stats("tottime").print_stats(15)


if __name__ == "__main__":
    main()
