"""One pose through the public API (issue 23, item 3): `evaluate_motion` and
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

    python scripts/benchmark_pose.py [--rounds 7]
"""

from __future__ import annotations

import argparse
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


def rows() -> dict[str, Timed]:
    from pinmech.solve.core import _core
    from pinmech.solve.motion import PointMotion

    pinmech, mechanism, data, q, v, a = _p1()
    run_many, _, _ = peers.pinmech_p2(*peers.p2_angles(360), many=True)
    cells = {type(c.cell_contents).__name__: c.cell_contents for c in run_many.__closure__}
    solver, Q = cells["RateSolver"], cells["ndarray"]
    q2 = Q[3]
    core, row_scale, v_scale = solver._compiled()
    plan_motion = pinmech.evaluate_motion(mechanism, data, q, v, a, points=["D"], links=["link3"])
    plan = plan_motion._plan
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
            lambda: _core.frames_at(mechanism.model, data, q, v, a, plan.frames, plan.joints)),
        "floor: Core.rates on one pose alone (P2)": Timed(
            lambda: core.rates(Q[3:4], solver.x_dot, solver.x_ddot, row_scale, v_scale, 0, 1e-3,
                               solver.max_condition, -1)),
        "floor: one nanobind call (Core.nq)": Timed(lambda: core.nq),
        "floor: a frozen dataclass of four fields": Timed(lambda: PointMotion(x, x, x, "l")),
        "floor: Mechanism.checked_q (one pose)": Timed(lambda: mechanism.checked_q(q)),
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--calls", type=int, default=2000, help="calls in one timed sample")
    args = parser.parse_args(argv)
    timed = rows()
    for t in timed.values():
        t.calls = args.calls
        t.run()
    time_rounds(list(timed.values()), args.rounds)
    print("| call | us (median) | spread (fastest - slowest round) |\n| --- | --- | --- |")
    for name, t in timed.items():
        us = [x * 1e6 for x in t.times]
        print(f"| {name} | {statistics.median(us):.3g} | {min(us):.3g} - {max(us):.3g} |")


if __name__ == "__main__":
    main()
