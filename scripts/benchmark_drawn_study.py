"""Speed of a tolerance study over a drawn linkage's `[params]` against the same study over a
URDF's joint and cut placements: the bundled four-bar (crank 40, coupler 120, rocker 80,
ground 100 mm; the same tolerances as models/studies/four_bar_tolerance.toml), once as the
URDF (models/four_bar.urdf: joint origins and cut frames written in place) and once as the
drawn linkage models/linkages/four_bar_coupler_point.toml (its params crank, coupler,
rocker, ground: each variant redrawn and its placements written in place).

Two timings, in interleaved rounds (scripts/interleave.py), wall time:
- the variants' loop: `run_batch` over `--samples` variants (the mechanism built once);
- the whole study: `pinmech.study(file)` (scene loaded, nominal's sensitivity, variants).
For each, per round the drawn row's time over the URDF row's (the ratio), then the median
and the spread (min .. max) over the rounds; and each row's median time a variant.

    python scripts/benchmark_drawn_study.py --samples 400 --rounds 5
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import Timed, time_rounds  # noqa: E402

import pinmech  # noqa: E402
from pinmech.design.study.file import load_study  # noqa: E402
from pinmech.design.study.outputs import StudyOutputs  # noqa: E402
from pinmech.design.study.tolerance import batches, run_batch  # noqa: E402
from pinmech.design.study.variant import StudyMechanism  # noqa: E402

TOLERANCES = {"crank": 'tolerance = "0.1 mm"', "ground": 'sigma = "0.05 mm"',
              "coupler": 'tolerance = "0.1 mm"\ndistribution = "uniform"', "rocker": 'tolerance = "0.1 mm"'}
URDF = {"crank": 'joint = "A"\ncomponent = "x"', "ground": 'joint = "O4"\ncomponent = "x"',
        "coupler": 'cut = "B"\nside = "parent"\ncomponent = "x"', "rocker": 'cut = "B"\nside = "child"\ncomponent = "x"'}


def study_file(folder: Path, name: str, scene: Path, targets: dict[str, str], samples: int, steps: int) -> Path:
    """A tolerance study of the four lengths, written to folder/name.toml."""
    lines = [f'scene = "{scene.as_posix()}"', 'kind = "tolerance"', f"steps = {steps}", f"samples = {samples}",
             "seed = 2025", "batch = 100"]
    for param, target in targets.items():
        lines += ["", f"[params.{param}]", target, TOLERANCES[param]]
    lines += ["", "[outputs]", 'points = ["P"]', 'links = ["rocker"]', ""]
    path = folder / f"{name}.toml"
    path.write_text("\n".join(lines))
    return path


def rows(paths: dict[str, Path]) -> dict[str, dict[str, Timed]]:
    """Per study: its variants' loop and its whole run, as timed rows (seconds a variant)."""
    out = {}
    for name, path in paths.items():
        spec = load_study(path)
        sm = StudyMechanism(spec)
        outputs = StudyOutputs(sm)
        todo = batches(spec.samples, spec.batch)

        def loop(sm=sm, outputs=outputs, todo=todo) -> None:
            for batch in todo:
                run_batch(sm, outputs, batch)

        out[name] = {"loop": Timed(loop, poses=spec.samples), "study": Timed(lambda p=path: pinmech.study(p),
                                                                             poses=spec.samples)}
    return out


def summary(timed: dict[str, dict[str, Timed]]) -> list[str]:
    """Median time a variant of each row, and the drawn / URDF ratio's median and spread."""
    lines = []
    for what in ("loop", "study"):
        urdf, drawn = timed["urdf"][what].times, timed["drawn"][what].times
        ratios = [d / u for d, u in zip(drawn, urdf)]
        lines.append(f"{what:<6} URDF {statistics.median(urdf) * 1e6:8.1f} us/variant, drawn "
                     f"{statistics.median(drawn) * 1e6:8.1f} us/variant; drawn / URDF median "
                     f"{statistics.median(ratios):.2f} (spread {min(ratios):.2f} .. {max(ratios):.2f}, "
                     f"{len(ratios)} rounds)")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=400)
    parser.add_argument("--steps", type=int, default=73)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        paths = {"urdf": study_file(Path(folder), "urdf", ROOT / "models" / "scenes" / "four_bar.toml", URDF,
                                    args.samples, args.steps),
                 "drawn": study_file(Path(folder), "drawn", ROOT / "models" / "scenes" / "four_bar_coupler_point.toml",
                                     {p: f'param = "{p}"' for p in URDF}, args.samples, args.steps)}
        timed = rows(paths)
        time_rounds([r for row in timed.values() for r in row.values()], args.rounds)
    print(f"tolerance study, four-bar, {args.samples} variants x {args.steps} poses, wall time, "
          f"{args.rounds} interleaved rounds")
    print("\n".join(summary(timed)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
