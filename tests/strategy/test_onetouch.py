"""Aiming a kick against the kick model: the kick relative to the robot, part of the ball's
velocity across the heading kept."""

from __future__ import annotations

import math

import pytest

from strategy.onetouch import chip_heading, kick_heading, kicked_velocity


@pytest.mark.parametrize("robot_v", [(0.0, 0.0), (0.0, 1.0), (0.8, -0.4), (-1.0, 0.5)])
@pytest.mark.parametrize("ball_v", [(0.0, -2.0), (-3.0, 1.0), (1.0, 2.5), (0.0, 0.0)])
@pytest.mark.parametrize("target", [0.0, 0.6, -1.2])
def test_an_aimed_kick_leaves_toward_the_target_at_the_speed_asked(robot_v: tuple[float, float],
                                                                   ball_v: tuple[float, float], target: float) -> None:
    speed, retention = 5.0, 0.3
    h = kick_heading(target, speed, robot_v, ball_v, retention)
    # the kicker's speed relative to the robot: what is asked over the ground, less the robot's along the heading
    kicker = speed * math.cos(h - target) - (robot_v[0] * math.cos(h) + robot_v[1] * math.sin(h))
    vx, vy = kicked_velocity(h, kicker, robot_v, ball_v, retention)
    assert abs(math.remainder(math.atan2(vy, vx) - target, 2 * math.pi)) < 1e-9
    assert math.hypot(vx, vy) == pytest.approx(speed, abs=1e-9)
    naive = kicked_velocity(target, speed, robot_v, ball_v, retention)
    n = (-math.sin(target), math.cos(target))
    across = ((1 - retention) * (robot_v[0] * n[0] + robot_v[1] * n[1])
              + retention * (ball_v[0] * n[0] + ball_v[1] * n[1]))
    if abs(across) > 0.1:  # aiming straight at the target would miss it
        assert abs(math.remainder(math.atan2(naive[1], naive[0]) - target, 2 * math.pi)) > 0.01


def test_a_still_robot_and_ball_or_no_kick_aim_straight() -> None:
    assert kick_heading(0.7, 5.0, (0.0, 0.0), (0.0, 0.0), 0.3) == pytest.approx(0.7)
    assert kick_heading(0.7, 0.0, (1.0, -2.0), (0.0, 1.0), 0.3) == 0.7


def test_a_robot_outrunning_the_kick_faces_the_aim() -> None:
    # driving away from the aim faster than the kick: no heading sends the ball along it
    assert kick_heading(0.0, 1.0, (-2.0, 0.0), (-2.0, 0.0), 0.3) == 0.0


@pytest.mark.parametrize("robot_v", [(0.0, 0.0), (0.0, 1.0), (0.8, -0.4), (-1.0, 0.5)])
@pytest.mark.parametrize("ball_v", [(0.0, -2.0), (1.0, 2.5), (0.0, 0.0)])
@pytest.mark.parametrize("target", [0.0, 0.6, -1.2])
def test_an_aimed_chip_leaves_toward_the_target(robot_v: tuple[float, float], ball_v: tuple[float, float],
                                                target: float) -> None:
    """A chip's kicker speed is sent as asked: its horizontal part, relative to the robot, leaves the
    ball along the target's direction over the ground from the heading found (within 1e-6 rad)."""
    kicker, angle, retention = 4.0, 0.7854, 0.3
    h = chip_heading(target, kicker, angle, robot_v, ball_v, retention)
    vx, vy = kicked_velocity(h, kicker * math.cos(angle), robot_v, ball_v, retention)
    assert abs(math.remainder(math.atan2(vy, vx) - target, 2 * math.pi)) < 1e-6
    assert vx * math.cos(target) + vy * math.sin(target) > 0.0
