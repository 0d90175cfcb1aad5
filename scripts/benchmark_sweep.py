"""The speed/accuracy trade of an R-RTR cycle, measured in one run on this machine.

For each setting: the median time per pose (median over 5 repeats of a 3600-pose cycle,
divided by 3600) and the largest relative error of D's position, velocity and
acceleration over the cycle against the independent closed form (scripts/closed_form.py).
Relative error = max |pinmech - closed form| over the cycle / max |closed form| over it.
Two references are measured in the same run: the closed form itself (vectorized numpy,
the lower bound) and the bare Pinocchio calls one pose needs (kinematics, frame
placements, frame Jacobians, classical accelerations; no solver logic), the floor of a
Pinocchio-based tool.

Run: python scripts/benchmark_sweep.py [--poses 3600] [--repeats 5] [--out benchmark.md]
"""

from __future__ import annotations

import argparse
import functools
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))
import closed_form

import pinmech

ROOT = Path(__file__).resolve().parents[1]
OMEGA1 = -50 * np.pi / 30
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@functools.cache
def _setup(tol: float = 1e-13):
    """Model, solver and branch guess, built once per tolerance: loading is not timed per pose."""
    mech = pinmech.Mechanism.from_urdf(ROOT / "models" / "r_rtr.urdf")
    solver = pinmech.LoopSolver(mech, ["A"], tol=tol)
    guess = mech.neutral()
    mech.set_coordinate(guess, "B", np.radians(20))
    mech.set_coordinate(guess, "B_slider", -0.06)
    return mech, solver, guess


def _read_d(mech, data, fid, q, v, a, out, i):
    pin.forwardKinematics(mech.model, data, q, v, a)
    pin.updateFramePlacements(mech.model, data)
    out[0][i] = data.oMf[fid].translation[:2]
    out[1][i] = pin.getFrameVelocity(mech.model, data, fid, LWA).linear[:2]
    out[2][i] = pin.getFrameClassicalAcceleration(mech.model, data, fid, LWA).linear[:2]


def run_exact(phis, *, tol=1e-13, warm=True, predictor=False):
    """pinmech's solver pose by pose; returns D's (position, velocity, acceleration)."""
    mech, solver, guess0 = _setup(tol)
    fid, data = mech.frame_id("D"), mech.model.createData()
    out = [np.zeros((len(phis), 2)) for _ in range(3)]
    guess, prev = guess0, None
    for i, phi in enumerate(phis):
        if predictor and prev is not None:
            dt = (phi - phis[i - 1]) / OMEGA1
            guess = pin.integrate(mech.model, prev.q, prev.v * dt + 0.5 * prev.a * dt * dt)
        elif not warm:
            guess = guess0
        sol = solver.solve([phi], [OMEGA1], [0.0], guess=guess)
        guess, prev = sol.q, sol
        _read_d(mech, data, fid, sol.q, sol.v, sol.a, out, i)
    return out


def run_finite_differences(phis):
    """Positions by Newton only (warm start); velocities and accelerations by central
    differences in time over the periodic cycle."""
    mech, solver, guess = _setup()
    fid, data = mech.frame_id("D"), mech.model.createData()
    dt = (phis[1] - phis[0]) / OMEGA1
    pos = np.zeros((len(phis), 2))
    for i, phi in enumerate(phis):
        guess, _, _ = solver.close(guess, [phi])
        pin.framesForwardKinematics(mech.model, data, guess)
        pos[i] = data.oMf[fid].translation[:2]
    vel = (np.roll(pos, -1, 0) - np.roll(pos, 1, 0)) / (2 * dt)  # the cycle is periodic
    acc = (np.roll(pos, -1, 0) - 2 * pos + np.roll(pos, 1, 0)) / dt**2
    return [pos, vel, acc]


