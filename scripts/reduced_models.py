"""What modelling only what a scene requires saves: full robot models vs the scene's reduced one.

For the UR5, Panda and Talos scenes in models/scenes, measures in one run, per model:
size (nq, nv, joints, frames), time to load it (URDF -> pin.Model, kinematics only, no
meshes), and time to solve the scene's end-effector rate problem (q_dot and q_ddot of
the 6-D task; on a model with more joints than the scene moves, it is solved as a
minimum-norm problem over all of them). The models:

  full      every joint free, as example-robot-data's loader builds it (Talos on its
            floating base: a free-flyer root joint, nq 7 / nv 6);
  fixed     Talos only: every joint free, base fixed to the world;
  scene     what `pinmech solve` builds: the joints the scene does not move are locked
            at their scene values with pin.buildReducedModel (`move = [...]`).

The last column is what the model changes in the answer: the largest rate the
minimum-norm solution gives a joint the scene does not move (0 on the scene's model).
Also the time example-robot-data's loader takes, which also builds the visual and
collision geometry (meshes). Times are medians of repeats, on whatever machine runs this.

Run: python scripts/reduced_models.py [--out FILE.md]     (needs pip install "pinmech[robots]")
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from interleave import machine  # noqa: E402

SCENES = Path(__file__).resolve().parents[1] / "models" / "scenes"
ROBOT_SCENES = (("ur5.toml", "ur5"), ("panda.toml", "panda"), ("talos_left_arm.toml", "talos"))
LOAD_REPEATS, SOLVE_REPEATS, MESH_REPEATS = 21, 300, 3


def _median_time(fn, repeats: int) -> float:
    """Median wall time of `fn()` over `repeats` calls [s]."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _models(scene, robot: str) -> list[tuple[str, object]]:
    """(label, loader) pairs: each loader builds one Mechanism of the scene's robot."""
    from pinmech import Mechanism, load_mechanism
    from pinmech.model.robots import robot_root_joint

    urdf, root = scene.urdf, robot_root_joint(robot)
    models = [("full", lambda: Mechanism.from_urdf(urdf, root_joint=root))]
    if root is not None:
        models.append(("fixed", lambda: Mechanism.from_urdf(urdf)))
    models.append(("scene", lambda: load_mechanism(scene)))
    return models


def measure(scene_name: str, robot: str) -> list[dict]:
    """One row per model of the scene's robot: size, load time [ms], solve time [us], method,
    and the largest rate the minimum-norm answer gives a joint the scene holds still."""
    import pinmech
    from pinmech.io.analysis_task import scene_pose, scene_tasks

    scene = pinmech.Scene.load(SCENES / scene_name)
    moved = set(pinmech.load_mechanism(scene).joints)
    rows = []
    for label, load in _models(scene, robot):
        mech = load()
        q, _, _ = scene_pose(scene, mech)
        solver = pinmech.RateSolver(mech, scene_tasks(scene))
        solution = solver.solve(q)
        held = [solution.v[j.idx_v : j.idx_v + j.nv] for n, j in mech.joints.items() if n not in moved and j.nv]
        rows.append({
            "held_rate": max((float(abs(x).max()) for x in held), default=0.0),
            "model": label, "nq": mech.model.nq, "nv": mech.model.nv, "joints": mech.model.njoints - 1,
            "frames": mech.model.nframes, "load_ms": 1e3 * _median_time(load, LOAD_REPEATS),
            "solve_us": 1e6 * _median_time(lambda solver=solver, q=q: solver.solve(q), SOLVE_REPEATS),
            "method": solution.method,
        })
    return rows


def load_with_meshes_ms(robot: str) -> float:
    """example-robot-data's own loader (model, visual and collision geometry) [ms]."""
    import example_robot_data as erd

    return 1e3 * _median_time(lambda: erd.load(robot), MESH_REPEATS)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="also write the Markdown report to this file")
    args = parser.parse_args(argv)
    try:
        import example_robot_data  # noqa: F401
    except ImportError:
        print('this script needs the robots extra: pip install "pinmech[robots]"')
        return
    lines = [f"Medians of {LOAD_REPEATS} loads, {SOLVE_REPEATS} rate solves, {MESH_REPEATS} loads with meshes; "
             f"{machine()}.", "",
             "| scene | model | nq | nv | joints | frames | load [ms] | rate solve [us] | method | "
             "largest rate of a joint the scene holds [rad/s or m/s] |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for scene, robot in ROBOT_SCENES:
        rows = measure(scene, robot)
        for r in rows:
            lines.append(f"| {scene} | {r['model']} | {r['nq']} | {r['nv']} | {r['joints']} | {r['frames']} | "
                         f"{r['load_ms']:.1f} | {r['solve_us']:.0f} | {r['method']} | {r['held_rate']:.3g} |")
        full, reduced = rows[0], rows[-1]
        lines.append(f"| {scene} | ratio full / scene | | | | | {full['load_ms'] / reduced['load_ms']:.2f} | "
                     f"{full['solve_us'] / reduced['solve_us']:.2f} | | |")
        lines.append(f"| {scene} | example-robot-data loader, with meshes | | | | | "
                     f"{load_with_meshes_ms(robot):.0f} | | | |")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.out:
        args.out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
