"""The project's one angle wrap (:func:`cmdragons.geometry.wrap_angle`, its very formula) compiled
for numba kernels: every package's kernels call this one, so a wrapped angle has the same bits
wherever it is computed."""

from __future__ import annotations

from collections.abc import Callable

from numba import njit

from cmdragons.geometry import wrap_angle as _wrap_angle

__all__ = ["wrap_angle"]

wrap_angle: Callable[[float], float] = njit(cache=True)(_wrap_angle)  # type: ignore[assignment]  # (numba: a float in, a float out)
