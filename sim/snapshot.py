"""The simulator's state at one instant as plain arrays: what the renderer draws."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["BALL_COLUMNS", "ROBOT_COLUMNS", "Snapshot"]

BALL_COLUMNS = ("x", "y", "z", "vx", "vy", "vz")
ROBOT_COLUMNS = ("team", "id", "x", "y", "theta", "vx", "vy", "omega")  # team: 0 blue, 1 yellow


@dataclass(frozen=True)
class Snapshot:
    """Field frame, SI units. ``ball`` has shape (6,), ``robots`` shape (n, 8); see the columns."""

    t: float
    frame_number: int
    ball: NDArray[np.float64]
    robots: NDArray[np.float64]
