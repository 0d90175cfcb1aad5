"""Condition numbers of square matrices: the compiled core's (`pinmech._core.condition`)
against numpy's SVD, timed interleaved in one process, with each one's error against the
SVD's condition number.

The core computes 2x2 in closed form, 3x3 from fixed-size eigenvalue problems, and above
that from a Householder bidiagonalization and Laguerre's method on its Golub-Kahan matrix,
with bisection on Sturm counts where Laguerre does not converge (a repeated or clustered
singular value). Two spectra at each size: a random Gaussian matrix, and one with half its
singular values equal (3) and the other half equal (0.5), which takes the bisection; from
4x4 up, a band matrix too, 2 nonzeros below the diagonal and 1 above (the dependent
Jacobian of a chain of loops in block order), which the core bidiagonalizes by plane
rotations.

Times are microseconds a call from Python (the call's overhead included: see the 1x1 row),
median of the rounds and spread (fastest - slowest round). The core's call also factors
the matrix (the LU its caller would share).

Run: python scripts/condition_time.py [--sizes 1 2 3 4 8 16 32] [--rounds 7] [--out FILE.md]
"""

from __future__ import annotations

import argparse
import statistics
import sys

import numpy as np

from interleave import Timed, machine, time_rounds

SIZES = (1, 2, 3, 4, 8, 16, 32)
CALLS = 500  # calls a sample


def with_singular_values(rng: np.random.Generator, s: np.ndarray) -> np.ndarray:
    """U diag(s) V^T with random orthogonal U, V."""
    n = len(s)
    U, _ = np.linalg.qr(rng.normal(size=(n, n)))
    V, _ = np.linalg.qr(rng.normal(size=(n, n)))
    return (U * s) @ V.T


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--out", help="also write the table to this Markdown file")
    args = parser.parse_args(argv)
    try:
        from pinmech import _core
    except ImportError as exc:
        sys.exit(f"condition_time: pinmech's compiled core is not importable ({exc})")

    rng = np.random.default_rng(0)
    cases = []
    for n in args.sizes:
        spectra = {"random": rng.normal(size=(n, n))}
        if n >= 2:
            spectra["half repeated"] = with_singular_values(rng, np.where(np.arange(n) < n // 2, 3.0, 0.5))
        if n >= 4:
            i, j = np.indices((n, n))
            spectra["band (2 below, 1 above)"] = np.where((i - j <= 2) & (j - i <= 1), rng.normal(size=(n, n)), 0.0)
        for name, A in spectra.items():
            sigma = np.linalg.svd(A, compute_uv=False)
            want = sigma[0] / sigma[-1]
            error = abs(_core.condition(A)[0] / want - 1.0)
            core = Timed(lambda A=A: _core.condition(A), calls=CALLS)
            svd = Timed(lambda A=A: np.linalg.svd(A, compute_uv=False), calls=CALLS)
            cases.append((n, name, want, error, core, svd))
    time_rounds([t for case in cases for t in case[4:]], args.rounds)

    def cell(t: Timed) -> tuple[str, str]:
        us = [x * 1e6 for x in t.times]
        return f"{statistics.median(us):.3g}", f"{min(us):.3g} - {max(us):.3g}"

    lines = [f"Condition numbers, {args.rounds} interleaved rounds of {CALLS} calls; us a call from Python; "
             f"{machine()}.", "",
             "| n | spectrum | condition | core us (median) | spread | numpy SVD us (median) | spread |"
             " core's relative error vs SVD |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for n, name, want, error, core, svd in cases:
        lines.append(f"| {n} | {name} | {want:.3g} | {' | '.join(cell(core))} | {' | '.join(cell(svd))} | {error:.1e} |")
    text = "\n".join(lines)
    print(text)
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
