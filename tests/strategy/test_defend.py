"""The defending opponent: where it puts its robots (in a receiver's passing lane, on a shot's line,
off the defense areas) on hand-built world states, and in the simulator, with the referee judging
every frame, that a marker takes the pass meant for its receiver, a blocker the shot at the goal,
and that it keeps the rules' distance and speed in a stop and at the other team's free kick."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pytest

from cmdragons.messages import BallState, GameEvent, GameState, RefereeCommand, RobotCommand, RobotState, WorldState
from cmdragons.runtime.settings import load_settings
from sim.referee import Referee
from sim.world import World
from strategy.defend import DefendTeam, detour, keep_off_robots, threats

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")
FIELD = SETTINGS.field_geometry()
P = SETTINGS.team.defend_opponent
R = SETTINGS.field.robot.radius_m
BALL_R = SETTINGS.field.ball.radius_m
RULES = SETTINGS.sim.referee.figures
GAME = GameState(0.0)  # normal play; blue defends -x, so the defending team (yellow) defends +x


def team() -> DefendTeam:
    return DefendTeam("yellow", FIELD, P, SETTINGS.strategy)


def _segment(p: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
    """(distance from p to the segment a-b, the share of the way from a to b of its nearest point)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    u = max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)))
    return math.hypot(p[0] - a[0] - u * dx, p[1] - a[1] - u * dy), u


def yellow_line_up(n: int = 6) -> list[RobotState]:
    """The defending team spread over its half (+x), the goalie on its line."""
    spots = [(4.3, 0.0), (3.0, 1.5), (3.0, -1.5), (2.0, 0.0), (1.0, 2.0), (1.0, -2.0)]
    return [RobotState("yellow", k, x, y, math.pi) for k, (x, y) in enumerate(spots[:n])]


# --- where it stands -------------------------------------------------------------------------------
@pytest.mark.parametrize("receiver", [(2.0, -1.5), (0.5, 2.0), (3.0, 2.5), (-1.5, -2.0)])
def test_a_marker_stands_in_the_receivers_passing_lane(receiver: tuple[float, float]) -> None:
    ball = BallState(-1.0, 0.5, 0.0, 0.0)
    blue = [RobotState("blue", 0, -4.3, 0.0, 0.0), RobotState("blue", 1, -1.2, 0.5, 0.0),  # keeper, passer
            RobotState("blue", 2, *receiver, 0.0)]
    intents = team().intents(WorldState(0.0, ball, (*blue, *yellow_line_up())), GAME)
    lane = [(it, *_segment((it.x, it.y), receiver, (ball.x, ball.y))) for it in intents.values()]
    it, off, _ = min(lane, key=lambda t: t[1])
    assert off < 0.01  # on the line from the receiver to the ball
    assert math.hypot(it.x - receiver[0], it.y - receiver[1]) == pytest.approx(P.mark_gap_m, abs=0.01)
    assert abs(math.atan2(ball.y - it.y, ball.x - it.x) - it.theta) < 1e-9  # facing the ball


def test_the_opponent_on_the_ball_and_their_keeper_are_not_marked_the_nearest_to_our_goal_first() -> None:
    ball = BallState(-1.0, 0.5, 0.0, 0.0)
    blue = [RobotState("blue", 0, -4.3, 0.0, 0.0), RobotState("blue", 1, -1.2, 0.5, 0.0),
            RobotState("blue", 2, 0.0, 2.0, 0.0), RobotState("blue", 3, 3.0, -1.0, 0.0)]
    assert [r.id for r in threats(blue, ball, FIELD, 1.0, P)] == [3, 2]


@pytest.mark.parametrize("ball_xy", [(1.5, 0.8), (-2.0, -1.0), (2.5, -0.3)])
def test_a_blocker_stands_on_the_shots_line_to_the_goal(ball_xy: tuple[float, float]) -> None:
    ball = BallState(*ball_xy, 0.0, 0.0)
    shooter = RobotState("blue", 1, ball_xy[0] - 0.15, ball_xy[1], 0.0)
    intents = team().intents(WorldState(0.0, ball, (shooter, *yellow_line_up())), GAME)
    goal = (FIELD.half_length, 0.0)
    on_line = [it for rid, it in intents.items() if rid != 0 and _segment((it.x, it.y), ball_xy, goal)[0] < 0.01]
    nearest = min(math.hypot(it.x - ball.x, it.y - ball.y) for it in on_line)  # (a defender may be on it too)
    assert nearest == pytest.approx(P.block_distance_m, abs=0.01)


