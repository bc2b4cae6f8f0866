"""Skills in constructed scenes: the receive skill's one-touch kick; which ball a robot holds."""

from __future__ import annotations

import math

import pytest

from cmdragons.geometry import wrap_angle
from cmdragons.messages import BallState, RobotState
from strategy.skills import SkillParams, held_ball, receive

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


OMEGA = 9.0  # rad/s: a robot turning with the ball at the cap
THETA = 0.7  # rad


def _face_ball(slip: tuple[float, float], off_m: float = 0.0) -> tuple[RobotState, BallState]:
    """A robot at (1, 2) moving at (0.2, -0.1) m/s and turning at ``OMEGA``, the ball on the middle of
    its kicker face (``off_m`` further out) moving with the face's point plus ``slip`` (m/s)."""
    c = SKILLS.contact_m + off_m
    robot = RobotState("blue", 4, 1.0, 2.0, THETA, 0.2, -0.1, OMEGA)
    # the face point's velocity, rigid body: v + omega x r (r = c along the heading)
    fvx = 0.2 - OMEGA * SKILLS.contact_m * math.sin(THETA)
    fvy = -0.1 + OMEGA * SKILLS.contact_m * math.cos(THETA)
    ball = BallState(1.0 + c * math.cos(THETA), 2.0 + c * math.sin(THETA), fvx + slip[0], fvy + slip[1])
    return robot, ball


@pytest.mark.parametrize(("slip", "off_m", "held"), [
    ((0.0, 0.0), 0.0, True),  # swung round with the face at 0.8 m/s: held
    ((0.8 * SKILLS.held_slip_m_s, 0.0), 0.0, True),  # the tracker's lag within the slip allowed
    ((0.0, -1.2 * SKILLS.held_slip_m_s), 0.0, False),  # moving off the face
    ((-1.5, 0.0), 0.0, False),  # a pass arriving on the face at 1.5 m/s is not held yet
    ((0.0, 0.0), 1.2 * SKILLS.dribble_hold_m, False),  # off the face
])
def test_a_ball_moving_with_a_robots_face_is_held(slip: tuple[float, float], off_m: float, held: bool) -> None:
    """A ball on a robot's kicker face that moves with the face (the robot's turn included) moves
    as the robot does; any other ball is as it is seen."""
    robot, ball = _face_ball(slip, off_m)
    other = RobotState("blue", 1, -2.0, 0.0, 0.0)
    played = held_ball(ball, (other, robot), SKILLS)
    assert (played.x, played.y) == (ball.x, ball.y)
    if held:
        assert (played.vx, played.vy) == pytest.approx((robot.vx, robot.vy), abs=1e-12)
    else:
        assert played == ball


def test_a_ball_a_robot_drives_onto_is_not_carried() -> None:
    """A robot driving onto a ball at rest, the ball touching its face: the ball stays at rest as
    seen (a push onto it slower than the slip does not carry it yet)."""
    robot = RobotState("blue", 2, 0.0, 0.0, 0.0, 0.8 * SKILLS.held_slip_m_s, 0.0, 0.0)
    ball = BallState(SKILLS.contact_m, 0.0, 0.0, 0.0)
    assert held_ball(ball, (robot,), SKILLS) == ball
