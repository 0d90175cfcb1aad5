"""What modelling only what a scene requires saves: full robot model vs the scene's reduced one.

For the UR5, Panda and Talos scenes in models/scenes, measures in one run: model size
(nq, nv, joints, frames), time to load (URDF -> pin.Model, no meshes), time to solve the
scene's end-effector rate problem, for the full model (every joint free; the task solved
as a minimum-norm problem) and for the scene's model (joints the scene does not move are
locked out with pin.buildReducedModel). Also the load time with meshes, as
example-robot-data's loader builds it, for comparison. Times are medians of repeats.

Run: python scripts/reduced_models.py      (needs pip install "pinmech[robots]")
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

SCENES = Path(__file__).resolve().parents[1] / "models" / "scenes"


def _median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def measure(scene_name: str) -> list[dict]:
    import pinmech
    from pinmech.analysis import load_mechanism
    from pinmech.analysis_task import scene_pose, scene_tasks
    from pinmech.solve_rates import RateSolver

    scene = pinmech.Scene.load(SCENES / scene_name)
    full_raw = {k: v for k, v in scene.raw.items() if k != "move"}
    full_scene = pinmech.Scene(scene.path, full_raw)
    rows = []
    for label, sc in (("full", full_scene), ("scene", scene)):
        load = _median_time(lambda sc=sc: load_mechanism(sc), 5)
        mech = load_mechanism(sc)
        q, _, _ = scene_pose(sc, mech)
        solver = RateSolver(mech, scene_tasks(sc))
        solve = _median_time(lambda solver=solver, q=q: solver.solve(q), 200)
        rows.append({"model": label, "nq": mech.model.nq, "nv": mech.model.nv, "joints": mech.model.njoints - 1,
                     "frames": mech.model.nframes, "load_ms": 1e3 * load, "solve_us": 1e6 * solve,
                     "method": solver.solve(q).method})
    return rows


def load_with_meshes_ms(robot: str) -> float:
    import example_robot_data as erd

    return 1e3 * _median_time(lambda: erd.load(robot), 3)


def main() -> None:
    try:
        import example_robot_data  # noqa: F401
    except ImportError:
        print('this script needs the robots extra: pip install "pinmech[robots]"')
        return
    print("| scene | model | nq | nv | joints | frames | load [ms] | solve [us] | method |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for scene, robot in (("ur5.toml", "ur5"), ("panda.toml", "panda"), ("talos_left_arm.toml", "talos")):
        rows = measure(scene)
        for r in rows:
            print(f"| {scene} | {r['model']} | {r['nq']} | {r['nv']} | {r['joints']} | {r['frames']} | "
                  f"{r['load_ms']:.2f} | {r['solve_us']:.0f} | {r['method']} |")
        full, reduced = rows
        print(f"| {scene} | ratio full/scene | | | | | {full['load_ms'] / reduced['load_ms']:.2f} | "
              f"{full['solve_us'] / reduced['solve_us']:.2f} | |")
        print(f"| {scene} | example-robot-data loader (meshes, collisions) | | | | | "
              f"{load_with_meshes_ms(robot):.0f} | | |")
    np.set_printoptions()


if __name__ == "__main__":
    main()
