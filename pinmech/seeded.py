"""Seeded pseudo-random numbers for the sample poses pinmech probes (the structural rank of
closure rows and of a task, a closed start, the check of the compiled core against the
closure rows): the same from run to run, drawn by Python's own generator (`random`, which
the standard library's tempfile loads anyway), so that a plain `pinmech solve` does not
import numpy.random and what it loads (about 10 ms of start-up, 7% of importing Pinocchio)."""

from __future__ import annotations

import random

import numpy as np


class Seeded:
    """Draws from one seed, each call continuing the sequence (as numpy's Generator does)."""

    def __init__(self, seed: int) -> None:
        self._random = random.Random(seed)

    def normal(self, size: int) -> np.ndarray:
        """`size` numbers of the standard normal distribution."""
        gauss = self._random.gauss
        return np.array([gauss(0.0, 1.0) for _ in range(size)], dtype=float)

    def uniform(self, low: float, high: float, size: int) -> np.ndarray:
        """`size` numbers uniform in [low, high)."""
        draw = self._random.uniform
        return np.array([draw(low, high) for _ in range(size)], dtype=float)
