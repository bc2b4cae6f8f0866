"""Skills in constructed scenes: the receive skill's one-touch kick."""

from __future__ import annotations

import math

import pytest

from cmdragons.geometry import wrap_angle
from cmdragons.messages import BallState, RobotState
from strategy.skills import SkillParams, receive

SKILLS = SkillParams()


@pytest.mark.parametrize(("facing_off_rad", "armed"), [
    (0.0, True),
    (SKILLS.one_touch_facing_rad * 0.8, True),
    (SKILLS.one_touch_facing_rad * 1.2, False),
    (1.1, False),  # still facing the ball it receives, not the aim: a kick now would send it back
])
def test_a_one_touch_kick_is_armed_only_facing_its_heading(facing_off_rad: float, armed: bool) -> None:
    ball = BallState(-1.0, 0.0, 2.0, 0.0)  # rolling at +x toward the receiving point
    wait_at, shoot_at = (0.0, 0.0), (3.0, 1.5)
    heading = receive(RobotState("blue", 1, 0.1, 0.0, 0.0), ball, wait_at, SKILLS, shoot_at, 5.0).theta
    robot = RobotState("blue", 1, 0.1, 0.0, heading + facing_off_rad)
    intent = receive(robot, ball, wait_at, SKILLS, shoot_at, 5.0)
    assert abs(wrap_angle(intent.theta - heading)) < 1e-9  # turning to the one-touch heading either way
    assert not intent.avoid_ball  # meeting the ball on its path
    if armed:
        assert intent.kick_speed == 5.0 and intent.dribbler == 0.0
    else:  # a ball that arrives before the robot has turned is trapped, not kicked back
        assert intent.kick_speed == 0.0 and intent.dribbler == SKILLS.hold_dribbler


def test_a_trap_faces_the_ball() -> None:
    ball = BallState(-1.0, 0.5, 2.0, 0.0)
    intent = receive(RobotState("blue", 1, 0.0, 0.0, 0.0), ball, (0.0, 0.4), SKILLS)
    assert intent.kick_speed == 0.0 and intent.dribbler == SKILLS.hold_dribbler
    assert intent.theta == pytest.approx(math.pi)  # toward the ball coming along y = 0.5
    assert intent.y == pytest.approx(0.5)  # on its path
