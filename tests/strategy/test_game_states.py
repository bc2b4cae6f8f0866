"""Game states against the rules, one function at a time."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, GameState, RefereeCommand, RobotState
from strategy.game_states import (
    GameStateParams,
    halt,
    hold_shape,
    keep_away,
    keep_off_line,
    our_kickoff,
    own_goal_sign,
    restart_rules,
)
from strategy.skills import Intent

FIELD = Field(LeagueParams())
P = GameStateParams()
RADIUS = 0.09
CIRCLE = FIELD.dims.center_circle_radius_m


def _intents(rng: np.random.Generator, n: int) -> dict[int, Intent]:
    xy = rng.uniform([-4.4, -2.9], [4.4, 2.9], (n, 2))
    return {i: Intent(float(x), float(y), 0.3, kick_speed=2.0) for i, (x, y) in enumerate(xy)}


@pytest.mark.parametrize(("team", "blue_negative", "sign"), [
    ("blue", True, -1.0), ("blue", False, 1.0), ("yellow", True, 1.0), ("yellow", False, -1.0)])
def test_own_goal_sign(team: str, blue_negative: bool, sign: float) -> None:
    game = GameState(0.0, "normal", blue_defends_negative_x=blue_negative)
    assert own_goal_sign(team, game) == sign  # type: ignore[arg-type]


def test_halt_stands_everyone_where_it_is() -> None:
    own = {3: RobotState("blue", 3, 1.0, -2.0, 0.4)}
    assert halt(own) == {3: Intent(1.0, -2.0, 0.4, max_speed_m_s=0.0)}


@pytest.mark.parametrize("own_sign", [-1.0, 1.0])
def test_without_a_ball_the_team_holds_a_shape_in_our_half(own_sign: float) -> None:
    own = {i: RobotState("blue", i, 0.0, 0.0, 0.0) for i in range(6)}
    out = hold_shape(own, FIELD, own_sign, P)
    assert all(it.x * own_sign > 0 and abs(it.x) < FIELD.half_length for it in out.values())
    assert len({(it.x, it.y) for it in out.values()}) == 6


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("kickoff", [False, True])
def test_keep_away_holds_the_distance_on_the_field(seed: int, kickoff: bool) -> None:
    rng = np.random.default_rng(seed)
    bx, by = (0.0, 0.0) if kickoff else rng.uniform([-4.4, -2.9], [4.4, 2.9])
    ball = BallState(float(bx), float(by), 0.0, 0.0)
    out = keep_away(_intents(rng, 8), ball, FIELD, -1.0, P, RADIUS, kickoff=kickoff, slow=True)
    for it in out.values():
        assert math.hypot(it.x - ball.x, it.y - ball.y) >= P.stop_distance_m + RADIUS - 1e-9
        assert abs(it.x) <= FIELD.half_length - RADIUS + 1e-9 and abs(it.y) <= FIELD.half_width - RADIUS + 1e-9
        assert it.max_speed_m_s == P.stop_speed_m_s and it.kick_speed == 0.0
        if kickoff:
            assert it.x < 0.0 and math.hypot(it.x, it.y) >= CIRCLE + RADIUS


@pytest.mark.parametrize("ball", [(-4.31, 1.31), (-4.31, -1.31), (-3.3, 0.0), (4.31, 1.1), (3.3, -0.5)])
def test_keep_away_places_no_one_in_a_defense_area_it_may_not_enter(ball: tuple[float, float]) -> None:
    """A free kick by a defense area: the places round the ball that lie in an area (with the
    robot's radius and ``area_clear_m``) are skipped; the goalie may stay in ours."""
    b = BallState(*ball, 0.0, 0.0)
    # defenders' places round the area's edge (outside it), on the ball's side of the field
    edge = FIELD.half_length - FIELD.dims.defense_depth_m - RADIUS - 0.15
    wide = FIELD.dims.defense_width_m / 2 + RADIUS + 0.15
    places = [(edge, -0.6), (edge, 0.0), (edge, 0.6), (3.8, wide), (4.2, wide), (3.8, -wide), (4.2, -wide)]
    toward_area = {k: Intent(math.copysign(x, ball[0]), y, 0.0) for k, (x, y) in enumerate(places)}
    goalie = Intent(-FIELD.half_length + 0.2, ball[1] * 0.3, 0.0, allow_own_defense=True)
    out = keep_away({**toward_area, 9: goalie}, b, FIELD, -1.0, P, RADIUS, kickoff=False, slow=True)
    for rid, it in out.items():
        assert math.hypot(it.x - b.x, it.y - b.y) >= P.stop_distance_m + RADIUS - 1e-9
        side = FIELD.in_defense_area(it.x, it.y, RADIUS + P.area_clear_m - 1e-9)
        assert side == 0 or (rid == 9 and side == -1)


@pytest.mark.parametrize("ball", [(-4.45, 1.45), (0.3, -0.2), (2.0, 2.85)])
def test_keep_away_spreads_robots_sent_to_one_spot(ball: tuple[float, float]) -> None:
    """Two defenders (or more) whose places fall inside the ball's circle together are moved to
    places ``spread_m`` apart round it, not to one spot where they stand body to body (a push moves
    one into the other); a place outside the circle stays where it is."""
    b = BallState(*ball, 0.0, 0.0)
    side = math.copysign(0.2, -ball[1])
    crowd = {k: Intent(ball[0] + 0.3 + 0.01 * k, ball[1] + side + 0.01 * k, 0.0) for k in range(4)}
    far = Intent(ball[0] + math.copysign(1.5, -ball[0]), ball[1] + side, 0.0)
    out = keep_away({**crowd, 7: far}, b, FIELD, -1.0, P, RADIUS, kickoff=False, slow=True)
    assert (out[7].x, out[7].y) == (far.x, far.y)
    places = [(it.x, it.y) for it in out.values()]
    gaps = [math.dist(p, q) for i, p in enumerate(places) for q in places[i + 1:]]
    assert min(gaps) >= P.spread_m - 1e-9
    for it in out.values():
        assert math.hypot(it.x - b.x, it.y - b.y) >= P.stop_distance_m + RADIUS - 1e-9
        assert abs(it.x) <= FIELD.half_length - RADIUS + 1e-9 and abs(it.y) <= FIELD.half_width - RADIUS + 1e-9
    # without the spread, the four crowd the circle's nearest spot, closer than two bodies
    tight = keep_away(crowd, b, FIELD, -1.0, dataclasses.replace(P, spread_m=0.0), RADIUS, kickoff=False, slow=True)
    spots = [(it.x, it.y) for it in tight.values()]
    assert max(math.dist(p, q) for p in spots for q in spots) < 2 * RADIUS


def _segment_distance(q: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
    d = np.subtract(b, a)
    u = float(np.clip(np.dot(np.subtract(q, a), d) / np.dot(d, d), 0.0, 1.0))
    return float(np.hypot(*(np.subtract(q, a) - u * d)))


@pytest.mark.parametrize(("ball", "target"), [
    ((4.4, 2.9), (3.5, 2.0)),  # out of a corner, diagonally
    ((-4.4, -2.9), (-4.3, -1.5)),  # out of a corner, along the goal line
    ((0.0, 2.9), (1.0, 2.8)),  # along the touch line
    ((1.0, 0.0), (-1.0, 0.5)),  # mid-field
])
def test_keep_off_line_leaves_the_placement_room_even_in_a_corner(ball: tuple[float, float],
                                                                  target: tuple[float, float]) -> None:
    """Every place at least placement_line_m (plus the radius) off the ball's way to its target and
    on the field, wherever the robots were: in a corner neither side of the line has room, and a
    robot clamped back into the field stood by the ball in the placer's way."""
    rng = np.random.default_rng(3)
    near = {k: Intent(float(ball[0] + dx), float(ball[1] + dy), 0.0)
            for k, (dx, dy) in enumerate(rng.uniform(-0.6, 0.6, (12, 2)))}
    out = keep_off_line(near, ball, target, FIELD, P, RADIUS)
    for it in out.values():
        assert abs(it.x) <= FIELD.half_length - RADIUS + 1e-9 and abs(it.y) <= FIELD.half_width - RADIUS + 1e-9
        assert _segment_distance((it.x, it.y), ball, target) >= P.placement_line_m + RADIUS - 1e-9


def test_at_our_kickoff_all_but_the_kicker_stay_in_our_half_outside_the_circle() -> None:
    intents = _intents(np.random.default_rng(7), 8)
    intents[0] = Intent(0.1, 0.05, 0.0, kick_speed=3.0)  # the kicker at the ball
    out = our_kickoff(intents, FIELD, 1.0, P, RADIUS, kicker=0)
    assert out[0] == intents[0]
    for rid, it in out.items():
        if rid != 0:
            assert it.x >= RADIUS + P.halfway_margin_m - 1e-12 and math.hypot(it.x, it.y) >= CIRCLE + RADIUS


def test_restart_rules_by_command() -> None:
    intents = _intents(np.random.default_rng(9), 6)
    ball = BallState(0.5, 0.5, 0.0, 0.0)

    def rules(command: str, ours: bool) -> dict[int, Intent]:
        return restart_rules(intents, GameState(0.0, command), ours, ball, FIELD, -1.0, P, RADIUS, kicker=None)

    assert rules("normal", False) == intents
    assert rules("free_kick", True) == intents  # ours: the attacker takes it
    for command, ours in (("stop", True), ("free_kick", False), ("kickoff", False)):
        # slow in a stop and at their kickoff
        slow = command in (RefereeCommand.STOP, RefereeCommand.KICKOFF)
        assert rules(command, ours) == keep_away(intents, ball, FIELD, -1.0, P, RADIUS,
                                                 command == RefereeCommand.KICKOFF, slow)
    assert rules("kickoff", True) == our_kickoff(intents, FIELD, -1.0, P, RADIUS, None)


def test_kickoff_places_are_where_our_kickoff_puts_its_robots() -> None:
    from strategy.game_states import kickoff_places, our_kickoff

    p = GameStateParams()
    radius = 0.09
    pts = np.array([[2.0, 1.0], [0.3, 0.1], [-2.0, -1.5], [0.2, -0.2]])
    placed = kickoff_places(pts, FIELD, -1.0, p, radius)  # we defend negative x
    intents = {i: Intent(float(x), float(y), 0.0) for i, (x, y) in enumerate(pts)}
    moved = our_kickoff(intents, FIELD, -1.0, p, radius, kicker=None)
    for i, (x, y) in enumerate(placed):
        assert (x, y) == pytest.approx((moved[i].x, moved[i].y), abs=1e-12)
    assert placed[2] == pytest.approx((-2.0, -1.5))  # already a legal place: unmoved
    assert placed[0, 0] == pytest.approx(-(radius + p.halfway_margin_m))
