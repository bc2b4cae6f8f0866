"""The floor's sorts for a handful of values (cmdragons._kernels) against numpy's."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons._kernels import argsort_small, sort_small


@pytest.mark.parametrize("n", [0, 1, 2, 5, 17, 60])
def test_sort_small_equals_numpy_sort(n: int) -> None:
    rng = np.random.default_rng(n)
    for _ in range(50):
        # few distinct values, so that ties are common; a tail past n that must stay untouched
        a = rng.integers(-3, 4, n + 4).astype(np.float64) * 0.5
        want = np.concatenate([np.sort(a[:n]), a[n:]])
        sort_small(a, n)
        np.testing.assert_array_equal(a, want)


@pytest.mark.parametrize("n", [0, 1, 2, 5, 17, 60])
def test_argsort_small_is_numpy_stable_argsort(n: int) -> None:
    rng = np.random.default_rng(100 + n)
    for _ in range(50):
        keys = np.concatenate([rng.integers(-3, 4, n).astype(np.float64), rng.normal(size=3)])
        np.testing.assert_array_equal(argsort_small(keys, n), np.argsort(keys[:n], kind="stable"))
