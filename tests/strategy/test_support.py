"""Supporter placement: the best points, spread apart and off the ball; the grid re-evaluated
every few frames."""

from __future__ import annotations

import itertools
import math

import numpy as np

from cmdragons.geometry import Field, LeagueParams
from strategy.evaluation import PassEvaluation, PassParams, candidate_grid
from strategy.support import Supporters, SupportParams, spread_points

FIELD = Field(LeagueParams())
P = SupportParams(spacing_m=1.0, min_ball_distance_m=0.5)


def _evaluation(points: list[tuple[float, float]], values: list[float]) -> PassEvaluation:
    pts = np.array(points, dtype=float)
    return PassEvaluation(pts, np.array(values, dtype=float), np.zeros_like(pts))


def test_the_best_points_spread_apart_and_off_the_ball() -> None:
    ev = _evaluation([(0.2, 0.0), (2.0, 0.0), (2.5, 0.0), (2.0, 1.5), (-2.0, 0.0)],
                     [0.99, 0.9, 0.8, 0.7, 0.1])
    ball = np.array([0.0, 0.0])
    # (0.2, 0) is on the ball, (2.5, 0) too near the better (2.0, 0)
    assert spread_points(ev, ball, 3, P) == [(2.0, 0.0), (2.0, 1.5), (-2.0, 0.0)]
    assert spread_points(ev, ball, 1, P) == [(2.0, 0.0)]
    assert spread_points(ev, ball, 0, P) == []


def test_spread_points_on_a_random_evaluation_keep_their_promises() -> None:
    rng = np.random.default_rng(3)
    pts = rng.uniform([-4.0, -2.5], [4.0, 2.5], (200, 2))
    ev = _evaluation([tuple(p) for p in pts], list(rng.random(200)))
    ball = np.array([0.5, -0.3])
    chosen = spread_points(ev, ball, 4, P)
    assert len(chosen) == 4
    for a, b in itertools.combinations(chosen, 2):
        assert math.dist(a, b) >= P.spacing_m
    assert all(math.dist(c, ball) >= P.min_ball_distance_m for c in chosen)
    value = {tuple(p): v for p, v in zip(ev.points, ev.values, strict=True)}
    assert [value[c] for c in chosen] == sorted((value[c] for c in chosen), reverse=True)  # best first


def test_the_grid_is_evaluated_on_the_first_frame_and_every_nth() -> None:
    supporters = Supporters(FIELD, PassParams(), SupportParams(eval_every_frames=3), obstacle_radius=0.11)
    assert supporters.evaluation is None
    ball, opponents = np.array([0.0, 0.0]), np.array([[1.0, 0.5]])
    supporters.update(1, ball, 1.0, opponents, 2)
    first = supporters.evaluation
    assert first is not None and len(first.points) == len(candidate_grid(FIELD, PassParams()))
    assert len(supporters.points) == 2
    supporters.update(2, np.array([2.0, 1.0]), 1.0, opponents, 2)
    assert supporters.evaluation is first  # held between evaluations
    supporters.update(3, np.array([2.0, 1.0]), 1.0, opponents, 2)
    assert supporters.evaluation is not first


def test_at_our_kickoff_the_points_spread_where_the_robots_will_stand() -> None:
    # two good points beyond the halfway line a robot would stand side by side on (0.25 m apart),
    # a third well apart on our side
    ev = _evaluation([(2.0, 1.05), (0.8, 1.3), (-1.0, -1.5)], [0.9, 0.8, 0.5])
    ball = np.array([0.0, 0.0])
    assert spread_points(ev, ball, 2, P) == [(2.0, 1.05), (0.8, 1.3)]  # apart where they were evaluated
    placed = np.array([[-0.14, 1.05], [-0.14, 1.3], [-1.0, -1.5]])
    assert spread_points(ev, ball, 2, P, placed=placed) == [(-0.14, 1.05), (-1.0, -1.5)]


def _opponents_on(points: list[tuple[float, float]]) -> np.ndarray:
    return np.array(points, dtype=float)


def test_the_kickoff_points_hold_while_its_ball_waits() -> None:
    """The opponents coming to their places move the best points; held, ours stay put until the
    kickoff is over (then chosen anew)."""
    ball = np.array([0.0, 0.0])
    moved = Supporters(FIELD, PassParams(), SupportParams(eval_every_frames=1), obstacle_radius=0.11)
    held = Supporters(FIELD, PassParams(), SupportParams(eval_every_frames=1), obstacle_radius=0.11)
    moved.update(0, ball, 1.0, np.zeros((0, 2)), 3)
    held.update(0, ball, 1.0, np.zeros((0, 2)), 3, hold=True)
    first = list(held.points)
    assert first == moved.points
    blockers = _opponents_on([(x + 0.3, y) for x, y in first])  # an opponent beside each point
    moved.update(1, ball, 1.0, blockers, 3)
    held.update(1, ball, 1.0, blockers, 3, hold=True)
    assert moved.points != first
    assert held.points == first
    assert held.evaluation is not None and held.evaluated_frame == 1  # the evaluation goes on
    held.update(2, ball, 1.0, blockers, 3)  # the kickoff is over
    assert held.points == moved.points
def test_points_keep_clear_of_a_receivers_point() -> None:
    ev = _evaluation([(2.0, 0.0), (2.0, 1.5), (-2.0, 0.0)], [0.9, 0.7, 0.1])
    ball = np.array([0.0, 0.0])
    # a receiver waits at (2.05, 0.1), by the best point: the supporters take the next ones
    assert spread_points(ev, ball, 2, P, taken=[(2.05, 0.1)]) == [(2.0, 1.5), (-2.0, 0.0)]
    assert spread_points(ev, ball, 2, P, taken=[(-2.0, 2.5)]) == [(2.0, 0.0), (2.0, 1.5)]  # far: no change


def test_a_receivers_point_is_kept_clear_between_evaluations() -> None:
    supporters = Supporters(FIELD, PassParams(), SupportParams(eval_every_frames=3), obstacle_radius=0.11)
    ball, opponents = np.array([0.0, 0.0]), np.array([[1.0, 0.5]])
    supporters.update(1, ball, 1.0, opponents, 2)
    first, best = supporters.evaluation, supporters.points[0]
    supporters.update(2, ball, 1.0, opponents, 2, taken=[best])  # a pass decided to the best point's robot
    assert supporters.evaluation is first  # not re-evaluated: chosen again from the same evaluation
    assert all(math.dist(q, best) >= SupportParams().spacing_m for q in supporters.points)
    supporters.update(3, ball, 1.0, opponents, 2, taken=[best])
    assert all(math.dist(q, best) >= SupportParams().spacing_m for q in supporters.points)
    supporters.update(4, ball, 1.0, opponents, 2)  # the pass is over: the best point is a supporter's again
    assert supporters.points[0] == best
