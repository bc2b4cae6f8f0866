"""Pass and shot evaluation in constructed scenes, against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.geometry import Field, LeagueParams
from strategy.evaluation import PassParams, best_shot, candidate_grid, lane_open_angle, open_goal_angle, pass_values
from strategy.plays import StrategyParams

FIELD = Field(LeagueParams())
R = StrategyParams().obstacle_radius_m  # robot radius plus ball radius
P = PassParams()
NONE = np.zeros((0, 2))


def test_open_goal_angle_without_obstacles_is_the_goal_mouth() -> None:
    d = 2.0
    width, aim = open_goal_angle(np.array([[FIELD.half_length - d, 0.0]]), FIELD, 1.0, NONE, R, 101, P.post_margin_m)
    gw = FIELD.goal_half_width - P.post_margin_m
    assert width[0] == pytest.approx(2 * math.atan(gw / d), rel=1e-3)
    assert aim[0] == pytest.approx(0.0, abs=1e-9)


def test_goalkeeper_shadow_moves_the_aim_to_the_far_post() -> None:
    keeper = np.array([[FIELD.half_length - 0.1, 0.25]])  # covering the left half of the goal
    origin = np.array([2.5, 0.0])
    width, aim = open_goal_angle(origin[None, :], FIELD, 1.0, keeper, R, 101, P.post_margin_m)
    gw = FIELD.goal_half_width - P.post_margin_m
    assert aim[0] == pytest.approx(-gw)  # the open right side, at its post: the keeper must cover all of the gap
    rel = keeper[0] - origin
    shadow_edge = math.atan2(rel[1], rel[0]) - math.asin(R / math.hypot(*rel))
    gap = shadow_edge - math.atan2(-gw, FIELD.half_length - origin[0])
    spacing = 2 * math.atan(gw / (FIELD.half_length - origin[0])) / 100
    assert width[0] == pytest.approx(2 * gap, abs=2 * spacing)  # counted twice: no centre aim halves it
    _, target, value = best_shot(origin, FIELD, 1.0, keeper, R, P)
    assert target[1] < 0.0 and 0 < value <= 1


def test_a_gap_between_two_blockers_is_aimed_at_its_centre() -> None:
    origin = np.array([2.5, 0.0])
    blockers = np.array([[FIELD.half_length - 0.3, 0.3], [FIELD.half_length - 0.3, -0.3]])
    width, aim = open_goal_angle(origin[None, :], FIELD, 1.0, blockers, R, 101, P.post_margin_m)
    assert aim[0] == pytest.approx(0.0, abs=0.02)
    rel = blockers - origin
    edges = np.arctan2(rel[:, 1], rel[:, 0]) + np.array([-1, 1]) * np.arcsin(R / np.hypot(rel[:, 0], rel[:, 1]))
    gw = FIELD.goal_half_width - P.post_margin_m
    spacing = 2 * math.atan(gw / (FIELD.half_length - origin[0])) / 100
    assert width[0] == pytest.approx(edges[0] - edges[1], abs=2 * spacing)


def test_lane_blocked_by_an_obstacle_on_the_line_but_not_beyond_the_receiver() -> None:
    ball = np.array([0.0, 0.0])
    target = np.array([[2.0, 0.0]])
    assert lane_open_angle(ball, target, np.array([[1.0, 0.0]]), R, 0.5)[0] == 0.0
    assert lane_open_angle(ball, target, np.array([[3.0, 0.0]]), R, 0.5)[0] == pytest.approx(1.0)
    # an obstacle beside the lane narrows it on its side only
    side = lane_open_angle(ball, target, np.array([[1.0, 0.5]]), R, 0.5)[0]
    expected = math.atan2(0.5, 1.0) - math.asin(R / math.hypot(1.0, 0.5)) + 0.5
    assert side == pytest.approx(expected, rel=1e-9)


def test_pass_evaluation_prefers_the_open_receiver() -> None:
    ball = np.array([-1.0, 0.0])
    open_receiver = np.array([1.5, 1.5])
    marked_receiver = np.array([1.5, -1.5])
    opponents = np.array([[0.25, -0.75], [3.5, 0.0]])  # one in the lane to the marked receiver
    ev = pass_values(ball, np.stack([open_receiver, marked_receiver]), FIELD, 1.0, opponents, R, P)
    assert ev.values[0] > 0.05 and ev.values[1] == 0.0


def test_grid_best_point_is_open_and_legal() -> None:
    ball = np.array([-2.0, 1.0])
    rng = np.random.default_rng(3)
    opponents = rng.uniform([-1, -3], [4.5, 3], size=(6, 2))
    pts = candidate_grid(FIELD, P)
    assert all(FIELD.in_defense_area(x, y) == 0 for x, y in pts)
    ev = pass_values(ball, pts, FIELD, 1.0, opponents, R, P)
    best, value = ev.best()
    assert value > 0
    assert lane_open_angle(ball, best[None, :], opponents, R, 1.0)[0] > 0
    assert FIELD.in_field(float(best[0]), float(best[1]), margin=P.field_margin_m - 1e-9)


@pytest.mark.parametrize("seed", range(5))
def test_the_goal_shadow_kernel_agrees_with_its_numpy_reference(seed: int) -> None:
    from strategy._kernels import goal_samples_free
    from strategy.evaluation import goal_samples_free_reference

    rng = np.random.default_rng(seed)
    points = rng.uniform([-4.5, -3.0], [4.5, 3.0], size=(200, 2))
    obstacles = rng.uniform([-4.5, -3.0], [4.5, 3.0], size=(int(rng.integers(1, 22)), 2))
    ys = np.linspace(-0.4, 0.4, 24)
    expected = goal_samples_free_reference(points, ys, 4.5, obstacles, 0.1115)
    assert np.array_equal(goal_samples_free(points, ys, 4.5, obstacles, 0.1115), expected)
    assert 0 < expected.sum() < expected.size  # some samples shadowed, some free