@pytest.mark.parametrize("keeper", [True, False])  # False: its goalie sent off, nobody keeps goal
@pytest.mark.parametrize("ball_xy", [(4.0, 0.5), (-4.0, -0.5), (3.6, 0.9)])
def test_no_field_player_is_sent_into_a_defense_area(ball_xy: tuple[float, float], keeper: bool) -> None:
    ball = BallState(*ball_xy, 0.0, 0.0)
    blue = [RobotState("blue", 0, -4.3, 0.0, 0.0), RobotState("blue", 1, ball_xy[0] - 0.2, ball_xy[1], 0.0),
            RobotState("blue", 2, 4.0, -0.6, 0.0), RobotState("blue", 3, 3.8, 0.9, 0.0)]
    yellow = yellow_line_up() if keeper else yellow_line_up()[1:]
    intents = team().intents(WorldState(0.0, ball, (*blue, *yellow)), GAME)
    assert sorted(intents) == [r.id for r in yellow]
    for rid, it in intents.items():
        if rid != SETTINGS.strategy.roles.goalie_id:
            assert FIELD.in_defense_area(it.x, it.y, R) == 0, (rid, it)


@pytest.mark.parametrize(("gap", "other_v"), [(0.2, 0.0), (0.1, 0.0), (0.0, 0.0), (0.1, 1.0), (0.1, -1.0)])
def test_it_closes_on_another_robot_no_faster_than_allowed(gap: float, other_v: float) -> None:
    me = RobotState("yellow", 1, 0.0, 0.0, 0.0)
    other = RobotState("blue", 2, 2 * R + gap, 0.0, 0.0, other_v, 0.0)
    cmd = keep_off_robots(RobotCommand("yellow", 1, 3.0, 0.5), me, [other], R, P)
    allowed = P.closing_m_s * gap / P.near_gap_m
    assert cmd.vx <= allowed + min(other_v, 0.0) + 1e-9 or cmd.vx == 0.0
    assert 0.0 <= cmd.vx <= 3.0 and cmd.vy == 0.5  # slowed toward it, never turned back, the rest kept


@pytest.mark.parametrize(("start", "goal"), [((-1.0, 0.0), (1.0, 0.0)), ((-1.0, 0.3), (1.0, 0.2)),
                                             ((0.0, -1.0), (0.1, 1.0)), ((-0.8, 0.8), (0.8, -0.8))])
def test_a_way_through_the_balls_circle_goes_round_it(start: tuple[float, float], goal: tuple[float, float]) -> None:
    radius, share, x, y = 0.6, 1.2, *start
    for _ in range(400):  # steps of 2 cm toward the way point asked afresh each step
        wx, wy = detour((x, y), goal, (0.0, 0.0), radius, share)
        d = math.hypot(wx - x, wy - y)
        if d < 1e-9:
            break
        x, y = x + (wx - x) / d * min(0.02, d), y + (wy - y) / d * min(0.02, d)
        assert math.hypot(x, y) >= radius - 1e-9
    assert math.hypot(x - goal[0], y - goal[1]) < 1e-6  # it arrives


@pytest.mark.parametrize(("start", "goal", "expected"), [
    ((-1.0, 1.0), (1.0, 1.0), (1.0, 1.0)),  # the straight way keeps out of the circle
    ((0.3, 0.0), (0.3, 2.0), (0.3, 2.0)),  # from inside, the way leads away from the centre: straight on
    ((0.3, 0.0), (-2.0, 0.0), (0.72, 0.0)),  # from inside toward the centre: straight out first
    ((0.72, 0.0), (-2.0, 0.1), (0.6, 0.72 * math.sin(math.acos(1 / 1.2)))),  # on the way round, the goal's side
])
def test_the_way_point_of_a_detour(start: tuple[float, float], goal: tuple[float, float],
                                   expected: tuple[float, float]) -> None:
    assert detour(start, goal, (0.0, 0.0), 0.6, 1.2) == pytest.approx(expected, abs=1e-9)


# --- in the simulator ------------------------------------------------------------------------------
def scene(blue: list[tuple[float, float, float]], yellow: int = 6) -> tuple[World, Referee]:
    s = SETTINGS.sim
    w = World(SETTINGS.field, s.physics, s.robot, s.ball, s.kicker, s.dribbler,
              robots_per_team={"blue": len(blue), "yellow": yellow})
    ref = Referee(w.field, w.robot_keys(), s.referee)
    for k, (x, y, theta) in enumerate(blue):
        w.place_robot("blue", k, x, y, theta)
    for r in yellow_line_up(yellow):
        w.place_robot("yellow", r.id, r.x, r.y, r.theta)
    return w, ref


def play(w: World, ref: Referee, seconds: float, each: Callable[[World], None] | None = None,
         judge: bool = True, blue: tuple[RobotCommand, ...] = ()) -> list[GameEvent]:
    """The defending team (yellow) plays, blue stands (or keeps to the commands ``blue``); the
    referee judges every frame (``judge``)."""
    yellow, calls = team(), []
    for _ in range(round(seconds * SETTINGS.sim.physics.frame_rate_hz)):
        events = w.step_frame([*yellow.commands(w.ground_truth().world(), ref.state()), *blue])
        if judge:
            teleport = ref.observe(w.t, events, tuple(w.ball_body.position), w.ground_truth())
            calls += ref.calls.new
            assert teleport is None
        if each is not None:
            each(w)
    return calls


