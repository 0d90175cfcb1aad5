"""The core's condition numbers along a path: each search for sigma_max and sigma_min
starts from the previous matrix's values where a Sturm count brackets them (as at every
pose of a sweep), and the structural band comes from the caller. The values must stay
numpy's 2-norm condition numbers (np.linalg.cond(A, 2), an SVD: LAPACK's, independent of
the core's rotations, Laguerre steps and Sturm counts).

Bar: 1e-12 relative. Both numpy's SVD and the core's bidiagonalization are backward
stable, so each is within about n eps kappa of the exact value: at most
32 x 2.2e-16 x 100 = 7e-13 for the matrices here (n <= 32, condition numbers below 100,
checked), under the bar; a start on the wrong side of a singular value, or a band too
narrow, would be off by order one.
"""

from __future__ import annotations

import numpy as np
import pytest

import pinmech.solve.core as core
from tests.tolerance import rounding

N = 32


def _chain_like(rng: np.random.Generator, n: int = N) -> np.ndarray:
    """A block lower-bidiagonal matrix of 2x2 blocks (a chain of loops' J_dep in block
    order: each block's rows touch its columns and the last column of the block before;
    band 2 below, 1 above), entries of standard deviation 0.5."""
    A = np.zeros((n, n))
    for s in range(0, n, 2):
        A[s:s + 2, s:s + 2] = 0.5 * rng.normal(size=(2, 2))
        if s:
            A[s:s + 2, s - 1] = 0.5 * rng.normal(size=2)
    return A


def _path(A0: np.ndarray, A1: np.ndarray, steps: int, step: float) -> list[np.ndarray]:
    return [2.0 * np.eye(len(A0)) + A0 * np.cos(t) + A1 * np.sin(t) for t in step * np.arange(steps)]


def _check(As: list[np.ndarray], got: list[tuple[float, float]]) -> None:
    for A, (condition, sigma_min) in zip(As, got):
        want = np.linalg.cond(A, 2)
        assert want < 100.0  # the bar's premise
        assert condition == pytest.approx(want, rel=rounding(1.0, want))
        assert sigma_min == pytest.approx(np.linalg.svd(A, compute_uv=False)[-1], rel=rounding(1.0, want))


@pytest.mark.parametrize("step", [1e-4, 0.01, 0.2])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_warm_started_condition_numbers_along_a_path_are_numpys(seed, step):
    """A chain-like band matrix moving smoothly (steps of 1e-4 to 0.2 rad along
    2 I + A0 cos t + A1 sin t): each value from the last one's start, the band given
    (2 below, 1 above) and found by the scan, against np.linalg.cond."""
    rng = np.random.default_rng(seed)
    As = _path(_chain_like(rng), _chain_like(rng), 60, step)
    _check(As, core._core.conditions(As, 2, 1))
    _check(As, core._core.conditions(As))


@pytest.mark.parametrize("kl, ku", [(0, 0), (1, 1), (2, 1), (1, 3), (3, 2)])
def test_warm_starts_from_unrelated_matrices_are_numpys(kl, ku):
    """Unrelated band matrices in a row, of sizes 4 to 32: the last values bracket
    anything or nothing (below, between or above the new singular values), so every
    branch of the start is taken; each result against np.linalg.cond."""
    rng = np.random.default_rng(10 * kl + ku)
    As = []
    for n in rng.integers(4, N + 1, size=40):
        i, j = np.indices((n, n))
        scale = 10.0 ** rng.uniform(-3, 3)  # the last values far off in scale too
        As.append(scale * np.where((i - j <= kl) & (j - i <= ku), 0.5 * rng.normal(size=(n, n)) + 4.0 * (i == j), 0.0))
    _check(As, core._core.conditions(As, kl, ku))
    _check(As, core._core.conditions(As))


def test_a_repeated_matrix_gives_the_same_numbers():
    """The same matrix twice in a row: the second search starts at the first's values
    (on a singular value, to rounding) and must land on numpy's numbers again."""
    rng = np.random.default_rng(7)
    A = 2.0 * np.eye(N) + _chain_like(rng)
    got = core._core.conditions([A, A, A], 2, 1)
    _check([A, A, A], got)
