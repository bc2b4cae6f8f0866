"""Plays against the rules and the roles' promises, over many seeded random situations."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cmdragons.config import ConfigError, parse
from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, GameState, RefereeCommand, RobotState, TeamInfo, WorldState
from strategy.defense import DefenseParams
from strategy.plays import Strategy, StrategyParams, off_ball_line
from strategy.roles import Role, RoleKind
from strategy.skills import Intent

GOALIE = Role(RoleKind.GOALIE)

FIELD = Field(LeagueParams())


def random_world(rng: np.random.Generator, n_own: int, n_opp: int) -> WorldState:
    def robot(team: str, rid: int) -> RobotState:
        x, y = rng.uniform([-4.3, -2.8], [4.3, 2.8])
        return RobotState(team, rid, float(x), float(y), float(rng.uniform(-math.pi, math.pi)))  # type: ignore[arg-type]

    bx, by = rng.uniform([-4.3, -2.8], [4.3, 2.8])
    bv = rng.normal(0, 1.0, 2) * (rng.random() < 0.5)
    robots = tuple(robot("blue", i) for i in range(n_own)) + tuple(robot("yellow", i) for i in range(n_opp))
    return WorldState(0.0, BallState(float(bx), float(by), float(bv[0]), float(bv[1])), robots)


@pytest.mark.parametrize("seed", range(40))
def test_goal_never_left_without_a_goalie(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n_own = int(rng.integers(1, 7))
    world = random_world(rng, n_own, int(rng.integers(0, 7)))
    strategy = Strategy("blue", FIELD, StrategyParams())
    game = GameState(0.0, "normal", blue_defends_negative_x=bool(seed % 2))
    strategy.decide(world, game)
    assert GOALIE in strategy.roles.roles.values()
    own_sign = strategy.own_sign(game)
    goalie = next(rid for rid, role in strategy.roles.roles.items() if role == GOALIE)
    intent = strategy.decide(world, game)[goalie]
    assert abs(intent.x - own_sign * FIELD.half_length) < 1.2  # at our goal, whatever else happens


@pytest.mark.parametrize("seed", range(20))
@pytest.mark.parametrize("command", ["stop", "free_kick"])
def test_distance_to_the_ball_when_the_rules_ask(seed: int, command: str) -> None:
    rng = np.random.default_rng(100 + seed)
    world = random_world(rng, 6, 6)
    assert world.ball is not None
    p = StrategyParams()
    game = GameState(0.0, command, for_team="yellow" if command == RefereeCommand.FREE_KICK else None)
    for rid, it in Strategy("blue", FIELD, p).decide(world, game).items():
        assert math.hypot(it.x - world.ball.x, it.y - world.ball.y) >= 0.5 + p.robot_radius_m, rid
        if command == RefereeCommand.STOP:
            assert it.max_speed_m_s is not None and it.max_speed_m_s <= 1.5
        assert it.kick_speed == 0.0


@pytest.mark.parametrize("seed", range(10))
def test_their_kickoff_keeps_us_in_our_half_outside_the_circle(seed: int) -> None:
    rng = np.random.default_rng(200 + seed)
    world = random_world(rng, 6, 6)
    world = WorldState(0.0, BallState(0.0, 0.0, 0.0, 0.0), world.robots)
    game = GameState(0.0, "kickoff", for_team="yellow", blue_defends_negative_x=True)
    for it in Strategy("blue", FIELD, StrategyParams()).decide(world, game).values():
        assert it.x < 0.0
        assert math.hypot(it.x, it.y) >= FIELD.dims.center_circle_radius_m


def test_halt_stops_everyone() -> None:
    world = random_world(np.random.default_rng(1), 6, 0)
    intents = Strategy("blue", FIELD, StrategyParams()).decide(world, GameState(0.0, "halt"))
    assert all(it.max_speed_m_s == 0.0 for it in intents.values())


def _robot(team: str, rid: int, x: float, y: float, theta: float = 0.0) -> RobotState:
    return RobotState(team, rid, x, y, theta)  # type: ignore[arg-type]


def test_a_contested_ball_is_played_from_the_attackers_side() -> None:
    # blue attacks +x; the attacker stands on the goal side of the ball, an opponent right behind it:
    # swinging round would hand the ball over, so it is kicked from where the attacker stands
    p = StrategyParams()
    ball = BallState(2.0, 0.5, 0.0, 0.0)
    robots = (_robot("blue", 0, -4.3, 0.0), _robot("blue", 1, 2.2, 0.5, math.pi),
              _robot("yellow", 0, 4.3, 0.0), _robot("yellow", 1, 1.8, 0.5))
    strategy = Strategy("blue", FIELD, p)
    game = GameState(0.0, "normal", blue_defends_negative_x=True)
    intent = strategy.decide(WorldState(0.0, ball, robots), game)[1]
    approach = math.pi  # from the attacker to the ball
    off = abs(math.remainder(intent.theta - approach, 2 * math.pi))
    assert off <= p.kicking.contest_turn_rad + 1e-6
    assert strategy.last_action[1] == "clear"
    # with the opponent gone the same attacker goes round the ball to play it toward their goal
    alone = Strategy("blue", FIELD, p)
    intent = alone.decide(WorldState(0.0, ball, robots[:3]), game)[1]
    assert abs(math.remainder(intent.theta - approach, 2 * math.pi)) > p.kicking.contest_turn_rad


def test_a_decided_pass_goes_where_its_receiver_waits() -> None:
    # the receiver is told to wait at the pass point before the kick, and the passer keeps kicking at
    # that point even when the receiver has drifted from it
    p = StrategyParams(defense=DefenseParams(defenders=0))
    ball = BallState(-1.0, 0.0, 0.0, 0.0)
    robots = [_robot("blue", 0, -4.3, 0.0), _robot("blue", 1, -1.3, 0.0), _robot("blue", 2, 1.0, 2.0),
              _robot("yellow", 0, 4.3, 0.0), _robot("yellow", 1, 0.5, -0.3)]
    strategy = Strategy("blue", FIELD, p)
    game = GameState(0.0, "normal", blue_defends_negative_x=True)
    strategy.decide(WorldState(0.0, ball, tuple(robots)), game)
    planned = strategy.passes.current
    assert planned is not None and planned.passer == 1 and not planned.kicked
    point = planned.point
    robots[2] = _robot("blue", 2, point[0] + 0.3, point[1] - 0.2)
    intents = strategy.decide(WorldState(0.05, ball, tuple(robots)), game)
    assert strategy.roles.roles[planned.receiver] == Role(RoleKind.RECEIVER)
    receiver = intents[planned.receiver]
    assert math.hypot(receiver.x - point[0], receiver.y - point[1]) < 1e-9
    assert strategy.passes.current is not None and strategy.passes.current.point == point
    kick_dir = intents[1].theta
    assert abs(math.remainder(kick_dir - math.atan2(point[1] - ball.y, point[0] - ball.x), 2 * math.pi)) < 1e-6


def test_the_pass_heat_is_the_last_grid_evaluation_read_only() -> None:
    strategy = Strategy("blue", FIELD, StrategyParams())
    assert strategy.pass_heat is None
    world = random_world(np.random.default_rng(5), 6, 6)
    strategy.decide(world, GameState(0.0, "normal"))
    heat = strategy.pass_heat
    assert heat is not None
    points, values = heat
    assert points.shape == (len(strategy.supporters.grid), 2) and values.shape == (len(points),)
    assert np.all((values >= 0.0) & (values <= 1.0))
    with pytest.raises(ValueError, match="read-only"):
        values[0] = 1.0
    assert strategy.supporters.evaluation is not None and strategy.supporters.evaluation.values.flags.writeable


def test_the_radii_are_read_in_one_place() -> None:
    p = StrategyParams()
    assert p.robot_radius_m == p.skills.robot_radius_m
    assert p.obstacle_radius_m == p.skills.robot_radius_m + p.skills.ball_radius_m


@pytest.mark.parametrize(("section", "key", "value"), [
    ("kicking", "meet_cos", 1.5), ("pass_play", "timeout_s", 0.0), ("support", "eval_every_frames", 0),
    ("game_states", "stop_distance_m", 0.4), ("defense", "defenders", 11)])
def test_out_of_range_settings_are_refused_by_name(section: str, key: str, value: float) -> None:
    raw = {section: {key: value}}
    with pytest.raises(ConfigError, match=f"{section}.{key}"):
        parse(StrategyParams, raw, file="strategy.yaml")


@pytest.mark.parametrize(("robot", "expected"), [
    ((0.3, 0.1), (0.3, 0.4)),  # beside the rolling ball's way: sideways to clear_m off it
    ((-0.3, -0.2), (-0.3, -0.4)),  # behind it, on its right: likewise, on that side
    ((0.5, -0.6), (0.5, -0.6)),  # already clear of its way: stays
])
def test_the_restart_kicker_steps_out_of_the_rolling_balls_way(robot: tuple[float, float],
                                                               expected: tuple[float, float]) -> None:
    p = StrategyParams()
    ball = BallState(0.0, 0.0, 1.5, 0.0)
    r = RobotState("blue", 1, *robot, 0.0)
    away = Intent(3.0, 0.0, 0.0)  # its own way: along the ball's, into it
    it = off_ball_line(r, away, ball, FIELD, p.robot_radius_m, p.barred_near_m, p.barred_clear_m, p.barred_rolling_m_s)
    assert (it.x, it.y) == pytest.approx(expected, abs=1e-9)
    assert it.avoid_ball and it.theta == pytest.approx(math.atan2(-it.y, -it.x))


@pytest.mark.parametrize(("robot", "ball"), [
    ((0.3, 0.1), BallState(0.0, 0.0, 0.2, 0.0)),  # the ball (nearly) at rest
    ((1.5, 0.1), BallState(0.0, 0.0, 1.5, 0.0)),  # the robot far from it
])
def test_the_restart_kicker_goes_its_way_by_a_ball_at_rest_or_far(robot: tuple[float, float],
                                                                  ball: BallState) -> None:
    p = StrategyParams()
    away = Intent(3.0, 0.0, 0.0)
    r = RobotState("blue", 1, *robot, 0.0)
    it = off_ball_line(r, away, ball, FIELD, p.robot_radius_m, p.barred_near_m, p.barred_clear_m, p.barred_rolling_m_s)
    assert it is away


@pytest.mark.parametrize("seed", range(10))
def test_a_team_with_a_robot_too_many_drives_the_one_nearest_the_halfway_line_at_a_touch_line_out(seed: int) -> None:
    """Six of ours on the field, five allowed (a yellow card running): from ``leave_after_s`` on, the
    robot nearest either crossing of the halfway line and the touch lines (never the keeper) drives
    onto that touch line at the halfway line, partly in the field margin, within the rules' 1 m of
    the halfway line; before, and with six allowed, nobody leaves."""
    rng = np.random.default_rng(300 + seed)
    world = random_world(rng, 6, 6)
    p = StrategyParams()
    strategy = Strategy("blue", FIELD, p)
    info = dataclasses.replace(TeamInfo(), max_robots=5, goalkeeper=int(rng.integers(0, 6)))
    game = GameState(0.0, "normal", blue_team=info)
    w = FIELD.half_width

    def out_of(intents: dict[int, Intent]) -> list[int]:  # those going to the touch line at the halfway line
        return [rid for rid, it in intents.items() if abs(it.x) <= 1.0 and w < abs(it.y) <= w + 0.5]

    assert out_of(strategy.decide(world, game)) == []  # not yet: the referee's handlers may take one first
    later = dataclasses.replace(world, t=p.game_states.leave_after_s + 0.1)
    leaving = out_of(strategy.decide(later, game))
    own = [r for r in world.robots if r.team == "blue" and r.id != info.goalkeeper]
    nearest = min(own, key=lambda r: min(math.hypot(r.x, r.y - w), math.hypot(r.x, r.y + w)))
    assert leaving == [nearest.id]
    it = strategy.decide(later, game)[nearest.id]
    r = p.robot_radius_m
    assert abs(it.x) <= 1.0 and w < abs(it.y) < w + r + FIELD.dims.boundary_width_m and it.y * nearest.y >= 0
    allowed = GameState(0.0, "normal", blue_team=dataclasses.replace(info, max_robots=6))
    assert out_of(Strategy("blue", FIELD, p).decide(later, allowed)) == []


# blue's and yellow's robots (id, x, y, theta) in the ER-Force simulator's self-play (Division B field,
# 16.5 s in): yellow places the ball in blue's half while blue's attacker has decided a pass to robot
# 4, which stands at the best supporter point; robot 5, the one supporter left, was sent to that point
# too (targets 2 cm apart) and drove into 4 for 13 s (38 own collisions counted from the tracks)
_RECEIVER_SITUATION = (
    ("blue", 0, -4.35, -0.03, -0.20), ("blue", 1, -3.27, 1.22, -2.50), ("blue", 2, -4.00, -1.50, 2.70),
    ("blue", 3, -3.08, -0.88, -0.74), ("blue", 4, 2.55, -0.47, 3.11), ("blue", 5, 2.70, -0.38, 3.10),
    ("yellow", 0, 4.34, 0.0, -3.09), ("yellow", 1, 3.24, 0.13, -3.07), ("yellow", 2, -3.99, -1.24, 0.85),
    ("yellow", 3, -3.32, 1.04, -1.09), ("yellow", 4, 3.26, -0.20, -3.14), ("yellow", 5, -3.40, -0.15, -1.66),
)


@pytest.mark.parametrize("command", ["ball_placement", "stop"])
def test_no_supporter_is_sent_to_the_receivers_point_while_play_is_stopped(command: str) -> None:
    p = StrategyParams()
    robots = tuple(_robot(team, rid, x, y, th) for team, rid, x, y, th in _RECEIVER_SITUATION)
    ball = BallState(-3.39, -0.25, 0.0, 0.0)
    game = GameState(0.0, command, for_team="yellow" if command == "ball_placement" else None,
                     blue_defends_negative_x=True, placement=(-3.3, 0.57) if command == "ball_placement" else None)
    strategy = Strategy("blue", FIELD, p)
    receivers = 0
    for k in range(2 * p.support.eval_every_frames):  # across a re-evaluation of the supporters' points
        intents = strategy.decide(WorldState(0.016 * k, ball, robots), game)
        receivers += RoleKind.RECEIVER in {role.kind for role in strategy.roles.roles.values()}
        points = sorted((it.x, it.y, rid) for rid, it in intents.items())
        for i, (xa, ya, a) in enumerate(points):
            for xb, yb, b in points[i + 1:]:
                assert math.hypot(xa - xb, ya - yb) >= 2.0 * p.robot_radius_m, (k, a, b)
    assert receivers > 0  # the situation: a pass decided, its receiver waiting at a supporter's point


def test_our_kickoffs_kicker_stays_barred_when_the_attackers_role_moves_on_before_the_normal_start() -> None:
    # our kickoff: robot 1 passes to robot 4; the ball rolls for some frames before the referee's
    # normal start (an auto-referee on vision sees it move late), and meanwhile the pass is under way:
    # the attacker's role is nobody's. The kicker must stay barred from the ball until another robot
    # touched it: in grSim it took the role back when the pass fell short and played the ball again,
    # a double touch
    still = (_robot("blue", 0, -4.3, 0.0), _robot("blue", 1, -0.15, 0.0), _robot("blue", 2, -3.2, 0.3),
             _robot("blue", 5, -3.2, -0.3), _robot("blue", 3, -1.0, -1.5), _robot("blue", 4, -0.2, 1.3),
             _robot("yellow", 0, 4.3, 0.0), _robot("yellow", 1, 2.0, 0.0))
    strategy = Strategy("blue", FIELD, StrategyParams())
    kickoff = GameState(0.0, "kickoff", for_team="blue", blue_defends_negative_x=True, ready=True)
    normal = GameState(0.0, "normal", blue_defends_negative_x=True)
    t = 0.0
    for _ in range(10):
        strategy.decide(WorldState(t, BallState(0.0, 0.0, 0.0, 0.0), still), kickoff)
        t += 1 / 60
    planned = strategy.passes.current
    assert planned is not None and planned.passer == 1 and planned.receiver == 4
    # kicked towards the pass point at 1.2 m/s, slowing to rest 0.5 m short of the receiver
    to = np.array(planned.point) / math.hypot(*planned.point)
    decel = 1.2**2 / (2 * (math.hypot(*planned.point) - 0.5))
    s, v = 0.0, 1.2
    attackers, barred = set(), set()
    for k in range(300):
        ball = BallState(float(s * to[0]), float(s * to[1]), float(v * to[0]), float(v * to[1]))
        strategy.decide(WorldState(t, ball, still), kickoff if k < 12 else normal)
        if k >= 12:
            attackers |= {rid for rid, role in strategy.roles.roles.items() if role == Role(RoleKind.ATTACKER)}
            barred.add(strategy._barred)
        t += 1 / 60
        s, v = s + v / 60, max(0.0, v - decel / 60)
    assert v == 0.0
    assert barred == {1}
    assert 1 not in attackers