def run_hermite(phis, every=10):
    """Exact poses every `every` steps; D's motion in between by quintic Hermite interpolation
    of its position from the exact position, velocity and acceleration (time as parameter)."""
    coarse = phis[::every]
    exact = run_exact(np.append(coarse, coarse[0] + 2 * np.pi), predictor=True)
    t = (np.append(coarse, coarse[0] + 2 * np.pi) - phis[0]) / OMEGA1
    tq = (phis - phis[0]) / OMEGA1
    idx = np.minimum((np.arange(len(phis)) // every), len(coarse) - 1)
    h = t[idx + 1] - t[idx]
    s = ((tq - t[idx]) / h)[:, None]
    p0, p1 = exact[0][idx], exact[0][idx + 1]
    v0, v1 = exact[1][idx] * h[:, None], exact[1][idx + 1] * h[:, None]
    a0, a1 = exact[2][idx] * (h**2)[:, None], exact[2][idx + 1] * (h**2)[:, None]
    basis = [1 - 10 * s**3 + 15 * s**4 - 6 * s**5, s - 6 * s**3 + 8 * s**4 - 3 * s**5,
             0.5 * s**2 - 1.5 * s**3 + 1.5 * s**4 - 0.5 * s**5, 10 * s**3 - 15 * s**4 + 6 * s**5,
             -4 * s**3 + 7 * s**4 - 3 * s**5, 0.5 * s**3 - s**4 + 0.5 * s**5]
    d1 = [-30 * s**2 + 60 * s**3 - 30 * s**4, 1 - 18 * s**2 + 32 * s**3 - 15 * s**4,
          s - 4.5 * s**2 + 6 * s**3 - 2.5 * s**4, 30 * s**2 - 60 * s**3 + 30 * s**4,
          -12 * s**2 + 28 * s**3 - 15 * s**4, 1.5 * s**2 - 4 * s**3 + 2.5 * s**4]
    d2 = [-60 * s + 180 * s**2 - 120 * s**3, -36 * s + 96 * s**2 - 60 * s**3, 1 - 9 * s + 18 * s**2 - 10 * s**3,
          60 * s - 180 * s**2 + 120 * s**3, -24 * s + 84 * s**2 - 60 * s**3, 3 * s - 12 * s**2 + 10 * s**3]
    coeffs = [p0, v0, a0, p1, v1, a1]
    pos = sum(b * c for b, c in zip(basis, coeffs))
    vel = sum(b * c for b, c in zip(d1, coeffs)) / h[:, None]
    acc = sum(b * c for b, c in zip(d2, coeffs)) / (h**2)[:, None]
    return [pos, vel, acc]


def run_floor(phis):
    """The bare Pinocchio calls of one pose, at a fixed closed configuration."""
    mech, solver, guess = _setup()
    sol = solver.solve([phis[0]], [OMEGA1], [0.0], guess=guess)
    model, data = mech.model, mech.model.createData()
    cut = mech.closures[0]
    fp, fc, fd = cut.parent_frame, cut.child_frame, mech.frame_id("D")
    zero = np.zeros(model.nv)
    for _ in phis:
        pin.computeJointJacobians(model, data, sol.q)
        pin.updateFramePlacements(model, data)
        pin.getFrameJacobian(model, data, fp, LWA)
        pin.getFrameJacobian(model, data, fc, LWA)
        pin.forwardKinematics(model, data, sol.q, sol.v, zero)
        pin.getFrameClassicalAcceleration(model, data, fp, LWA)
        pin.getFrameClassicalAcceleration(model, data, fc, LWA)
        pin.getFrameClassicalAcceleration(model, data, fd, LWA)


def run_closed_form(phis):
    cf = closed_form.r_rtr(phis, OMEGA1, 0.0)
    return [cf.D, cf.vD, cf.aD]


def _error(result, reference):
    if result is None:
        return ["", "", ""]
    return [float(np.max(np.abs(r - c)) / np.max(np.abs(c))) for r, c in zip(result, reference)]


def path_table(repeats: int) -> str:
    """Text 17.110's task followed for 0.08 s: time per step and largest drift vs the step."""
    from pinmech.analysis import load_mechanism
    from pinmech.analysis_task import scene_pose, scene_tasks
    from pinmech.path import follow_path

    scene = pinmech.Scene.load(ROOT / "models" / "scenes" / "planar_arm.toml")
    mech = load_mechanism(scene)
    q0, _, _ = scene_pose(scene, mech)
    tasks = scene_tasks(scene)
    lines = ["| step [s] | feedback gain [1/s] | time per step [us] | largest drift [m] |", "| --- | --- | --- | --- |"]
    for step in (1e-2, 1e-3, 1e-4):
        for gain in (0.0, 50.0):
            times, drift = [], 0.0
            for _ in range(repeats):
                start = time.perf_counter()
                points = list(follow_path(mech, tasks, q0, duration=0.08, step=step, gain=gain))
                times.append((time.perf_counter() - start) / len(points))
                drift = max(p.drift for p in points)
            lines.append(f"| {step:g} | {gain:g} | {1e6 * statistics.median(times):.0f} | {drift:.1e} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=3600)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--out", default=None, help="also write the markdown table here")
    parser.add_argument("--plot", default=None, help="also draw time against error here (PNG; pinmech[plot])")
    args = parser.parse_args(argv)
    phis = np.radians(30) + np.linspace(0, 2 * np.pi, args.poses, endpoint=False)
    reference = run_closed_form(phis)
    settings = [
        ("closed form, vectorized numpy (lower bound)", run_closed_form),
        ("bare Pinocchio calls of one pose (floor)", run_floor),
        ("default: predictor, tol 1e-13, analytic rates", lambda p: run_exact(p, predictor=True)),
        ("warm start from the previous pose, no predictor", run_exact),
        ("cold start (every pose from the scene's guess)", lambda p: run_exact(p, warm=False)),
        ("predictor, loose tolerance 1e-6", lambda p: run_exact(p, tol=1e-6, predictor=True)),
        ("finite differences of positions (tol 1e-13)", run_finite_differences),
        ("quintic Hermite, exact every 10th pose", run_hermite),
    ]
    rows = []
    for name, fn in settings:
        times = []
        for _ in range(args.repeats):
            start = time.perf_counter()
            result = fn(phis)
            times.append((time.perf_counter() - start) / args.poses)
        rows.append((name, statistics.median(times), _error(result, reference)))
    default = rows[2][1]
    lines = ["| setting | time per pose [us] | vs floor | vs default | rel. error position | velocity | acceleration |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for name, t, errs in rows:
        cells = [f"{e:.1e}" if e != "" else "-" for e in errs]
        lines.append(f"| {name} | {1e6 * t:.1f} | {t / rows[1][1]:.0f}x | {t / default:.2f} | " + " | ".join(cells) + " |")
    table = "\n".join(lines)
    print(f"{args.poses} poses, median of {args.repeats} runs, numpy {np.__version__}, pin {pin.__version__}\n")
    print(table)
    paths = path_table(args.repeats)
    print("\nArm path (text 17.110, D at 1 m/s along x for 0.08 s, CD vertical):\n")
    print(paths)
    if args.out:
        Path(args.out).write_text(table + "\n\n" + paths + "\n", encoding="utf-8")
    if args.plot:
        plot_trade(rows, args.plot)


def plot_trade(rows, path: str) -> None:
    """Time per pose against the acceleration error, one marker per setting (log-log)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print('the plot needs matplotlib: pip install "pinmech[plot]"')
        return
    fig, ax = plt.subplots(figsize=(11, 5))
    for name, t, errs in rows:
        if errs[2] == "":
            ax.axvline(1e6 * t, color="0.5", linestyle=":", label=name)
            continue
        ax.scatter(1e6 * t, max(errs[2], 1e-17), s=50, label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per pose [us]")
    ax.set_ylabel("largest relative error of a_D over the cycle")
    ax.set_title("R-RTR cycle: speed against accuracy (median of repeats, this machine)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(1.02, 0.0))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"figure written to {path}")


if __name__ == "__main__":
    main()
