"""Aiming a kick (Bruce 2006, appendix B.6, one-touch ball control, with the kick relative to the
robot): the heading that sends the ball off in the wanted direction.

Kick model (the simulator's, grSim's and the field's): the kicker pushes along the robot heading h
at the kicker's speed k, relative to the robot, whose velocity v_r carries over to the ball; the
ball's velocity across the heading relative to the robot, v_b - v_r, partly survives, by the
fraction c:

    v_out = k h + v_r + c ((v_b - v_r) . n) n        (n: h turned a quarter left)

Aiming straight at the target sends the ball off to the side whenever the robot or the ball moves
across the heading: a robot driving sideways at 1 m/s turns a 6 m/s shot by 0.17 rad. For the ball to
leave along the unit vector d at s over the ground, v_out = s d: across the heading that asks
(s d - (1 - c) v_r - c v_b) . n = 0, so the robot faces the direction of

    w = s d - (1 - c) v_r - c v_b

and along it the kicker fires at k = (s d - v_r) . h: s - v_r . h, as ``RobotShape.kicker_speed``
sends it, but for the cosine of the small angle between d and h. A held ball, a one-touch ball and a
ball driven through alike: v_b is the ball's velocity before the kick. Field frame, m/s, radians.

A chip is the same kick tilted up by the chip angle a: the kicker's speed k, sent as asked (the
robot's motion is not taken off it: that would change the flight's height and length), gives the
ball k cos a along h over the ground plus the same carried velocity, and k sin a up. Its
horizontal kick K = k cos a relative to the robot is fixed, not the ground speed s: along the heading
K + v_r . h = s d . h, so s and the heading are found together (:func:`chip_heading`).
"""

from __future__ import annotations

import math

__all__ = ["chip_heading", "kick_heading", "kicked_velocity"]

_CHIP_ITERATIONS = 8  # rounds of chip_heading's fixed point: the heading to well below a milliradian


def kicked_velocity(heading: float, kick_speed: float, robot_v: tuple[float, float], ball_v: tuple[float, float],
                    retention: float) -> tuple[float, float]:
    """The ball's velocity over the ground right after a flat kick at the kicker's ``kick_speed``
    (relative to the robot) from a robot at ``heading`` moving at ``robot_v``, the ball at ``ball_v``
    before it (the model above)."""
    hx, hy = math.cos(heading), math.sin(heading)
    across = (-hy * (ball_v[0] - robot_v[0]) + hx * (ball_v[1] - robot_v[1])) * retention
    return kick_speed * hx + robot_v[0] - hy * across, kick_speed * hy + robot_v[1] + hx * across


def kick_heading(direction: float, speed: float, robot_v: tuple[float, float], ball_v: tuple[float, float],
                 retention: float) -> float:
    """The robot heading (rad) that sends the ball off along ``direction`` (rad) at ``speed`` (m/s
    over the ground) from a robot moving at ``robot_v``, the ball at ``ball_v`` before the kick: the
    direction of w above. ``direction`` itself when there is no kick (``speed`` 0) or no heading
    sends the ball so (the robot's and the ball's carried velocity outrun the kick: w points back)."""
    if speed <= 0.0:
        return direction
    dx, dy = math.cos(direction), math.sin(direction)
    wx = speed * dx - (1.0 - retention) * robot_v[0] - retention * ball_v[0]
    wy = speed * dy - (1.0 - retention) * robot_v[1] - retention * ball_v[1]
    if wx * dx + wy * dy <= 0.0:
        return direction
    return math.atan2(wy, wx)


def chip_heading(direction: float, kicker_m_s: float, chip_angle_rad: float, robot_v: tuple[float, float],
                 ball_v: tuple[float, float], retention: float) -> float:
    """The robot heading (rad) from which a chip at the kicker's ``kicker_m_s`` (relative to the
    robot, tilted up by ``chip_angle_rad``) sends the ball off along ``direction`` (rad) over the
    ground, from a robot moving at ``robot_v``, the ball at ``ball_v`` before the kick (the model
    above): :func:`kick_heading` at the ground speed s that the chip's horizontal kick K gives along
    that heading, s = (K + v_r . h) / (d . h), found by fixed-point rounds from s = K + v_r . d."""
    horizontal = kicker_m_s * math.cos(chip_angle_rad)
    if horizontal <= 0.0:
        return direction
    dx, dy = math.cos(direction), math.sin(direction)
    speed = horizontal + robot_v[0] * dx + robot_v[1] * dy
    heading = direction
    for _ in range(_CHIP_ITERATIONS):
        heading = kick_heading(direction, speed, robot_v, ball_v, retention)
        hx, hy = math.cos(heading), math.sin(heading)
        along = hx * dx + hy * dy
        if along <= 0.0:
            return direction
        speed = (horizontal + robot_v[0] * hx + robot_v[1] * hy) / along
    return heading
