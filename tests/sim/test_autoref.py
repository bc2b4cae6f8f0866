"""The auto-referee on tracks: in scripted scenes of the simulator's world, the referee judging the
truth and the autoref judging the tracker's estimate from noisy detections of the same frames make
the same calls (kind, team, within a few frames); a stuck ball is restarted; with ``place_by: robots``
no teleport is asked for and the teams place the ball."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cmdragons.geometry import LeagueParams
from cmdragons.messages import (
    BallDetection,
    DetectionFrame,
    GameEvent,
    RefereeCommand,
    RobotCommand,
    RobotDetection,
    WorldState,
)
from cmdragons.tracking import Tracker, TrackerParams
from sim.autoref import AutoRef, BallCrossing, KickDetector
from sim.referee import Referee
from sim.referee_params import AutorefParams, RefereeParams
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World
from tests.sim.test_rules import Commands, drive

SIGMA_M = 0.002  # the detections' noise (m), about our vision's on the simulator's cameras
SAME_S = 0.1  # the autoref's call within this of the truth referee's (s): a few frames of tracking
LEAGUE = LeagueParams()
FRONT = LEAGUE.robot.front_distance_m + LEAGUE.ball.radius_m  # a ball at a robot's front: its centre this far ahead


def scene(params: RefereeParams | None = None) -> tuple[World, Referee, AutoRef]:
    """Robots parked apart along the bottom touch line, the ball at rest mid-field; both referees in
    normal play."""
    w = World(LEAGUE, PhysicsParams(), RobotParams(command_latency_s=0.0), BallParams(), KickerParams(),
              DribblerParams(), robots_per_team={"blue": 2, "yellow": 2})
    for i, (team, rid) in enumerate(w.robot_keys()):
        w.place_robot(team, rid, -3.5 + 1.0 * i, -2.6, 0.0)
    w.place_ball(0.0, 1.5)
    params = params if params is not None else RefereeParams()
    ref = Referee(w.field, w.robot_keys(), params)
    auto = AutoRef(w.field, w.robot_keys(), params)
    for r in (ref, auto.referee):
        r.give(RefereeCommand.NORMAL)
    return w, ref, auto


class Seen:
    """What the cameras show of the world: its truth with Gaussian noise, tracked."""

    def __init__(self, seed: int = 1) -> None:
        self.rng = np.random.default_rng(seed)
        self.tracker = Tracker(TrackerParams())
        self.n = 0

    def __call__(self, w: World) -> WorldState:
        gt, n = w.ground_truth(), self.rng.normal
        self.n += 1
        ball = (BallDetection(gt.ball.x + n(0, SIGMA_M), gt.ball.y + n(0, SIGMA_M), 1.0, (0.0, 0.0)),)
        robots = tuple(RobotDetection(r.team, r.id, r.x + n(0, SIGMA_M), r.y + n(0, SIGMA_M), r.theta + n(0, 0.01),
                                      1.0, (0.0, 0.0)) for r in gt.robots)
        world = self.tracker.step([DetectionFrame(0, self.n, gt.t, gt.t, ball, robots)], ahead_s=0.0)
        return dataclasses.replace(world, frame_number=self.n)


def play(w: World, ref: Referee | None, auto: AutoRef, seen: Seen, seconds: float,
         commands: Commands | None = None) -> tuple[list[GameEvent], list[GameEvent]]:
    """Both referees judge every frame (the truth referee drives: the world carries out its
    teleports; without it the autoref's); their calls."""
    truth: list[GameEvent] = []
    mine: list[GameEvent] = []
    for k in range(round(seconds * 60)):
        world = seen(w)  # the frame as captured, before the step
        events = w.step_frame(commands(k) if commands else [])
        own = auto.observe(world)
        mine += auto.calls
        teleport = own
        if ref is not None:
            teleport = ref.observe(w.t, events, tuple(w.ball_body.position), w.ground_truth())
            truth += ref.calls.new
        if teleport is not None:
            w.apply(teleport)
    return truth, mine


def same(truth: list[GameEvent], mine: list[GameEvent], kind: str) -> None:
    """The truth referee called ``kind`` and the autoref did the same: as many, each against the same
    team (and robot, where one is named) with the same restart, within ``SAME_S``."""
    t = [c for c in truth if c.kind == kind]
    m = [c for c in mine if c.kind == kind]
    assert t, f"the truth referee made no {kind} call: {truth}"
    assert len(m) == len(t), (t, m)
    for a, b in zip(t, m, strict=True):
        assert (b.team, b.restart, b.for_team) == (a.team, a.restart, a.for_team)
        assert b.robot == a.robot or a.robot is None
        assert abs(b.t - a.t) <= SAME_S


def test_a_crash_is_called_on_tracks_as_on_the_truth() -> None:
    w, ref, auto = scene()
    w.place_robot("blue", 0, -0.5, 0.0, 0.0)
    w.place_robot("yellow", 0, 0.5, 0.0, math.pi)
    truth, mine = play(w, ref, auto, Seen(), 1.5, drive("blue", 0, vx=2.5))
    same(truth, mine, "crash")


def test_a_double_touch_after_a_free_kick_is_seen_by_the_kick_detector() -> None:
    w, ref, auto = scene()
    w.apply(ref.free_kick("blue", (0.0, 0.0)))
    auto.referee.free_kick("blue", (0.0, 0.0))
    w.place_robot("blue", 1, -FRONT - 0.05, 0.0, 0.0)

    def commands(k: int) -> list[RobotCommand]:
        if k < 30:  # kick it away, stand, then drive after it again
            return [RobotCommand("blue", 1, vx=0.5, kick_speed=1.5)]
        return [RobotCommand("blue", 1, vx=1.5 if k > 60 else 0.0)]

    truth, mine = play(w, ref, auto, Seen(), 2.5, commands)
    same(truth, mine, "double_touch")


@pytest.mark.parametrize(("y", "kind"), [(0.0, "goal"), (1.2, "ball_out")])
def test_a_kick_into_the_goal_or_past_the_goal_line_is_seen_with_its_kicker(y: float, kind: str) -> None:
    """Blue (attacking +x) kicks from 2 m before the goal: into it (a goal, the kickoff for yellow) or
    beside it (out: the free kick for yellow, blue touched it last)."""
    w, ref, auto = scene()
    x = w.field.half_length - 2.0
    w.place_ball(x, y)
    w.place_robot("blue", 1, x - FRONT - 0.05, y, 0.0)
    truth, mine = play(w, ref, auto, Seen(), 2.0, drive("blue", 1, vx=0.5, kick_speed=3.0, until=20))
    assert [c.kind for c in mine if c.kind in ("goal", "ball_out")] == [kind]
    call = next(c for c in mine if c.kind == kind)
    assert call.for_team == "yellow" and call.team == "blue"
    assert ref.score == auto.referee.score and ref.balls_out == auto.referee.balls_out
    crossed = next(e for e in truth + mine if e.kind == kind).t
    assert abs(call.t - crossed) <= SAME_S


@pytest.mark.parametrize(("speed", "called"), [(2.0, True), (1.0, False)])
def test_a_robot_too_fast_in_a_stop_on_tracks(speed: float, called: bool) -> None:
    w, ref, auto = scene()
    for r in (ref, auto.referee):
        r.give(RefereeCommand.STOP)
    w.place_robot("yellow", 1, -3.0, 0.5, 0.0)
    truth, mine = play(w, ref, auto, Seen(), 3.0, drive("yellow", 1, vx=speed))
    if called:
        same(truth, mine, "stop_speed")
    else:
        assert not [c for c in truth + mine if c.kind == "stop_speed"]


def test_a_stuck_ball_is_stopped_and_force_started_by_the_autoref_alone() -> None:
    """No truth referee: the tracked ball lies still for the rules' time in normal play -> no progress,
    a stop, then a force start where it lies after the restart delay."""
    params = RefereeParams()
    w, _, auto = scene(params)
    _, mine = play(w, None, auto, Seen(), params.no_progress_s + 0.5)
    stuck = [c for c in mine if c.kind == "no_progress"]
    assert len(stuck) == 1 and stuck[0].t == pytest.approx(params.no_progress_s, abs=0.1)
    assert auto.state().command == RefereeCommand.STOP
    play(w, None, auto, Seen(), params.restart_delay_s + 0.1)
    assert auto.state().command == RefereeCommand.FORCE_START
    assert math.dist(tuple(w.ball_body.position), (0.0, 1.5)) < params.no_progress_m  # where it lay


def test_placed_by_robots_the_autoref_asks_for_no_teleport_and_the_kicking_team_places_the_ball() -> None:
    """``place_by: robots``: after a goal the kicking team is asked to place the ball on the centre
    spot; once it lies there (put by hand here) with the team clear of it, the kickoff follows."""
    params = dataclasses.replace(RefereeParams(), place_by="robots")
    w, _, auto = scene(params)
    seen = Seen()
    teleports = []
    x = w.field.half_length - 1.0
    w.place_ball(x, 0.0)
    w.place_robot("blue", 1, x - FRONT - 0.05, 0.0, 0.0)
    kick = drive("blue", 1, vx=0.5, kick_speed=3.0, until=20)
    for k in range(round((1.5 + params.restart_delay_s) * 60)):
        world = seen(w)
        w.step_frame(kick(k))
        teleports.append(auto.observe(world))
    assert auto.referee.score["blue"] == 1
    g = auto.state()
    assert (g.command, g.for_team, g.placement) == (RefereeCommand.BALL_PLACEMENT, "yellow", (0.0, 0.0))
    w.place_ball(0.0, 0.0)  # placed by the yellow team
    w.place_robot("blue", 1, -1.0, 0.0, 0.0)
    for _ in range(round((0.5 + params.restart_delay_s) * 60)):
        world = seen(w)
        w.step_frame([])
        teleports.append(auto.observe(world))
    g = auto.state()
    assert (g.command, g.for_team) == (RefereeCommand.KICKOFF, "yellow")
    assert all(t is None for t in teleports)


def test_ball_crossing_calls_each_crossing_once_until_the_ball_is_back() -> None:
    f = World(LEAGUE, PhysicsParams(), RobotParams(), BallParams(), KickerParams(), DribblerParams(),
              robots_per_team={"blue": 0, "yellow": 0}).field
    c = BallCrossing(f)
    past = f.half_length + 0.05
    assert c.see(0.0, 0.0, 0.0, -1, None) is None
    goal = c.see(0.1, past, 0.0, -1, "yellow")
    assert goal is not None and type(goal).__name__ == "Goal" and goal.scoring_team == "blue"
    assert c.see(0.2, past + 0.05, 0.0, -1, "yellow") is None  # still out: once
    assert c.see(0.3, 0.0, 0.0, -1, None) is None
    out = c.see(0.4, 1.0, f.half_width + 0.05, -1, "yellow")
    assert out is not None and type(out).__name__ == "BallOut" and (out.y, out.last_touch) == (f.half_width, "yellow")


def test_the_kick_detector_ignores_a_ball_put_elsewhere() -> None:
    """A ball that jumps (the referee put it somewhere) is no touch, though its velocity changed and a
    robot stands where it now lies."""
    from cmdragons.messages import BallState, RobotState

    f = World(LEAGUE, PhysicsParams(), RobotParams(), BallParams(), KickerParams(), DribblerParams(),
              robots_per_team={"blue": 0, "yellow": 0}).field
    d = KickDetector(f, AutorefParams())
    robot = RobotState("blue", 1, 0.0, 0.0, 0.0)
    assert d.see(WorldState(0.0, BallState(2.0, 2.0, 1.0, 0.0), (robot,))) is None
    assert d.see(WorldState(1 / 60, BallState(FRONT, 0.0, 0.0, 0.0), (robot,))) is None  # put at the robot
    kick = d.see(WorldState(2 / 60, BallState(FRONT + 0.03, 0.0, 2.0, 0.0), (robot,)))  # then kicked by it
    assert kick is not None and (kick.team, kick.id) == ("blue", 1)


def test_placing_by_robots_needs_the_full_rules() -> None:
    with pytest.raises(ValueError, match="place_by"):
        RefereeParams(rules="basic", place_by="robots")

