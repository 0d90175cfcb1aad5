"""One pose through the public API: `evaluate_motion` and
`RateSolver.solve` on one pose, with what bounds them from below, interleaved in one
process (scripts/interleave.py): medians and spread over the rounds, in microseconds.

Rows:
- evaluate_motion on one R-RTR pose (models/scenes/r_rtr.toml at crank 5 deg), link 3
  and D asked: the call alone, and the call with every P1 output read (link 3's angle,
  angular velocity and acceleration, the slider's rate and acceleration, D's velocity and
  acceleration: the Motion's dicts built);
- evaluate_motion with every point and link (the defaults), outputs read;
- RateSolver.solve on one P2 pose (models/planar_arm.urdf, text 17.110's task);
- the floor under them: the compiled call alone (`_core.frames_at`; `Core.rates` on one
  pose), one nanobind call that does nothing but return (`Core.nq`), building one frozen
  dataclass of four fields, and `Mechanism.checked_q` on one pose.

With `--before DIR` (a checkout of an earlier pinmech, e.g. `git archive d3dde90`), that
checkout's `solve/motion.py` and `solve/rates.py` are loaded beside this one's (on this
compiled core) and timed in the same rounds: a before/after ratio under one machine load.

    python scripts/benchmark_pose.py [--rounds 7] [--before DIR]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from interleave import Timed, time_rounds  # noqa: E402

import benchmark_peers as peers  # noqa: E402


def _p1():
    import pinmech

    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(peers.SCENE_P1))
    s = next(iter(sweep.chunks(np.radians([5.0])))).solution
    return pinmech, sweep.mechanism, sweep.solver.data, s.q[0], s.v[0], s.a[0]


def _module_from(path: Path, name: str):
    """The Python module at `path`, loaded under `name` (its imports from this pinmech)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def before_rows(root: Path) -> dict[str, Timed]:
    """evaluate_motion and RateSolver.solve as the checkout at `root` computes them."""
    motion = _module_from(root / "pinmech" / "solve" / "motion.py", "_before_motion")
    rates = _module_from(root / "pinmech" / "solve" / "rates.py", "_before_rates")
    pinmech, mechanism, data, q, v, a = _p1()
    run_many, _, _ = peers.pinmech_p2(*peers.p2_angles(360), many=True)
    cells = {type(c.cell_contents).__name__: c.cell_contents for c in run_many.__closure__}
    solver = cells["RateSolver"]
    old = rates.RateSolver(solver.mechanism, [rates.Task(t.frame, t.components, t.velocity, t.acceleration)
                                              for t in solver.tasks])
    q2 = cells["ndarray"][3]

    def motion_read():
        m = motion.evaluate_motion(mechanism, data, q, v, a, points=["D"], links=["link3"])
        return peers._pinmech_p1_row(m)

    return {"before: evaluate_motion (link3, D), P1 outputs read": Timed(motion_read),
            "before: RateSolver.solve (P2 pose)": Timed(lambda: old.solve(q2))}


def rows() -> dict[str, Timed]:
    from pinmech.solve.core import _core
    from pinmech.solve.motion import PointMotion

    pinmech, mechanism, data, q, v, a = _p1()
    run_many, _, _ = peers.pinmech_p2(*peers.p2_angles(360), many=True)
    cells = {type(c.cell_contents).__name__: c.cell_contents for c in run_many.__closure__}
    solver, Q = cells["RateSolver"], cells["ndarray"]
    q2 = Q[3]
    core = solver._compiled()
    Q1, out = Q[3:4].copy(), np.empty((1, core.rate_columns))
    plan = pinmech.evaluate_motion(mechanism, data, q, v, a, points=["D"], links=["link3"])._plan
    rows_out = np.empty((plan.rows, _core.KINEMATICS_COLUMNS))
    x = np.zeros(3)

    def motion_read():
        m = pinmech.evaluate_motion(mechanism, data, q, v, a, points=["D"], links=["link3"])
        return peers._pinmech_p1_row(m)

    def motion_all():
        m = pinmech.evaluate_motion(mechanism, data, q, v, a)
        return m.joints, m.links, m.points, m.sliders

    return {
        "evaluate_motion (link3, D), call alone": Timed(
            lambda: pinmech.evaluate_motion(mechanism, data, q, v, a, points=["D"], links=["link3"])),
        "evaluate_motion (link3, D), P1 outputs read": Timed(motion_read),
        "evaluate_motion (every point and link), all read": Timed(motion_all),
        "RateSolver.solve (P2 pose)": Timed(lambda: solver.solve(q2)),
        "floor: _core.frames_at alone (R-RTR, link3 and D)": Timed(
            lambda: _core.frames_at(mechanism.model, data, q, v, a, plan.frames, plan.joints, rows_out)),
        "floor: Core.rates on one pose alone (P2)": Timed(
            lambda: core.rates(Q1, solver.x_dot, solver.x_ddot, -1, out)),
        "floor: one nanobind call (Core.nq)": Timed(lambda: core.nq),
        "floor: a frozen dataclass of four fields": Timed(lambda: PointMotion(x, x, x, "l")),
        "floor: Mechanism.checked_q (one pose)": Timed(lambda: mechanism.checked_q(q)),
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--calls", type=int, default=2000, help="calls in one timed sample")
    parser.add_argument("--before", type=Path, help="an earlier checkout to time beside this one")
    args = parser.parse_args(argv)
    timed = rows()
    if args.before:
        timed.update(before_rows(args.before))
    for t in timed.values():
        t.calls = args.calls
        t.run()
    load = os.getloadavg()[0]
    time_rounds(list(timed.values()), args.rounds)
    print(f"{args.rounds} interleaved rounds of {args.calls} calls; load average {load:.1f} before, "
          f"{os.getloadavg()[0]:.1f} after (a shared machine: read the fastest rounds too)\n")
    print("| call | us (median) | spread (fastest - slowest round) |\n| --- | --- | --- |")
    for name, t in timed.items():
        us = [x * 1e6 for x in t.times]
        print(f"| {name} | {statistics.median(us):.3g} | {min(us):.3g} - {max(us):.3g} |")


if __name__ == "__main__":
    main()
