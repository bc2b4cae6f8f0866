"""Time-optimal trapezoidal motion profiles, 1D and 2D (Bruce 2006 appendix B.4).

1D: from any initial velocity to a target position *and* velocity under a speed limit, an
acceleration (speed grows) and a deceleration (speed shrinks); metres, seconds (or radians for the
heading). 2D: x and y as two 1D problems whose limits are the 2D limits times cos(theta) and
sin(theta); theta is found by binary search so that both axes arrive together.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.control import _kernels as K
from cmdragons.control._kernels import heading_command  # public here: the heading's profile

__all__ = ["Profile1D", "Profile2D", "TrapezoidParams", "heading_command", "trapezoid_1d", "trapezoid_2d"]


@dataclass(frozen=True)
class TrapezoidParams(Validated):
    """configs/control.yaml ``trapezoid``: how the 2D split is searched."""

    split_iterations: int = setting(30, lo=4, hi=60)  # binary-search steps on the x/y split angle


@dataclass(frozen=True)
class Profile1D:
    """A 1D profile from velocity ``v0``: ``phases`` (k, 2) of (duration_s, acceleration), the
    total time ``duration_s`` (inf when the limits are zero but the robot must still move)."""

    v0: float
    phases: NDArray[np.float64]
    duration_s: float

    def state(self, t_s: float) -> tuple[float, float]:
        """Displacement and velocity ``t_s`` seconds from now (velocity held after the end)."""
        x, v = K.phases_state(self.phases, self.v0, float(t_s))
        return float(x), float(v)

def trapezoid_1d(distance: float, v0: float, v_target: float, v_max: float, accel: float, decel: float) -> Profile1D:
    """The time-optimal profile covering ``distance`` from velocity ``v0`` and arriving at
    ``v_target`` (clamped to ``v_max``): speeds up at ``accel``, slows down at ``decel`` (Bruce 2006
    B.4)."""
    ph, total = K.profile_1d(float(distance), float(v0), float(v_target), float(v_max), float(accel), float(decel))
    return Profile1D(float(v0), ph, float(total))


@dataclass(frozen=True)
class Profile2D:
    """Two 1D profiles that arrive together; ``theta`` splits the limits (x: cos, y: sin)."""

    x: Profile1D
    y: Profile1D
    theta: float

    @property
    def duration_s(self) -> float:
        return max(self.x.duration_s, self.y.duration_s)

    def state(self, t_s: float) -> tuple[float, float, float, float]:
        """(dx, dy, vx, vy) ``t_s`` seconds from now, field frame."""
        x, vx = self.x.state(t_s)
        y, vy = self.y.state(t_s)
        return x, y, vx, vy


def trapezoid_2d(
    delta: tuple[float, float],
    v0: tuple[float, float],
    v_target: tuple[float, float],
    v_max: float,
    accel: float,
    decel: float,
    params: TrapezoidParams | None = None,
) -> Profile2D:
    """The 2D profile to displacement ``delta`` (m, field frame) from velocity ``v0`` arriving with
    ``v_target`` (m/s); both axes arrive together (Bruce 2006 B.4)."""
    p = params or TrapezoidParams()
    dx, dy = float(delta[0]), float(delta[1])
    theta, _, _ = K.split_2d(dx, dy, float(v0[0]), float(v0[1]), float(v_target[0]), float(v_target[1]),
                             float(v_max), float(accel), float(decel), p.split_iterations)
    c, s = float(np.cos(theta)), float(np.sin(theta))
    px = trapezoid_1d(dx, v0[0], v_target[0], v_max * c, accel * c, decel * c)
    py = trapezoid_1d(dy, v0[1], v_target[1], v_max * s, accel * s, decel * s)
    return Profile2D(px, py, float(theta))
