"""The floor's sorts and median (cmdragons.sorting), which the other kernels use instead of numba's,
against numpy: exact agreement, ties included."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons import sorting as kern


def values_with_ties(rng: np.random.Generator, n: int, levels: int) -> np.ndarray:
    """``n`` floats drawn from ``levels`` distinct values (few levels: many ties), some negative."""
    return rng.integers(-levels // 2, levels - levels // 2, size=n).astype(np.float64) * 0.25


@pytest.mark.parametrize("n", [0, 1, 2, 3, 7, 8, 15, 16, 17, 100, 1001])
@pytest.mark.parametrize("levels", [1, 3, 50, 1_000_000])
def test_argsort_stable_equals_numpy_stable_argsort(n: int, levels: int) -> None:
    rng = np.random.default_rng(n * 7 + levels)
    for _ in range(5):
        keys = values_with_ties(rng, n, levels)
        np.testing.assert_array_equal(kern.argsort_stable(keys), np.argsort(keys, kind="stable"))


def test_argsort_stable_keeps_index_order_of_equal_keys() -> None:
    keys = np.array([2.0, 1.0, 2.0, 1.0, 0.0, 2.0])
    assert kern.argsort_stable(keys).tolist() == [4, 1, 3, 0, 2, 5]


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 36, 37, 200])
@pytest.mark.parametrize("levels", [1, 4, 256])
def test_median_equals_numpy_median(n: int, levels: int) -> None:
    rng = np.random.default_rng(n * 3 + levels)
    for _ in range(5):
        values = values_with_ties(rng, n, levels)
        before = values.copy()
        assert kern.median(values) == np.median(values)  # exactly: the same middle values, the same mean
        np.testing.assert_array_equal(values, before)  # the input is left as it was


def test_median_of_a_strided_view_and_of_nothing() -> None:
    ring = np.arange(30, dtype=np.float64).reshape(3, 10)[:, ::-1]
    assert kern.median(ring[1, :7]) == np.median(ring[1, :7])
    assert np.isnan(kern.median(np.empty(0)))


@pytest.mark.parametrize("n", [0, 1, 2, 5, 17, 60])
def test_sort_small_equals_numpy_sort(n: int) -> None:
    rng = np.random.default_rng(n)
    for _ in range(20):
        a = values_with_ties(rng, n + 4, 7)
        want = np.concatenate([np.sort(a[:n]), a[n:]])  # the tail past n stays untouched
        kern.sort_small(a, n)
        np.testing.assert_array_equal(a, want)
