"""The robots on the field kept at the referee's allowed count, as the league's simulation
controller keeps them: too many, the robot nearest a crossing of the halfway line and a touch line
goes, only while the game is halted or the ball is 2 m or more from the halfway line; fewer, with a
robot taken off, it comes back by the touch line near the halfway line on a free spot."""

from __future__ import annotations

import dataclasses
import math

import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, GameState, RefereeCommand, RobotState, TeamInfo, WorldState
from sim.substitution import RobotCount, RobotCountParams

FIELD = Field(LeagueParams())
SETTLE_S = RobotCountParams().settle_s


def world(t: float, ball_x: float, blue: int = 6) -> WorldState:
    """``blue`` robots of blue spread over the field (blue 3 the one nearest the halfway line at the
    bottom touch line), six of yellow, the ball at (``ball_x``, 0)."""
    spots = [(-4.0, 0.0), (-2.0, 1.0), (-2.0, -1.0), (0.4, -2.7), (1.0, 1.5), (-1.0, 2.0)]
    robots = [RobotState("blue", i, x, y, 0.0) for i, (x, y) in enumerate(spots[:blue])]
    robots += [RobotState("yellow", i, -x, -y, math.pi) for i, (x, y) in enumerate(spots)]
    return WorldState(t, BallState(ball_x, 0.0, 0.0, 0.0), tuple(robots))


def game(blue_allowed: int, command: RefereeCommand = RefereeCommand.NORMAL) -> GameState:
    return GameState(0.0, command, blue_team=dataclasses.replace(TeamInfo(), max_robots=blue_allowed),
                     yellow_team=dataclasses.replace(TeamInfo(), max_robots=6))


@pytest.mark.parametrize(("ball_x", "command", "taken"), [
    (2.5, RefereeCommand.NORMAL, True), (-2.0, RefereeCommand.STOP, True),
    (1.0, RefereeCommand.NORMAL, False), (0.0, RefereeCommand.HALT, True)])
def test_a_robot_too_many_goes_where_the_rules_allow_a_substitution(ball_x: float, command: RefereeCommand,
                                                                    taken: bool) -> None:
    count = RobotCount(FIELD, RobotCountParams())
    assert not count.step(world(0.0, ball_x), game(5, command))  # the count off: not yet settled
    change = count.step(world(SETTLE_S, ball_x), game(5, command))
    assert change.off == ((("blue", 3),) if taken else ())
    assert change.on == ()


def test_a_robot_taken_off_comes_back_by_its_touch_line_near_the_halfway_line_when_allowed() -> None:
    count = RobotCount(FIELD, RobotCountParams())
    count.step(world(0.0, 3.0), game(5))
    assert count.step(world(SETTLE_S, 3.0), game(5)).off == (("blue", 3),)
    assert not count.step(world(SETTLE_S + 0.1, 3.0, blue=5), game(5))  # five on, five allowed
    assert not count.step(world(SETTLE_S + 0.2, 3.0, blue=5), game(6))  # allowed again: not yet settled
    change = count.step(world(2 * SETTLE_S + 0.2, 3.0, blue=5), game(6))
    assert change.off == () and len(change.on) == 1
    team, rid, x, y, _ = change.on[0]
    r = FIELD.league.robot.radius_m
    assert (team, rid) == ("blue", 3)
    assert 0.0 < -x <= 1.0 and y == pytest.approx(-(FIELD.half_width - 2 * r))  # blue's half and touch line
    assert all(math.hypot(o.x - x, o.y - y) > 4 * r for o in world(0.0, 3.0, blue=5).robots)
    assert not count.step(world(3 * SETTLE_S, 3.0, blue=6), game(6))


def test_a_team_short_of_robots_it_never_took_off_and_the_count_left_alone_are_untouched() -> None:
    count = RobotCount(FIELD, RobotCountParams())
    assert not count.step(world(0.0, 3.0, blue=4), game(6))
    assert not count.step(world(5.0, 3.0, blue=4), game(6))  # none of ours off: nothing to put back
    off = RobotCount(FIELD, RobotCountParams(keep=False))
    assert not off.step(world(0.0, 3.0), game(5)) and not off.step(world(5.0, 3.0), game(5))
