"""One-touch ball control (Bruce 2006, appendix B.6): aim the kicker so that the redirected ball
leaves in the wanted direction.

Kick model (the simulator's): the kicker pushes along the robot heading h with speed s; the ball's
velocity across the heading (relative to the robot) partly survives, by the fraction c:

    v_out = s h + c (v_in - (v_in . h) h)

so for a ball arriving with v_in, aiming h straight at the target sends the ball off to the side.
We solve for the heading whose outgoing velocity points at the target: the signed angle between
v_out(h) and the target direction changes monotonically near the solution, so bisection on the
heading angle finds it. Field frame, m/s, radians.
"""

from __future__ import annotations

import math

from cmdragons.geometry import wrap_angle

__all__ = ["aim_heading", "redirected_velocity"]

_BRACKET = math.pi / 2 * 0.999  # the heading is searched within this of the target direction (rad) ...
_BISECTIONS = 60  # ... in at most so many halvings


def redirected_velocity(heading: float, v_in: tuple[float, float], kick_speed: float,
                        retention: float) -> tuple[float, float]:
    """The ball's velocity right after a kick at ``heading`` (the model above)."""
    hx, hy = math.cos(heading), math.sin(heading)
    across = -hy * v_in[0] + hx * v_in[1]
    return (kick_speed * hx - hy * across * retention, kick_speed * hy + hx * across * retention)


def _error(heading: float, v_in: tuple[float, float], kick_speed: float, retention: float, target: float) -> float:
    vx, vy = redirected_velocity(heading, v_in, kick_speed, retention)
    return wrap_angle(math.atan2(vy, vx) - target)


def aim_heading(target_angle: float, v_in: tuple[float, float], kick_speed: float, retention: float,
                tolerance_rad: float = 1e-6) -> float:
    """The robot heading (rad) that sends a ball arriving with ``v_in`` off at ``target_angle``."""
    if kick_speed <= 0.0 or retention == 0.0:
        return target_angle
    # the correction is less than a right angle whenever the kick outruns the retained part
    lo, hi = target_angle - _BRACKET, target_angle + _BRACKET
    e_lo = _error(lo, v_in, kick_speed, retention, target_angle)
    e_hi = _error(hi, v_in, kick_speed, retention, target_angle)
    if e_lo * e_hi > 0:  # the retained part dominates: no heading reaches the target, get closest
        return lo if abs(e_lo) < abs(e_hi) else hi
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        e_mid = _error(mid, v_in, kick_speed, retention, target_angle)
        if abs(e_mid) < tolerance_rad:
            return mid
        if (e_mid < 0) == (e_lo < 0):
            lo, e_lo = mid, e_mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
