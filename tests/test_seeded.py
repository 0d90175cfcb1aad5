"""pinmech.seeded: the sample poses' numbers are the same from run to run, continue their
sequence call after call, and have the distributions they are named for (moments of
20,000 draws within 5 standard errors: a seeded run either passes always or never)."""

from __future__ import annotations

import math

import numpy as np

from pinmech.seeded import Seeded

N = 20_000


def test_one_seed_gives_one_sequence_continued_call_after_call():
    a, b = Seeded(7), Seeded(7)
    first, second = a.normal(3), a.normal(3)
    np.testing.assert_array_equal(np.concatenate([first, second]), b.normal(6))
    assert not np.array_equal(first, second) and not np.array_equal(Seeded(8).normal(3), first)


def test_normal_draws_have_mean_0_and_variance_1():
    x = Seeded(20261122).normal(N)
    assert x.shape == (N,) and x.dtype == np.float64
    assert abs(x.mean()) < 5 / math.sqrt(N)  # standard error of the mean: 1/sqrt(N)
    assert abs(x.var() - 1.0) < 5 * math.sqrt(2 / N)  # of the variance of a normal sample: sqrt(2/N)


def test_uniform_draws_stay_in_their_interval_with_its_mean_and_variance():
    x = Seeded(11).uniform(-1.0, 1.0, N)
    assert x.min() >= -1.0 and x.max() < 1.0
    assert abs(x.mean()) < 5 * math.sqrt(1 / 3 / N)  # variance of U(-1, 1): (b - a)^2 / 12 = 1/3
    assert abs(x.var() - 1 / 3) < 5 * math.sqrt((1 / 5 - 1 / 9) / N)  # var of x^2: E x^4 - (E x^2)^2