def first_touch(w: World, seconds: float, passer: int) -> tuple[str, int] | None:
    """The first robot but the passer the ball touches in ``seconds`` of play (nobody judging)."""
    touched: list[tuple[str, int]] = []

    def watch(w: World) -> None:
        gt = w.ground_truth()
        for r in gt.robots:
            near = math.hypot(r.x - gt.ball.x, r.y - gt.ball.y) < R + BALL_R + 0.01
            if near and not touched and (r.team, r.id) != ("blue", passer):
                touched.append((r.team, r.id))

    play(w, Referee(w.field, w.robot_keys(), SETTINGS.sim.referee), seconds, each=watch, judge=False)
    return touched[0] if touched else None


def test_a_marker_takes_the_pass_meant_for_its_receiver() -> None:
    receiver, passer = (2.0, -1.5), (-1.2, 0.5)
    w, ref = scene([(-4.3, 0.0, 0.0), (*passer, 0.0), (*receiver, math.pi)])
    w.place_ball(-1.0, 0.5)
    ref.give(RefereeCommand.FORCE_START)
    play(w, ref, 4.0, judge=False)  # the marker takes its place in the lane
    gt = w.ground_truth()
    lane = [_segment((r.x, r.y), receiver, (gt.ball.x, gt.ball.y)) for r in gt.robots if r.team == "yellow"]
    off, share = min(lane)
    assert off < 0.05 and 0.0 < share < 1.0  # between the receiver and the ball
    # the pass: the ball sent at the receiver, to arrive there at a controllable speed
    dx, dy = receiver[0] - gt.ball.x, receiver[1] - gt.ball.y
    d = math.hypot(dx, dy)
    w.place_ball(gt.ball.x, gt.ball.y, 3.5 * dx / d, 3.5 * dy / d)
    who = first_touch(w, 3.0, passer=1)
    assert who is not None and who[0] == "yellow" and who[1] != 0, who


def test_a_blocker_takes_a_shot_at_the_goal() -> None:
    # their shooter holds the ball on its dribbler, facing our goal
    shooter = (1.3, 0.8)
    w, ref = scene([(-4.3, 0.0, 0.0), (*shooter, 0.0)])
    w.place_ball(shooter[0] + SETTINGS.strategy.skills.contact_m, shooter[1])
    ref.give(RefereeCommand.FORCE_START)
    play(w, ref, 3.0, judge=False, blue=(RobotCommand("blue", 1, dribbler=1.0),))
    gt = w.ground_truth()
    goal = (FIELD.half_length, 0.0)
    lanes = [_segment((r.x, r.y), (gt.ball.x, gt.ball.y), goal)[0] for r in gt.robots
             if r.team == "yellow" and r.id != 0]
    assert min(lanes) < R + BALL_R  # a field player's body across the line: the ball cannot pass
    dx, dy = goal[0] - gt.ball.x, goal[1] - gt.ball.y
    d = math.hypot(dx, dy)
    w.place_ball(gt.ball.x, gt.ball.y, 5.0 * dx / d, 5.0 * dy / d)
    who = first_touch(w, 2.0, passer=1)
    assert who is not None and who[0] == "yellow" and who[1] != 0, who


@pytest.mark.parametrize("command", [RefereeCommand.STOP, RefereeCommand.FREE_KICK])
def test_it_keeps_the_rules_distance_and_speed_in_a_stop_and_at_their_free_kick(command: RefereeCommand) -> None:
    ball = (1.0, 0.5)
    w, ref = scene([(-4.3, 0.0, 0.0), (ball[0] - 0.3, ball[1], 0.0)])
    for k in range(1, 6):  # all round the ball, inside the rules' distance
        a = k * 2 * math.pi / 5
        w.place_robot("yellow", k, ball[0] + (0.25 + R) * math.cos(a), ball[1] + (0.25 + R) * math.sin(a), a)
    w.place_ball(*ball)
    if command == RefereeCommand.STOP:
        ref.give(RefereeCommand.STOP)
        grace, limit, speed_limit = RULES.stop_grace_s, RULES.stop_distance_m, RULES.stop_speed_m_s
    else:
        w.apply(ref.free_kick("blue", ball))
        grace, limit, speed_limit = RULES.kick_point_grace_s, RULES.kick_point_distance_m, math.inf
    worst = {"gap": math.inf, "speed": 0.0}

    def check(w: World) -> None:
        gt = w.ground_truth()
        for r in gt.robots:
            if r.team == "yellow" and gt.t >= grace:
                worst["gap"] = min(worst["gap"], math.hypot(r.x - gt.ball.x, r.y - gt.ball.y) - R)
            if r.team == "yellow" and command == RefereeCommand.STOP:
                worst["speed"] = max(worst["speed"], math.hypot(r.vx, r.vy))

    calls = play(w, ref, 6.0, each=check)
    assert ref.game.command == command  # blue stands: the free kick is still to be taken
    assert worst["gap"] >= limit
    assert worst["speed"] < speed_limit
    assert not [e for e in calls if e.team == "yellow"], [(e.kind, e.value) for e in calls]
