"""The goalie's clearing and the defenders' slots."""

from __future__ import annotations

import dataclasses
import math

import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, RobotState
from strategy.defense import DefenseParams, ball_to_clear, clear_target, defender_slots, goalie
from strategy.skills import SkillParams

FIELD = Field(LeagueParams())
P = DefenseParams()


@pytest.mark.parametrize(("n", "slots"), [(0, []), (1, [0.0]), (2, [-0.16, 0.16]), (3, [-0.32, 0.0, 0.32])])
def test_defender_slots_are_spaced_and_centred(n: int, slots: list[float]) -> None:
    assert defender_slots(DefenseParams(defenders=n, defender_spacing_m=0.32)) == pytest.approx(slots, abs=1e-12)


def _in_our_area(own_sign: float) -> tuple[float, float]:
    return own_sign * (FIELD.half_length - 0.3), 0.2


@pytest.mark.parametrize("own_sign", [-1.0, 1.0])
def test_a_still_ball_in_our_area_is_cleared_up_the_field_on_its_side(own_sign: float) -> None:
    x, y = _in_our_area(own_sign)
    ball = BallState(x, y, 0.0, 0.0)
    assert ball_to_clear(ball, FIELD, own_sign, P)
    tx, ty = clear_target(ball, FIELD, own_sign, P)
    assert tx == pytest.approx(-own_sign * FIELD.half_length * P.clear_depth_share)
    assert ty == pytest.approx(FIELD.half_width * P.clear_width_share)  # the ball's side (y > 0)
    robot = RobotState("blue", 0, own_sign * (FIELD.half_length - 0.1), 0.0, 0.0)
    intent, clears = goalie(robot, ball, FIELD, own_sign, P, SkillParams())
    assert clears and intent.allow_own_defense


@pytest.mark.parametrize(("at", "v"), [("ours", (1.0, 0.0)), ("theirs", (0.0, 0.0)), ("middle", (0.0, 0.0))])
def test_otherwise_the_goalie_blocks(at: str, v: tuple[float, float]) -> None:
    own_sign = -1.0
    x, y = {"ours": _in_our_area(own_sign), "theirs": _in_our_area(-own_sign), "middle": (0.0, 0.0)}[at]
    ball = BallState(x, y, *v)
    assert not ball_to_clear(ball, FIELD, own_sign, P)
    robot = RobotState("blue", 0, own_sign * (FIELD.half_length - 0.1), 0.0, 0.0)
    intent, clears = goalie(robot, ball, FIELD, own_sign, P, SkillParams())
    assert not clears and intent.kick_speed == 0.0
    assert abs(intent.y) <= FIELD.goal_half_width  # between the posts


@pytest.mark.parametrize("own_sign", [-1.0, 1.0])
def test_the_goalie_s_reflex_moves_it_toward_a_slow_shot_s_line(own_sign: float) -> None:
    # a shot too slow for the goalie to meet on its line (under goalie_shot_speed_m_s): blocking alone
    # stands on the line from the ball to the goal's centre; the reflex steps toward the ball's path
    skills = SkillParams()
    goal_x = own_sign * FIELD.half_length
    line_x = goal_x - own_sign * skills.goalie_depth_m
    bx, by, path_y = goal_x - own_sign * (FIELD.dims.defense_depth_m + 0.3), 0.35, -0.15
    t = 3.0  # s to the goalie's line
    ball = BallState(bx, by, (line_x - bx) / t, (path_y - by) / t)
    assert math.hypot(ball.vx, ball.vy) < skills.goalie_shot_speed_m_s and not ball_to_clear(ball, FIELD, own_sign, P)
    robot = RobotState("blue", 0, line_x, 0.0, 0.0)
    on_p = dataclasses.replace(P, goalie_reflex=True, goalie_reflex_gain_s=1.0)
    off, _ = goalie(robot, ball, FIELD, own_sign, P, skills)
    on, clears = goalie(robot, ball, FIELD, own_sign, on_p, skills)
    assert not clears and on.x == off.x
    assert path_y - 1e-12 <= on.y < off.y - 0.02  # toward the ball's path from blocking's point, not past it
    # a ball going away from our goal: no reflex
    away = BallState(bx, by, -ball.vx, ball.vy)
    assert goalie(robot, away, FIELD, own_sign, on_p, skills)[0] == \
        goalie(robot, away, FIELD, own_sign, P, skills)[0]
