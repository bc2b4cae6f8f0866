"""One-touch redirection in the simulator: the kicker, aimed with the kick model, sends the ball
within 5 degrees of the target."""

from __future__ import annotations

import math

import pytest

from cmdragons.geometry import LeagueParams
from cmdragons.messages import RobotCommand
from sim.world import BallParams, DribblerParams, Kick, KickerParams, PhysicsParams, RobotParams, World
from strategy.onetouch import kick_heading

LEAGUE = LeagueParams()
CONTACT = LEAGUE.robot.front_distance_m + LEAGUE.ball.radius_m


@pytest.mark.parametrize(("target_deg", "turn_deg", "speed"), [
    (0.0, 40.0, 2.0), (30.0, -60.0, 1.5), (-20.0, 70.0, 2.5), (90.0, 20.0, 1.0), (180.0, -45.0, 3.0)])
def test_one_touch_leaves_toward_the_target(target_deg: float, turn_deg: float, speed: float) -> None:
    # the ball comes from target + turn (seen from the robot): a turn a kicker can make (< 75 degrees)
    incoming_deg = target_deg + turn_deg
    kicker = KickerParams()
    w = World(LEAGUE, PhysicsParams(), RobotParams(), BallParams(), kicker, DribblerParams(),
              robots_per_team={"blue": 1, "yellow": 0})
    # the ball comes from the direction incoming_deg (seen from the robot) and rolls at it
    come_from = math.radians(incoming_deg)
    v_in = (-speed * math.cos(come_from), -speed * math.sin(come_from))
    target = math.radians(target_deg)
    kick = 4.0
    heading = kick_heading(target, kick, (0.0, 0.0), v_in, kicker.tangential_retention)  # the robot stands still
    # stand so the ball meets the middle of the kicker face
    rx, ry = -CONTACT * math.cos(heading), -CONTACT * math.sin(heading)
    w.place_robot("blue", 0, rx, ry, heading)
    start = 0.8
    w.place_ball(start * math.cos(come_from), start * math.sin(come_from))
    w.ball_body.velocity = v_in
    w._start_slide(0.0)  # already rolling: keep the rolling deceleration  # noqa: SLF001
    kicked = False
    for _ in range(120):
        events = w.step_frame([RobotCommand("blue", 0, kick_speed=kick)])
        if any(isinstance(e, Kick) for e in events):
            kicked = True
            break
    assert kicked
    vx, vy = w.ball_body.velocity
    assert abs(math.degrees(math.remainder(math.atan2(vy, vx) - target, 2 * math.pi))) < 5.0
