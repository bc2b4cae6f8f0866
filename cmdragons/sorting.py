"""numba kernels of the floor that other packages' kernels share: a small in-place sort, a stable
argsort and the median, written as loops over ``np.empty`` arrays (numba's generic ``argsort`` and
``median`` cost seconds of first-run compile per call site). Kept in agreement with numpy's own by
tests/test_floor_sorts.py."""

from __future__ import annotations

import numpy as np
from numba import njit

# numba's np.sort, np.argsort and np.median compile its generic sorts into every kernel that calls
# them, seconds of a fresh clone's first run each; the kernels use these instead.


@njit(cache=True)
def sort_small(a: np.ndarray, n: int) -> None:
    """Sort ``a[:n]`` ascending in place (insertion sort: for tens of values, no NaN)."""
    for i in range(1, n):
        v = a[i]
        j = i - 1
        while j >= 0 and a[j] > v:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = v


@njit(cache=True)
def argsort_stable(keys: np.ndarray) -> np.ndarray:
    """Indices that sort ``keys`` (1-d, no NaN) ascending; equal keys keep their index order (what
    ``np.argsort(keys, kind="stable")`` returns). Bottom-up merge sort, written out because numba's
    generic ``argsort`` costs seconds of first-run compile per call site."""
    n = keys.shape[0]
    idx = np.empty(n, dtype=np.int64)
    for k in range(n):
        idx[k] = k
    tmp = np.empty(n, dtype=np.int64)
    width = 1
    while width < n:
        lo = 0
        while lo < n:
            mid, hi = min(lo + width, n), min(lo + 2 * width, n)
            a, b, k = lo, mid, lo
            while a < mid and b < hi:
                if keys[idx[b]] < keys[idx[a]]:  # the right one only when strictly smaller: stable
                    tmp[k] = idx[b]
                    b += 1
                else:
                    tmp[k] = idx[a]
                    a += 1
                k += 1
            while a < mid:
                tmp[k] = idx[a]
                a += 1
                k += 1
            while b < hi:
                tmp[k] = idx[b]
                b += 1
                k += 1
            lo = hi
        idx, tmp = tmp, idx
        width *= 2
    return idx


@njit(cache=True)
def median(values: np.ndarray) -> float:
    """The median of ``values`` (1-d, no NaN), as ``np.median``: the middle value, or the mean of
    the two middle values for an even count; NaN for none."""
    n = values.shape[0]
    if n == 0:
        return np.nan
    order = argsort_stable(values)
    half = n >> 1
    if n & 1:
        return float(values[order[half]])
    return float((values[order[half - 1]] + values[order[half]]) / 2)
