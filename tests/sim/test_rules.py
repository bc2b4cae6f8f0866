"""The auto-referee: each foul in a scripted scene is called with its figure and restart, and the
clean counterpart of the scene is not; cards send robots off and back; placements end in time or not."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import pytest

from cmdragons.geometry import Field, LeagueParams, Team
from cmdragons.messages import (
    BallTruth,
    GameEvent,
    GameStage,
    Goal,
    GroundTruth,
    RefereeCommand,
    RobotCommand,
    RobotTruth,
)
from sim.referee import Referee
from sim.referee_params import RefereeParams
from sim.rules import FoulWatch, HeldBall, NoProgress, RulesParams, Situation, penalty_set, placed
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World

LEAGUE = LeagueParams()
FRONT = LEAGUE.robot.front_distance_m + LEAGUE.ball.radius_m
R = LEAGUE.robot.radius_m
Commands = Callable[[int], list[RobotCommand]]


def scene(blue: int = 2, yellow: int = 2, brake: float = 6.0, **figures: object) -> tuple[World, Referee]:
    """Robots parked apart along the bottom touch line, the ball at rest mid-field; full rules in normal play."""
    w = World(LEAGUE, PhysicsParams(), RobotParams(command_latency_s=0.0, max_brake_m_s2=brake), BallParams(),
              KickerParams(), DribblerParams(),
              robots_per_team={"blue": blue, "yellow": yellow})
    for i, (team, rid) in enumerate(w.robot_keys()):
        w.place_robot(team, rid, -3.5 + 1.0 * i, -2.6, 0.0)
    w.place_ball(0.0, 1.5)
    ref = Referee(w.field, w.robot_keys(), RefereeParams(figures=RulesParams(**figures)))  # type: ignore[arg-type]
    ref.give(RefereeCommand.NORMAL)
    return w, ref


def play(w: World, ref: Referee, seconds: float, commands: Commands | None = None) -> list[GameEvent]:
    """The referee judges every frame on the truth; the world carries out its teleports."""
    calls: list[GameEvent] = []
    for k in range(round(seconds * 60)):
        events = w.step_frame(commands(k) if commands else [])
        teleport = ref.observe(w.t, events, tuple(w.ball_body.position), w.ground_truth())
        calls += ref.calls.new
        if teleport is not None:
            w.apply(teleport)
    return calls


def kinds(calls: list[GameEvent]) -> list[str]:
    return [c.kind for c in calls]


def drive(team: str, rid: int, vx: float = 0.0, vy: float = 0.0, until: int = 10**9, **kw: object) -> Commands:
    return lambda k: [RobotCommand(team, rid, vx, vy, **kw) if k < until else RobotCommand(team, rid)]  # type: ignore[arg-type]


@pytest.mark.parametrize(("speed", "called"), [(2.5, True), (0.8, False)])
def test_crash_faster_than_the_limit_is_the_faster_robots_foul(speed: float, called: bool) -> None:
    w, ref = scene()
    w.place_robot("blue", 0, -1.0, 0.0, 0.0)
    w.place_robot("yellow", 0, 0.0, 0.0, math.pi)
    calls = play(w, ref, 1.0, drive("blue", 0, vx=speed, until=40))
    crashes = [c for c in calls if c.kind == "crash"]
    assert bool(crashes) == called
    if called:
        c = crashes[0]
        assert (c.team, c.robot, c.restart, c.for_team) == ("blue", 0, RefereeCommand.FREE_KICK, "yellow")
        assert c.value > 1.5 and c.limit == 1.5
        assert ref.game.command == RefereeCommand.STOP  # then the free kick (placed by yellow)


@pytest.mark.parametrize(("blue_v", "yellow_v", "called"), [
    ((0.0, 1.6), (-1.7, 0.0), ["crash_drawn", "crash_drawn"]),  # blue across the line, as fast: both at fault
    ((0.0, 2.5), (-1.7, 0.0), ["crash:blue"]),  # blue faster on the ground though yellow closes
    ((0.4, 0.0), (-1.7, 0.0), ["crash:yellow"]),
    ((0.0, 2.5), (-1.0, 0.0), []),  # closing at 1 m/s along the line: no crash
])
def test_crash_fault_goes_by_the_robots_own_speeds(blue_v: tuple[float, float], yellow_v: tuple[float, float],
                                                    called: list[str]) -> None:
    # the rules: the velocity difference along the line decides a crash, the robots' own speeds whose it is
    watch = FoulWatch(Field(LEAGUE), RulesParams())
    situation = Situation(RefereeCommand.NORMAL, None, 0.0, -1, True)
    ball = BallTruth(2.0, 2.0, 0.0, 0.0, 0.0)
    calls = []
    for k, gap in enumerate((0.3, 2 * R)):  # apart, then touching
        robots = (RobotTruth("blue", 0, 0.0, 0.0, 0.0, *blue_v, 0.0),
                  RobotTruth("yellow", 0, gap, 0.0, math.pi, *yellow_v, 0.0))
        calls += watch.judge(GroundTruth(k, k / 60.0, ball, robots), situation)
    got = [c.kind if c.kind == "crash_drawn" else f"{c.kind}:{c.team}" for c in calls if c.kind.startswith("crash")]
    assert got == called


@pytest.mark.parametrize(("push_s", "called"), [(1.2, True), (0.15, False)])
def test_pushing_an_opponent_farther_than_the_limit(push_s: float, called: bool) -> None:
    w, ref = scene(brake=1.0)  # the pushed robot's brakes weaker than the pusher's drive
    w.place_robot("blue", 0, -0.5, 0.0, 0.0)
    w.place_robot("yellow", 0, -0.5 + 2 * R + 0.005, 0.0, math.pi)
    calls = play(w, ref, 2.0, drive("blue", 0, vx=0.5, until=round(push_s * 60)))
    assert "crash" not in kinds(calls)  # slow: no crash
    pushes = [c for c in calls if c.kind == "pushing"]
    assert bool(pushes) == called
    if called:
        assert (pushes[0].team, pushes[0].robot, pushes[0].restart) == ("blue", 0, RefereeCommand.FREE_KICK)
        assert pushes[0].value > 0.2


@pytest.mark.parametrize(("speed", "called"), [(8.0, True), (5.0, False)])
def test_ball_faster_than_the_limit_after_a_touch(speed: float, called: bool) -> None:
    w, ref = scene()
    w.place_robot("blue", 1, -1.0, 0.0, 0.0)
    w.place_ball(-1.0 + FRONT + 0.003, 0.0)
    play(w, ref, 0.2, drive("blue", 1, vx=0.2, until=6))  # blue touches it ...
    # ... and it leaves at the speed of a kicker stronger than the simulator's (which stops at 6.5 m/s)
    w.place_ball(*w.ball_body.position, vx=speed)
    calls = play(w, ref, 0.1)
    fast = [c for c in calls if c.kind == "ball_too_fast"]
    assert bool(fast) == called
    if called:
        assert (fast[0].team, fast[0].robot, fast[0].restart, fast[0].for_team) == \
            ("blue", 1, RefereeCommand.FREE_KICK, "yellow")
        assert fast[0].value == pytest.approx(8.0, abs=0.3)


@pytest.mark.parametrize(("seconds", "called"), [(3.2, True), (1.2, False)])
def test_dribbling_the_ball_farther_than_the_limit(seconds: float, called: bool) -> None:
    w, ref = scene()
    w.place_robot("blue", 1, -2.0, 0.0, 0.0)
    w.place_ball(-2.0 + FRONT + 0.002, 0.0)
    calls = play(w, ref, seconds, drive("blue", 1, vx=0.5, dribbler=1.0))
    assert w.holding("blue", 1)
    dribbles = [c for c in calls if c.kind == "excessive_dribbling"]
    assert bool(dribbles) == called
    if called:
        assert dribbles[0].value > 1.0 and dribbles[0].restart is RefereeCommand.FREE_KICK


@pytest.mark.parametrize(("ball_x", "called"), [(4.1, True), (3.0, False)])
def test_attacker_touching_the_ball_in_the_opponents_defense_area(ball_x: float, called: bool) -> None:
    w, ref = scene()  # blue defends -x: the area at +x is yellow's
    w.place_robot("blue", 1, ball_x - 0.4, 0.3, 0.0)
    w.place_ball(ball_x, 0.3)
    calls = play(w, ref, 1.0, drive("blue", 1, vx=0.6, until=40))
    fouls = [c for c in calls if c.kind == "attacker_in_defense_area"]
    assert bool(fouls) == called
    if called:
        assert (fouls[0].team, fouls[0].robot, fouls[0].restart, fouls[0].for_team) == \
            ("blue", 1, RefereeCommand.FREE_KICK, "yellow")


@pytest.mark.parametrize(("rid", "called"), [(1, True), (0, False)])  # 0: the keeper may
def test_defender_in_its_own_defense_area_at_the_ball_gives_a_penalty(rid: int, called: bool) -> None:
    w, ref = scene()
    w.place_robot("blue", rid, -4.3, 0.0, 0.0)
    w.place_ball(-4.3 + FRONT + 0.05, 0.0)
    calls = play(w, ref, 1.5, drive("blue", rid, vx=0.5, until=20))
    fouls = [c for c in calls if c.kind == "defender_in_defense_area"]
    assert bool(fouls) == called
    if called:
        assert (fouls[0].restart, fouls[0].for_team) == (RefereeCommand.PENALTY, "yellow")
        g = ref.game
        assert g.command == RefereeCommand.PENALTY and g.for_team == "yellow" and not g.ready  # the restart came
        assert tuple(w.ball_body.position) == pytest.approx((-4.5 + 6.0, 0.0))  # on the mark, 6 m out


@pytest.mark.parametrize(("again", "called"), [(True, True), (False, False)])
def test_double_touch_after_a_free_kick(again: bool, called: bool) -> None:
    w, ref = scene()
    w.apply(ref.free_kick("blue", (0.0, 0.0)))
    w.place_robot("blue", 1, -FRONT - 0.05, 0.0, 0.0)

    def commands(k: int) -> list[RobotCommand]:
        if k < 30:  # kick it away, stand, then drive after it again (or not)
            return [RobotCommand("blue", 1, vx=0.5, kick_speed=1.0)]  # off at 1.5 m/s: the kick adds to the robot's 0.5
        return [RobotCommand("blue", 1, vx=1.5 if again and k > 60 else 0.0)]

    calls = play(w, ref, 2.5, commands)
    doubles = [c for c in calls if c.kind == "double_touch"]
    assert bool(doubles) == called
    if called:
        assert (doubles[0].team, doubles[0].robot, doubles[0].for_team) == ("blue", 1, "yellow")


@pytest.mark.parametrize(("speed", "called"), [(2.0, True), (1.0, False)])
def test_robot_too_fast_in_a_stop(speed: float, called: bool) -> None:
    w, ref = scene()
    ref.give(RefereeCommand.STOP)
    w.place_robot("yellow", 1, -3.0, 0.5, 0.0)
    calls = play(w, ref, 3.0, drive("yellow", 1, vx=speed))
    fouls = [c for c in calls if c.kind == "stop_speed"]
    assert bool(fouls) == called
    if called:
        assert fouls[0].t >= 2.0  # after the rules' time to slow down
        assert fouls[0].value == pytest.approx(2.0, abs=0.1) and fouls[0].restart is None
        assert ref.game.command == RefereeCommand.STOP  # counted, play stays stopped


@pytest.mark.parametrize(("gap", "called"), [(0.3, True), (0.8, False)])
def test_robot_too_close_to_the_ball_in_a_stop(gap: float, called: bool) -> None:
    w, ref = scene()
    ref.give(RefereeCommand.STOP)
    w.place_robot("yellow", 1, 0.0 - gap - R, 1.5, 0.0)
    calls = play(w, ref, 2.5)
    fouls = [c for c in calls if c.kind == "stop_distance"]
    assert bool(fouls) == called
    if called:
        assert fouls[0].team == "yellow" and fouls[0].value == pytest.approx(gap, abs=0.01)


@pytest.mark.parametrize(("gap", "called"), [(0.3, True), (0.8, False)])
def test_defender_too_close_at_a_free_kick(gap: float, called: bool) -> None:
    w, ref = scene()
    w.apply(ref.free_kick("blue", (1.0, 1.0)))
    w.place_robot("yellow", 1, 1.0 + gap + R, 1.0, math.pi)
    calls = play(w, ref, 1.5)
    fouls = [c for c in calls if c.kind == "kick_point_distance"]
    assert bool(fouls) == called
    if called:
        assert fouls[0].team == "yellow" and fouls[0].value == pytest.approx(gap, abs=0.01)


@pytest.mark.parametrize(("seconds", "called"), [(2.5, True), (1.5, False)])
def test_keeper_holding_the_ball(seconds: float, called: bool) -> None:
    w, ref = scene()
    ref = Referee(w.field, w.robot_keys(), RefereeParams(keeper_held_ball_s=2.0))
    ref.give(RefereeCommand.NORMAL)
    w.place_ball(-4.2, 0.3)  # at rest in blue's area
    calls = play(w, ref, seconds)
    held = [c for c in calls if c.kind == "keeper_held_ball"]
    assert bool(held) == called
    if called:
        assert (held[0].team, held[0].restart, held[0].for_team) == ("blue", RefereeCommand.FREE_KICK, "yellow")


@pytest.mark.parametrize(("beyond", "called"), [(0.5, True), (-0.5, False)])
def test_ball_over_the_boundary(beyond: float, called: bool) -> None:
    w, ref = scene()
    w.place_robot("blue", 1, 1.0, 2.0, math.pi / 2)
    w.place_ball(1.0, 2.0 + FRONT + 0.002)
    play(w, ref, 0.2, drive("blue", 1, vy=0.3))  # blue touches it last ...
    w.place_ball(1.0, w.field.boundary_half_width + beyond)  # ... and it flies over the wall (or not)
    calls = play(w, ref, 0.1)
    fouls = [c for c in calls if c.kind == "boundary_crossing"]
    assert bool(fouls) == called
    if called:
        assert (fouls[0].team, fouls[0].robot) == ("blue", 1)


def test_every_third_foul_is_a_yellow_card_that_sends_a_robot_off_for_its_time() -> None:
    w, ref = scene(blue=3, yellow=1, yellow_card_s=2.0)
    ref.give(RefereeCommand.STOP)
    for i, x in enumerate((-3.0, -2.5, -2.0)):
        w.place_robot("blue", i, x, -2.0, math.pi / 2)
    # three robots too fast in the stop: three fouls, a card; a robot but the keeper goes off
    calls = play(w, ref, 2.5, lambda k: [RobotCommand("blue", i, vy=2.0) for i in (0, 1, 2)])
    cards = [c for c in calls if c.kind == "yellow_card"]
    assert ref.cards.fouls["blue"] == 3 and len(cards) == 1 and cards[0].team == "blue"
    off = cards[0].robot
    assert off is not None and off != 0  # never the keeper
    x, y = tuple(w.robots[w.robot_keys().index(("blue", off))].body.position)
    assert y < -w.field.boundary_half_width  # parked outside the boundary
    assert ref.state().blue_team.max_robots == 2 and len(ref.state().blue_team.yellow_card_times_s) == 1
    calls = play(w, ref, 2.0)
    assert "yellow_card_over" in kinds(calls) and ref.state().blue_team.max_robots == 3
    x, y = tuple(w.robots[w.robot_keys().index(("blue", off))].body.position)
    assert w.field.in_field(x, y)  # back on, by the touch line


@pytest.mark.parametrize(("back_on", "called"), [(True, True), (False, False)])
def test_too_many_robots(back_on: bool, called: bool) -> None:
    w, ref = scene(blue=3, yellow=1, yellow_card_s=60.0)
    ref.card("blue", 2)
    play(w, ref, 0.1)
    if back_on:  # the robot sent off drives back on the field
        w.place_robot("blue", 2, 0.0, -1.0, 0.0)
    calls = play(w, ref, 0.5)
    fouls = [c for c in calls if c.kind == "too_many_robots"]
    assert bool(fouls) == called
    if called:
        assert fouls[0].value == 3 and fouls[0].limit == 2


def test_the_third_card_running_at_once_is_red() -> None:
    w, ref = scene(blue=4, yellow=1)
    for _ in range(3):
        ref.card("blue")
    assert ref.cards.yellow["blue"] == 2 and ref.cards.red["blue"] == 1
    assert ref.state().blue_team.max_robots == 1


@pytest.mark.parametrize(("carry", "succeeded"), [(True, True), (False, False)])
def test_ball_placement_succeeds_in_tolerance_and_fails_when_time_is_up(carry: bool, succeeded: bool) -> None:
    w, ref = scene(placement_time_s=8.0)
    target = (1.0, 0.0)
    ref.start_placement("blue", target)
    w.place_ball(0.0, 0.0)
    w.place_robot("blue", 1, -FRONT - 0.002, 0.0, 0.0)

    def commands(k: int) -> list[RobotCommand]:
        if not carry:
            return []
        if k < 60 * 5:  # scripted: carry the ball along x on the dribbler, hold it there ...
            bx = w.ball_body.position.x
            return [RobotCommand("blue", 1, vx=0.4 if target[0] - bx > 0.03 else 0.0, dribbler=1.0)]
        # ... then let go and back off
        return [RobotCommand("blue", 1, vx=-0.3)] if k < 60 * 6 else [RobotCommand("blue", 1)]

    calls = play(w, ref, 9.0, commands)
    if succeeded:
        done = [c for c in calls if c.kind == "placement_succeeded"]
        assert done and done[0].team == "blue" and done[0].value <= 8.0
        assert ref.tally.placements["blue"] == {"tried": 1, "succeeded": 1, "cut_short": 0}
    else:
        failed = [c for c in calls if c.kind == "placement_failed"]
        assert failed and failed[0].for_team == "yellow"
        assert tuple(w.ball_body.position) == pytest.approx(target)  # the referee placed it
        assert ref.tally.placement_failures["blue"] == 1
        assert ref.tally.placements["blue"] == {"tried": 1, "succeeded": 0, "cut_short": 0}


def test_a_placement_the_end_of_a_half_cuts_short_is_neither_tried_nor_failed() -> None:
    w, ref = scene(half_s=3.0, half_time_s=0.0)
    ref.start_placement("blue", (1.0, 0.0))  # nobody carries the ball: the half ends first
    calls = play(w, ref, 3.5)
    assert "stage_second_half" in kinds(calls) and not [k for k in kinds(calls) if k.startswith("placement_")]
    assert ref.tally.placements["blue"] == {"tried": 0, "succeeded": 0, "cut_short": 1}
    assert ref.tally.placement_failures["blue"] == 0
    ref.start_placement("blue", (1.0, 0.0))  # and one the match's end finds under way
    placed = ref.summary()["placements"]
    assert isinstance(placed, dict) and placed["blue"]["cut_short"] == 2 and placed["blue"]["tried"] == 0


def test_basic_rules_call_no_fouls() -> None:
    w, _ = scene()
    ref = Referee(w.field, w.robot_keys(), dataclasses.replace(RefereeParams(), rules="basic"))
    ref.give(RefereeCommand.NORMAL)
    w.place_robot("blue", 0, -1.0, 0.0, 0.0)
    w.place_robot("yellow", 0, 0.0, 0.0, math.pi)
    calls = play(w, ref, 1.0, drive("blue", 0, vx=2.5, until=40))
    assert calls == []


def test_a_penalty_shootout_alternates_its_kicks_and_ends_the_game() -> None:
    w, ref = scene(half_s=1.0, half_time_s=0.0, shootout_kicks=2, shootout_always=True, prepare_timeout_s=0.5,
                   penalty_time_s=3.0)
    takers: list[str] = []
    scored = {"n": 0}

    def commands(k: int) -> list[RobotCommand]:
        # yellow's first kick: the ball sent into the goal past the still keeper at the normal start
        # (nobody moves otherwise; the mark lies in the kicking team's own half)
        pen = ref.game.penalty
        if pen is not None and ref.game.ready and pen.team == "yellow" and not scored["n"]:
            w.place_ball(pen.mark[0], pen.mark[1], vx=-6.0 * math.copysign(1.0, pen.mark[0]), vy=0.35)
            scored["n"] = 1
        if pen is not None and (not takers or takers[-1][1] != pen.t_start):
            takers.append((pen.team, pen.t_start))  # type: ignore[arg-type]
        return []

    calls = play(w, ref, 2.0 + 4 * (1.0 + 0.5 + 3.0) + 2.0, commands)
    assert "stage_penalty_shootout" in kinds(calls) and kinds(calls)[-1] == "stage_post_game"
    assert [t for t, _ in takers] == ["yellow", "blue", "yellow", "blue"]  # type: ignore[misc]
    assert ref.tally.shootout == {"blue": {"taken": 2, "scored": 0}, "yellow": {"taken": 2, "scored": 1}}
    assert ref.score == {"blue": 0, "yellow": 0}  # the match's score stays
    assert ref.game.command == RefereeCommand.HALT and ref.game.stage == GameStage.POST_GAME


def test_no_shootout_after_a_match_decided_or_unconfigured() -> None:
    for figures in ({"shootout_kicks": 0}, {"shootout_kicks": 5}):
        w, ref = scene(half_s=1.0, half_time_s=0.0, **figures)
        if figures["shootout_kicks"]:
            ref.score["blue"] = 1  # decided: no shootout even when configured
        calls = play(w, ref, 2.5)
        assert "stage_penalty_shootout" not in kinds(calls) and ref.game.stage == GameStage.POST_GAME


def test_a_penalty_waits_for_a_ball_at_rest_and_ends_when_the_ball_turns_back() -> None:
    # the rules: the kicker may play the ball again and again for 10 s, the ball only ever moving
    # toward the goal; a keeper turning it back ends the kick
    w, ref = scene(prepare_timeout_s=0.5, penalty_time_s=5.0)
    w.apply(ref.start_penalty("blue"))
    mark = ref.game.penalty.mark if ref.game.penalty else (0.0, 0.0)
    calls = play(w, ref, 1.0)
    assert ref.game.ready
    w.place_ball(mark[0] + 0.5, mark[1])  # played forward, now at rest: still the kicker's
    calls += play(w, ref, 1.0)
    assert ref.game.command == RefereeCommand.PENALTY and "penalty_over" not in kinds(calls)
    w.place_ball(mark[0] + 0.5, mark[1], vx=-1.0)  # turned back toward the kicker's half
    calls += play(w, ref, 0.2)
    assert "penalty_over" in kinds(calls)


def test_a_penalty_ball_rolling_back_slower_than_the_rules_speed_leaves_the_kick_on() -> None:
    w, ref = scene(prepare_timeout_s=0.5, penalty_time_s=5.0, penalty_back_m_s=1.5)
    w.apply(ref.start_penalty("blue"))
    assert ref.game.penalty is not None
    mark = ref.game.penalty.mark
    play(w, ref, 1.0)
    w.place_ball(mark[0] + 0.5, mark[1], vx=-1.0)  # back toward the kicker's half, slower than 1.5 m/s
    calls = play(w, ref, 0.2)
    assert ref.game.command == RefereeCommand.PENALTY and "penalty_over" not in kinds(calls)


def test_the_ball_is_not_put_into_a_robot_on_the_penalty_mark() -> None:
    w, ref = scene()
    mark = (w.field.half_length - ref.rules.penalty_mark_from_goal_m, 0.0)  # blue attacks +x
    w.place_robot("yellow", 1, mark[0] + 0.02, mark[1] + 0.01, 0.0)  # standing on the mark
    play(w, ref, 0.1)
    teleport = ref.start_penalty("blue")
    w.apply(teleport)
    play(w, ref, 0.5)
    truth = w.ground_truth()
    assert math.hypot(truth.ball.x - mark[0], truth.ball.y - mark[1]) < 0.01  # the ball lies on the mark
    assert all(math.hypot(r.x - mark[0], r.y - mark[1]) >= R + LEAGUE.ball.radius_m for r in truth.robots)


def test_a_shootout_kick_has_only_the_kicker_and_the_other_keeper_on_the_field() -> None:
    # the rules: one attacker and the keeper per team; during an attempt only the kicker and the
    # other team's keeper move: the robot handlers take the others off and put these two in place
    w, ref = scene(blue=4, yellow=3, half_s=1.0, half_time_s=0.0, shootout_kicks=1, shootout_always=True,
                   prepare_timeout_s=0.5, penalty_time_s=1.0)
    seen = []

    def look(k: int) -> list[RobotCommand]:
        pen = ref.game.penalty
        if pen is not None and (not seen or seen[-1][0] != pen.team):
            truth = w.ground_truth()
            on = sorted((r.team, r.id) for r in truth.robots if w.field.in_field(r.x, r.y))
            seen.append((pen.team, on, (truth.ball.x, truth.ball.y), pen.mark))
        return []

    play(w, ref, 2.0 + 2 * (1.0 + 0.5 + 1.0) + 1.0, look)
    assert [s[0] for s in seen] == ["yellow", "blue"]
    assert seen[0][1] == [("blue", 0), ("yellow", 1)]  # blue's keeper, yellow's kicker (the lowest field id)
    assert seen[1][1] == [("blue", 1), ("yellow", 0)]
    for _, _, ball, mark in seen:
        assert math.hypot(ball[0] - mark[0], ball[1] - mark[1]) < 0.01
    assert ref.game.stage == GameStage.POST_GAME


@pytest.mark.parametrize(("roll", "called"), [(0.0, True), (0.4, False)])
def test_no_progress_in_game_stops_play_and_force_starts_it(roll: float, called: bool) -> None:
    """The rules' no progress in game: the ball in one place for no_progress_s while both teams may
    play it is a stop, then a force start where it lies; a ball that rolls on is progress."""
    w, ref = scene()
    w.place_ball(0.0, 1.5, vx=roll)
    calls = play(w, ref, RefereeParams().no_progress_s + 0.5)
    stuck = [c for c in calls if c.kind == "no_progress"]
    assert bool(stuck) == called
    if called:
        assert stuck[0].t == pytest.approx(RefereeParams().no_progress_s, abs=0.05) and stuck[0].team is None
        assert ref.game.command == RefereeCommand.STOP
        play(w, ref, RefereeParams().restart_delay_s + 0.1)
        assert ref.game.command == RefereeCommand.FORCE_START
        assert math.dist(tuple(w.ball_body.position), (0.0, 1.5)) < RefereeParams().no_progress_m  # not moved
    else:
        assert ref.game.command == RefereeCommand.NORMAL


def test_the_ball_held_in_a_defense_area_is_called_after_the_limit_of_watched_play() -> None:
    pitch = Field(LEAGUE)
    held = HeldBall(pitch, 2.0)
    in_area = (-(pitch.half_length - 0.3), 0.0)
    assert pitch.in_defense_area(*in_area) == -1
    ts = [0.5 * k for k in range(12)]
    calls = [(t, held.held(t, in_area, watched=True)) for t in ts]
    assert [t for t, side in calls if side] == [2.0, 4.5]  # counting again from the frame after a call
    assert all(side in (0, -1) for _, side in calls)
    held = HeldBall(pitch, 2.0)
    assert [held.held(t, in_area, watched=t != 1.5) for t in ts[:9]] == [0] * 8 + [-1]  # a break starts again
    assert HeldBall(pitch, 2.0).held(5.0, (0.0, 0.0), watched=True) == 0


def test_no_progress_is_the_ball_within_its_distance_for_the_limit() -> None:
    stuck = NoProgress(limit_s=3.0, within_m=0.05)
    wobble = [(0.0, 0.0), (0.03, 0.0), (0.0, 0.04), (0.04, 0.02)]
    assert [stuck.stuck(float(k), wobble[k % 4], watched=True) for k in range(5)] == [False] * 3 + [True, False]
    moving = NoProgress(limit_s=3.0, within_m=0.05)
    assert not any(moving.stuck(float(k), (0.06 * k, 0.0), watched=True) for k in range(10))
    unwatched = NoProgress(limit_s=3.0, within_m=0.05)
    assert not any(unwatched.stuck(float(k), (0.0, 0.0), watched=k != 2) for k in range(5))


def _frame(ball: tuple[float, float, float, float], *robots: tuple[Team, int, float, float]) -> GroundTruth:
    bx, by, vx, vy = ball
    return GroundTruth(0, 0.0, BallTruth(bx, by, 0.0, vx, vy),
                       tuple(RobotTruth(t, i, x, y, 0.0, 0.0, 0.0, 0.0) for t, i, x, y in robots))


@pytest.mark.parametrize(("ball", "robot_at", "off_m", "done"), [
    ((1.1, 0.0, 0.0, 0.0), (2.0, 0.0), 0.1, True),  # within the tolerance, at rest, the placer clear
    ((1.2, 0.0, 0.0, 0.0), (2.0, 0.0), 0.2, False),  # too far off the target
    ((1.1, 0.0, 0.2, 0.0), (2.0, 0.0), 0.1, False),  # still rolling
    ((1.1, 0.0, 0.0, 0.0), (1.1 + R + 0.03, 0.0), 0.1, False),  # the placer still at the ball
])
def test_a_placement_succeeds_with_the_ball_near_the_target_at_rest_and_the_placer_clear(
        ball: tuple[float, float, float, float], robot_at: tuple[float, float], off_m: float,
        done: bool) -> None:
    gt = _frame(ball, ("blue", 0, *robot_at), ("yellow", 0, 1.1 + R + 0.03, 0.1))  # the other team may stand there
    off, ok = placed(gt, "blue", (1.0, 0.0), Field(LEAGUE), RulesParams())
    assert off == pytest.approx(off_m) and ok is done


@pytest.mark.parametrize(("yellow_keeper_x", "blue_mate_x", "ready"), [
    (-4.45, 0.5, True), (-4.0, 0.5, False),  # the keeper off its line
    (-4.45, -2.0, False),  # a team-mate of the kicker 0.5 m behind the mark (at -2.5 m): less than 1 m
])
def test_a_penalty_is_set_when_all_but_kicker_and_keeper_are_behind_the_mark(
        yellow_keeper_x: float, blue_mate_x: float, ready: bool) -> None:
    pitch = Field(LEAGUE)
    mark = (-pitch.half_length + 2.0, 0.0)  # blue attacks -x
    gt = _frame((*mark, 0.0, 0.0), ("blue", 1, mark[0] + 0.2, 0.0), ("blue", 2, blue_mate_x, 1.0),
                ("yellow", 0, -pitch.half_length + (yellow_keeper_x + 4.5), 0.0), ("yellow", 1, 0.0, -1.0),
                ("yellow", 2, mark[0] + 0.3, 0.5))
    assert penalty_set(gt, "blue", mark, -1.0, pitch, RulesParams(), off={("yellow", 2)}) is ready
    assert not penalty_set(gt, "blue", mark, -1.0, pitch, RulesParams(), off=set())  # yellow 2 on the field, ahead


def test_a_kickoff_whose_ball_is_seen_late_on_the_centre_spot_is_not_taken_until_it_moves_from_there() -> None:
    """An auto-referee on tracked vision sees the ball it put on the centre spot arrive frames late:
    the ball still seen where play left it is no kickoff taken; once seen on the spot, moving
    ``ball_in_play_m`` from it is."""
    w, ref = scene()
    left = (3.0, 1.0)  # where play left the ball
    w.place_ball(*left)
    teleport = ref.kickoff_setup("yellow")
    for _ in range(5):  # the teleport not seen yet
        w.step_frame([])
        ref.observe(w.t, [], left)
        assert ref.game.command == RefereeCommand.KICKOFF
    w.apply(teleport)
    for _ in range(5):
        w.step_frame([])
        ref.observe(w.t, [], tuple(w.ball_body.position))
        assert ref.game.command == RefereeCommand.KICKOFF
    w.place_ball(2 * ref.rules.ball_in_play_m, 0.0)
    w.step_frame([])
    ref.observe(w.t, [], tuple(w.ball_body.position))
    assert ref.game.command == RefereeCommand.NORMAL


def test_the_kickoff_after_a_goal_is_not_taken_while_the_ball_is_still_seen_in_the_goal() -> None:
    """The kickoff the referee sets up after a goal (its ball put on the centre spot by a teleport):
    an auto-referee on tracked vision sees the ball still in the goal the frames after the teleport
    (ER-Force self-play: normal play the frame after, our robot went for the ball in the centre
    circle and a double touch was called); it is taken once the ball, seen on the spot, moves."""
    w, ref = scene()
    left = (w.field.half_length + 0.05, 0.1)  # in the goal
    w.place_ball(*left)
    ref.observe(w.t, [Goal(w.t, "blue", *left)], left, w.ground_truth())
    teleport = None
    for _ in range(round((ref.params.restart_delay_s + 1.0) * 60)):  # the restart due, its teleport not seen
        w.step_frame([])
        put = ref.observe(w.t, [], left, w.ground_truth())
        teleport = teleport or put
        assert ref.game.command in (RefereeCommand.STOP, RefereeCommand.KICKOFF)
    assert teleport is not None and teleport.ball == (0.0, 0.0) and ref.game.command == RefereeCommand.KICKOFF
    w.apply(teleport)
    for _ in range(5):
        w.step_frame([])
        ref.observe(w.t, [], tuple(w.ball_body.position), w.ground_truth())
        assert ref.game.command == RefereeCommand.KICKOFF
    w.place_ball(2 * ref.rules.ball_in_play_m, 0.0)
    w.step_frame([])
    ref.observe(w.t, [], tuple(w.ball_body.position), w.ground_truth())
    assert ref.game.command == RefereeCommand.NORMAL


def test_the_second_half_straight_from_play_stops_before_it_puts_the_robots_in_formation() -> None:
    # no half time: the first half ends in play, a robot holding the ball on its dribbler. The
    # formation's teleport comes after a stop (as after a goal), once the robots let go of the ball
    # (grSim holds a dribbled ball by a joint: teleported at once, the robot flung it off the field)
    w, ref = scene(half_s=3.0, half_time_s=0.0)
    ref.give(RefereeCommand.NORMAL)
    teleports: list[tuple[float, RefereeCommand]] = []
    for _ in range(round(3.0 * 60)):
        events = w.step_frame([])
        tp = ref.observe(w.t, events, tuple(w.ball_body.position), w.ground_truth())
        if tp is not None:
            teleports.append((w.t, ref.game.command))
            w.apply(tp)
    assert ref.game.stage == GameStage.FIRST_HALF and not teleports
    commands = []
    for _ in range(round(2.0 * 60)):
        events = w.step_frame([])
        tp = ref.observe(w.t, events, tuple(w.ball_body.position), w.ground_truth())
        commands.append((w.t, ref.game.command, ref.game.for_team))
        if tp is not None:
            teleports.append((w.t, ref.game.command))
            w.apply(tp)
    assert ref.game.stage == GameStage.SECOND_HALF
    assert commands[0][1] == RefereeCommand.STOP
    assert len(teleports) == 1 and teleports[0][1] == RefereeCommand.KICKOFF
    stop_s = teleports[0][0] - commands[0][0]
    assert stop_s == pytest.approx(ref.params.restart_delay_s, abs=2.0 / 60)
    # the formation: robots in their own halves (blue defends +x now), the ball on the centre spot
    assert tuple(w.ball_body.position) == pytest.approx((0.0, 0.0))
    robots = w.ground_truth().robots
    assert robots and all(r.x * (ref.blue_sign if r.team == "blue" else -ref.blue_sign) > 0.0 for r in robots)
