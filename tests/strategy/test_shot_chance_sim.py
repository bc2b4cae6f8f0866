"""A shot's chance against the simulator: kicks with a seeded normal direction error, their goals
counted in the simulator, against :func:`strategy.evaluation.shot_chance` (within 0.1, some three
binomial standard deviations of 150 kicks); and its aim against the open angle's (a post's end)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import Goal, RobotCommand
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World
from strategy.evaluation import PassParams, best_shot, shot_chance
from strategy.plays import StrategyParams

LEAGUE = LeagueParams()
FIELD = Field(LEAGUE)
FRONT = LEAGUE.robot.front_distance_m + LEAGUE.ball.radius_m  # robot centre to the ball on its kicker face
R = StrategyParams().obstacle_radius_m  # a robot's radius plus the ball's
KICK_M_S = 6.0
KICKS = 150
TOLERANCE = 0.1  # 150 kicks: a binomial standard deviation of at most 0.041


def goals_in_simulator(ball: tuple[float, float], aim: tuple[float, float], blockers: np.ndarray,
                       error_rad: float, kicks: int, rng: np.random.Generator) -> float:
    """The share of ``kicks`` shots from ``ball`` aimed at ``aim`` with a normal direction error of
    ``error_rad`` that the simulator counts as goals, the ``blockers`` (yellow) standing still."""
    base = math.atan2(aim[1] - ball[1], aim[0] - ball[0])
    goals = 0
    for error in rng.normal(0.0, error_rad, kicks):
        heading = base + float(error)
        w = World(LEAGUE, PhysicsParams(), RobotParams(), BallParams(), KickerParams(), DribblerParams(),
                  robots_per_team={"blue": 1, "yellow": len(blockers)})
        w.place_robot("blue", 0, ball[0] - (FRONT + 0.003) * math.cos(heading),
                      ball[1] - (FRONT + 0.003) * math.sin(heading), heading)
        for k, (x, y) in enumerate(blockers):
            w.place_robot("yellow", k, float(x), float(y), math.pi)
        w.place_ball(*ball)
        for n in range(90):  # 1.5 s: a 6 m/s ball crosses the goal line from 5 m in under 1 s
            events = w.step_frame([RobotCommand("blue", 0, kick_speed=KICK_M_S if n < 3 else 0.0)])
            if any(isinstance(e, Goal) for e in events):
                goals += 1
                break
    return goals / kicks


SCENES = [  # (ball, blockers, error_rad)
    ((FIELD.half_length - 5.0, 1.5), np.zeros((0, 2)), 0.1),  # open goal, from the side, far
    ((FIELD.half_length - 2.0, 0.0), np.array([[FIELD.half_length - 0.15, 0.2]]), 0.12),  # a keeper off centre
    ((FIELD.half_length - 2.5, -0.5), np.array([[FIELD.half_length - 0.6, -0.3],
                                                [FIELD.half_length - 0.15, 0.05]]), 0.08),  # a gap beside the keeper
]


@pytest.mark.parametrize(("ball", "blockers", "error_rad"), SCENES)
def test_the_shot_chance_is_the_share_of_kicks_that_score(ball: tuple[float, float], blockers: np.ndarray,
                                                          error_rad: float) -> None:
    chance, aim = shot_chance(np.array(ball), FIELD, 1.0, blockers, R, PassParams().goal_samples, error_rad)
    scored = goals_in_simulator(ball, aim, blockers, error_rad, KICKS, np.random.default_rng(7))
    assert 0.3 < chance < 0.9  # the kick's error matters: neither a sure goal nor a hopeless shot
    assert scored == pytest.approx(chance, abs=TOLERANCE)


def test_the_aim_with_the_kick_error_scores_more_than_a_posts_end() -> None:
    # a keeper covers the middle and the left: the open angle aims at the right post's end (0.1 m inside it),
    # half of whose kicks miss the post; the chance's aim stands off it by the kick's error
    ball, keeper, error_rad = (FIELD.half_length - 3.0, 0.0), np.array([[FIELD.half_length - 0.15, 0.12]]), 0.05
    _, post_aim, _ = best_shot(np.array(ball), FIELD, 1.0, keeper, R, PassParams())
    chance, aim = shot_chance(np.array(ball), FIELD, 1.0, keeper, R, PassParams().goal_samples, error_rad)
    assert post_aim[1] == pytest.approx(-(FIELD.goal_half_width - PassParams().post_margin_m))
    assert aim[1] > post_aim[1]
    at_post = goals_in_simulator(ball, post_aim, keeper, error_rad, KICKS, np.random.default_rng(11))
    at_aim = goals_in_simulator(ball, aim, keeper, error_rad, KICKS, np.random.default_rng(11))
    assert at_aim > at_post + 0.1
    assert at_aim == pytest.approx(chance, abs=TOLERANCE)


@pytest.mark.parametrize(("ball", "blockers"), [
    ((FIELD.half_length - 3.0, 0.4), np.zeros((0, 2))),
    ((FIELD.half_length - 2.0, -0.3), np.array([[FIELD.half_length - 0.15, 0.2]])),
])
def test_the_chance_is_the_same_at_either_goal(ball: tuple[float, float], blockers: np.ndarray) -> None:
    # the other goal is the mirror image: the same chance, the aim mirrored (the angles toward -x wrap at pi)
    chance, aim = shot_chance(np.array(ball), FIELD, 1.0, blockers, R, PassParams().goal_samples, 0.05)
    mirrored = np.array([[-x, y] for x, y in blockers]).reshape(-1, 2)
    other, other_aim = shot_chance(np.array([-ball[0], ball[1]]), FIELD, -1.0, mirrored, R, PassParams().goal_samples,
                                   0.05)
    assert other == pytest.approx(chance, abs=1e-9) and 0.5 < chance
    assert other_aim == pytest.approx((-aim[0], aim[1]), abs=1e-9)
