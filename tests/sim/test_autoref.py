"""The auto-referee on tracks: in scripted scenes of the simulator's world, the referee judging the
truth and the autoref judging the tracker's estimate from noisy detections of the same frames make
the same calls (kind, team, within a few frames); a stuck ball is restarted; with ``place_by: robots``
no teleport is asked for and the teams place the ball."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
import pytest

from cmdragons.geometry import LeagueParams
from cmdragons.messages import (
    BallDetection,
    BallOut,
    BallState,
    DetectionFrame,
    GameEvent,
    RefereeCommand,
    RobotCommand,
    RobotDetection,
    RobotState,
    WorldState,
)
from cmdragons.tracking import Tracker, TrackerParams
from sim.autoref import AutoRef, BallCrossing, KickDetector, OwnContacts, hull_gap
from sim.referee import Referee
from sim.referee_params import AutorefParams, RefereeParams
from sim.restarts import ball_out_taker
from sim.rules import RulesParams
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


def play(w: World, ref: Referee | None, auto: AutoRef, seen: Callable[[World], WorldState], seconds: float,
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
            return [RobotCommand("blue", 1, vx=0.5, kick_speed=1.0)]  # off at 1.5 m/s: the kick adds to the robot's 0.5
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


# --- touches from scripted tracks: the ball's path and which robot it hit are the ground truth ---------
R_BALL = LEAGUE.ball.radius_m
REACH = LEAGUE.robot.radius_m + R_BALL  # a ball's centre this far from a robot's centre touches its round side
DT = 1 / 60


def deflected_track(hit: tuple[float, float], v_in: tuple[float, float], v_out: tuple[float, float],
                    robots: tuple[RobotState, ...], frames: int = 40, lag: int = 1,
                    seed: int = 1) -> list[WorldState]:
    """Tracked frames of a ball that rolls at ``v_in`` to the point ``hit`` (reached between frames 19
    and 20), is turned there to ``v_out`` by the robot it hit, and rolls on; positions with the noise
    of our tracks (``SIGMA_M``), the velocity showing the turn ``lag`` frames late (the tracker's)."""
    rng = np.random.default_rng(seed)
    t_hit = 19.5 * DT
    out = []
    for k in range(frames):
        t = k * DT
        v = v_in if t < t_hit else v_out
        x = hit[0] + v[0] * (t - t_hit) + rng.normal(0, SIGMA_M)
        y = hit[1] + v[1] * (t - t_hit) + rng.normal(0, SIGMA_M)
        seen_v = v_in if t < t_hit + lag * DT else v_out
        out.append(WorldState(t, BallState(x, y, *seen_v), robots, k))
    return out


def touches(track: list[WorldState]) -> list[tuple[str, int]]:
    """The kick detector's touches along ``track``, in order."""
    d = KickDetector(scene()[0].field, AutorefParams())
    kicks = [d.see(w) for w in track]
    return [(k.team, k.id) for k in kicks if k is not None]


def test_a_robots_body_gap_is_the_distance_to_its_disc_cut_flat_at_the_front() -> None:
    shape = LEAGUE.robot
    r, f = shape.radius_m, shape.front_distance_m
    assert shape.gap(-0.5, 0.0) == pytest.approx(0.5 - r, abs=1e-12)  # behind: the round side
    assert shape.gap(0.0, 0.3) == pytest.approx(0.3 - r, abs=1e-12)
    assert shape.gap(f + 0.01, 0.0) == pytest.approx(0.01, abs=1e-12)  # in front of the flat face (inside the disc)
    assert shape.gap(0.0, 0.0) == pytest.approx(-f, abs=1e-12)  # the centre: as deep as the front is near
    w = shape.mouth_half_width_m
    ux, uy = 1.0 + f / r, w / r  # between the face's normal and the round side's at the face's corner ...
    n = math.hypot(ux, uy)
    assert shape.gap(f + 0.05 * ux / n, w + 0.05 * uy / n) == pytest.approx(0.05, abs=1e-12)  # ... the corner nearest
    assert shape.gap(f + 0.03, w + 0.04) == pytest.approx(math.hypot(f + 0.03, w + 0.04) - r, abs=1e-12)  # the side


@pytest.mark.parametrize("pass_gap", [0.005, 0.01, 0.02])
def test_a_ball_deflected_by_a_robot_is_its_touch_though_it_then_passes_near_another(pass_gap: float) -> None:
    """The ball rolls at 3 m/s into yellow 0's round side (45 degrees off its centre line), is turned by
    90 degrees and passes blue 0 ``pass_gap`` from its body without touching it (the first miss of the
    autoref bench: blue was taken for the last toucher): the touch is yellow's, and stays yellow's."""
    a = math.radians(45.0)
    yellow = RobotState("yellow", 0, 0.0, 0.0, math.pi)  # facing the ball with its back away: the round side hit
    hit = (-REACH * math.cos(a), REACH * math.sin(a))
    v_in, v_out = (3.0, 0.0), (0.0, 2.4)
    # blue 0 beside the outgoing path 0.2 m on, its body pass_gap from the ball
    blue = RobotState("blue", 0, hit[0] - REACH - pass_gap, hit[1] + 0.2, 0.0)
    track = deflected_track(hit, v_in, v_out, (yellow, blue))
    assert touches(track) == [("yellow", 0)]
    auto = scene()[2]
    for w in track:
        auto.observe(w)
    assert auto.referee.watch.last_touch == ("yellow", 0)


@pytest.mark.parametrize("lag", [1, 2, 3])
def test_of_two_robots_of_both_teams_near_the_deflection_the_one_whose_body_the_path_met_touched(lag: int) -> None:
    """The ball bounces back off blue 1's front at 2 m/s; yellow 1 stands beside the point of the
    bounce, as near the ball when the turn shows (``lag`` frames late) as blue 1 is: the path went
    through blue 1's body, not yellow 1's."""
    blue = RobotState("blue", 1, 0.0, 0.0, math.pi)  # its flat front toward -x, where the ball comes from
    hit = (-LEAGUE.robot.front_distance_m - R_BALL, 0.0)
    yellow = RobotState("yellow", 1, hit[0] - 0.03, -REACH - 0.03, 0.0)
    track = deflected_track(hit, (2.0, 0.0), (-1.6, -0.3), (blue, yellow), lag=lag)
    assert touches(track) == [("blue", 1)]


@pytest.mark.parametrize(("depth", "touched"), [(0.008, True), (-0.008, False)])
def test_a_graze_the_track_runs_through_is_a_touch_a_near_pass_is_none(depth: float, touched: bool) -> None:
    """A ball at 1.5 m/s past blue 0's round side, its track straight on (a graze too slight for the
    kick detector, the track not turning yet): ``depth`` into the body (m; negative: that far
    outside it) is a touch by blue 0, a near pass none (yellow 0 kicked it before)."""
    blue = RobotState("blue", 0, 0.0, 0.0, 0.0)
    yellow = RobotState("yellow", 0, -1.0, 1.0, 0.0)
    auto = scene()[2]
    auto.referee.watch.kicked(("yellow", 0))
    y = -(REACH - depth)  # the ball's line: its centre REACH - depth below blue 0's
    for k in range(60):
        x = -0.6 + 1.5 * k * DT
        auto.observe(WorldState(k * DT, BallState(x, y, 1.5, 0.0), (blue, yellow), k))
    assert auto.referee.watch.last_touch == (("blue", 0) if touched else ("yellow", 0))


def _robots_meet(a: RobotState, b: RobotState, frames: int = 60) -> list[WorldState]:
    """Frames of ``a`` and ``b`` moving at their velocities until their centres are two radii apart,
    then standing there (with the noise of our tracks)."""
    rng = np.random.default_rng(3)
    out, pa, pb = [], (a.x, a.y), (b.x, b.y)
    for k in range(frames):
        if math.dist(pa, pb) > 2 * LEAGUE.robot.radius_m:
            pa = (pa[0] + a.vx * DT, pa[1] + a.vy * DT)
            pb = (pb[0] + b.vx * DT, pb[1] + b.vy * DT)
            va, vb = (a.vx, a.vy), (b.vx, b.vy)
        else:
            va = vb = (0.0, 0.0)
        robots = tuple(dataclasses.replace(r, x=p[0] + rng.normal(0, SIGMA_M), y=p[1] + rng.normal(0, SIGMA_M),
                                           vx=v[0], vy=v[1]) for r, p, v in ((a, pa, va), (b, pb, vb)))
        out.append(WorldState(k * DT, None, robots, k))
    return out


@pytest.mark.parametrize(("a", "b", "collisions"), [
    # two blue robots driving into each other at 0.5 m/s each: one collision
    (RobotState("blue", 0, -0.3, 0.0, 0.0, vx=0.5), RobotState("blue", 1, 0.3, 0.0, 0.0, vx=-0.5), {"blue": 1}),
    # one of them standing, the other at 0.3 m/s: one
    (RobotState("yellow", 2, 0.0, 0.0, 0.0), RobotState("yellow", 3, 0.0, 0.4, 0.0, vy=-0.3), {"yellow": 1}),
    # standing side by side 2 mm apart, the tracks' noise closing and opening the gap: none
    (RobotState("blue", 0, 0.0, 0.0, 0.0), RobotState("blue", 1, 2 * LEAGUE.robot.radius_m + 0.002, 0.0, 0.0), {}),
    # robots of both teams meeting: no own collision (a crash is the rules')
    (RobotState("blue", 0, -0.3, 0.0, 0.0, vx=0.5), RobotState("yellow", 0, 0.3, 0.0, 0.0, vx=-0.5), {}),
])
def test_own_collisions_are_counted_from_tracks_once_per_meeting(a: RobotState, b: RobotState,
                                                                  collisions: dict[str, int]) -> None:
    own = OwnContacts(scene()[0].field, AutorefParams())
    for w in _robots_meet(a, b):
        own.see(w)
    assert own.counts() == {"blue": collisions.get("blue", 0), "yellow": collisions.get("yellow", 0)}


# --- the last touch before a ball out, against the simulator's contacts (the physics' last toucher) --------
def _out_given_to(w: World, ref: Referee, mine: list[GameEvent]) -> tuple[str | None, str | None]:
    """Whose free kick the simulator's ball out is by its physics' last toucher (the ground truth),
    and whose the autoref gave."""
    out = next(e for e in w.events if isinstance(e, BallOut))
    call = next(c for c in mine if c.kind == "ball_out")
    return ball_out_taker(out.last_touch, out.x, ref.blue_sign), call.for_team


def exact(w: World) -> WorldState:
    """The world as tracks with no noise: the simulator's truth (the touch rule alone is judged)."""
    gt = w.ground_truth()
    b = gt.ball
    return WorldState(gt.t, BallState(b.x, b.y, b.vx, b.vy),
                      tuple(RobotState(r.team, r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega) for r in gt.robots),
                      gt.frame_number)


@pytest.mark.parametrize("start_x", [0.57, 0.58, 0.585])
def test_a_robot_closing_on_a_ball_that_rolls_out_before_it_reaches_it_is_no_touch(start_x: float) -> None:
    """Yellow 0 kicks the ball at 1.2 m/s down over the bottom touch line; blue 0, its flat front
    toward the ball's path, drives at it at 0.4 m/s and comes nearer than a robot's radius, the
    ball's and the touch margin (the disc's reach), its face never within the touch margin of the
    ball, and the simulator has no contact before the ball is
    out: the free kick is blue's (yellow touched last), and the truth referee too keeps yellow's touch
    (the second miss of the autoref bench; a near pass its disc took for blue's touch cost it seed
    9's double touch)."""
    w, ref, auto = scene()
    w.place_ball(1.0, -2.4)
    w.place_robot("yellow", 0, 1.0, -2.4 + FRONT, -math.pi / 2)
    w.place_robot("blue", 0, start_x, -w.field.half_width, 0.0)
    margin = RulesParams().touch_margin_m
    nearest, body = [math.inf], [math.inf]
    last: list[tuple[str, int] | None] = []

    def commands(k: int) -> list[RobotCommand]:
        gt = w.ground_truth()
        blue = next(r for r in gt.robots if (r.team, r.id) == ("blue", 0))
        if abs(gt.ball.y) < w.field.half_width + R_BALL:
            nearest[0] = min(nearest[0], math.hypot(blue.x - gt.ball.x, blue.y - gt.ball.y))
            body[0] = min(body[0], hull_gap(LEAGUE.robot, (blue.x, blue.y, blue.theta), gt.ball.x, gt.ball.y) - R_BALL)
            last[:] = [ref.watch.last_touch, auto.referee.watch.last_touch]  # until the ball is out: the last toucher
        return [RobotCommand("yellow", 0, kick_speed=1.2 if 20 <= k < 23 else 0.0),
                RobotCommand("blue", 0, vx=0.4 if k > 20 else 0.0)]

    truth, mine = play(w, ref, auto, exact, 2.5, commands)
    out = next(e for e in w.events if isinstance(e, BallOut))
    assert out.last_touch == "yellow"  # the scene is what it says: near the disc, not the body, no contact
    assert nearest[0] < LEAGUE.robot.radius_m + R_BALL + margin and body[0] > margin
    assert _out_given_to(w, ref, mine) == ("blue", "blue")
    assert last == [("yellow", 0), ("yellow", 0)]


# a recorded situation (``cmdragons bench autoref``, seed 8, 3.62-3.85 s: the tracked frames of the two
# robots at the ball): blue 5 holds the ball at its front, yellow 4 faces it from the other side and
# kicks it into blue 5's front, off which it leaves to +y (the simulator's last touch: blue's; the ball
# then rolled out over the touch line, yellow's free kick). Per frame: t, ball (x, y, vx, vy), blue 5
# and yellow 4 (x, y, theta).
SQUEEZED = (
    (3.6167, (-0.4439, -1.2422, -0.1655, -0.4793), (-0.5354, -1.2443, 0.0234), (-0.2584, -1.2853, 2.8275)),
    (3.6333, (-0.4468, -1.2437, -0.1528, -0.4442), (-0.5379, -1.2518, 0.0886), (-0.2697, -1.2829, 2.8291)),
    (3.65, (-0.4501, -1.2455, -0.1585, -0.4214), (-0.5406, -1.2589, 0.1474), (-0.2821, -1.2801, 2.829)),
    (3.6667, (-0.4527, -1.2478, -0.0894, -0.4722), (-0.5422, -1.2666, 0.2075), (-0.2946, -1.2773, 2.8283)),
    (3.6833, (-0.4561, -1.2477, -0.1055, -0.3954), (-0.544, -1.2734, 0.2848), (-0.3079, -1.2741, 2.8279)),
    (3.7, (-0.4599, -1.2472, -0.0901, -0.3495), (-0.5455, -1.2794, 0.3595), (-0.3205, -1.2716, 2.8265)),
    (3.7167, (-0.4643, -1.2461, -0.1326, -0.2641), (-0.5476, -1.284, 0.4271), (-0.3336, -1.2683, 2.8265)),
    (3.7333, (-0.4521, -1.2554, 0.5044, -0.4775), (-0.5493, -1.2884, 0.503), (-0.3467, -1.2663, 2.8226)),
    (3.75, (-0.4572, -1.2542, -0.2807, 0.0597), (-0.55, -1.2915, 0.5758), (-0.3597, -1.2637, 2.8255)),
    (3.7667, (-0.4831, -1.2264, -1.0615, 1.0768), (-0.5513, -1.2931, 0.6396), (-0.3729, -1.2614, 2.8249)),
    (3.7833, (-0.502, -1.1624, -1.0264, 1.0412), (-0.5544, -1.2945, 0.6864), (-0.3836, -1.2588, 2.8202)),
    (3.8, (-0.5197, -1.0994, -1.0583, 3.7761), (-0.56, -1.2973, 0.7106), (-0.3918, -1.2545, 2.8224)),
    (3.8167, (-0.5374, -1.0372, -1.0524, 3.7087), (-0.5644, -1.2999, 0.734), (-0.3986, -1.2498, 2.8349)),
    (3.8333, (-0.5548, -0.976, -1.041, 3.656), (-0.569, -1.3018, 0.7622), (-0.4055, -1.2448, 2.8471)),
    (3.85, (-0.572, -0.9154, -1.0234, 3.6092), (-0.5732, -1.3036, 0.7946), (-0.4114, -1.239, 2.8535)),
)


# the same, recorded at seed 6, 18.60-18.73 s: blue 5 holds the ball, yellow 4 kicks it into blue 5's
# front (both kick in the simulator, blue at 1.5 m/s, yellow at 4.2 m/s a step later; its last touch:
# blue's); the track shows one turn, nearest yellow 4's face
SQUEEZED_AGAIN = (
    (18.6, (-0.4651, -1.1616, -0.0049, -0.3544), (-0.5493, -1.1974, 0.4019), (-0.3158, -1.2201, 2.8474)),
    (18.6167, (-0.467, -1.1641, 0.0181, -0.4427), (-0.5491, -1.2046, 0.4581), (-0.3265, -1.2171, 2.844)),
    (18.6333, (-0.4614, -1.1642, 0.2514, -0.1181), (-0.5491, -1.2114, 0.5105), (-0.3372, -1.2141, 2.846)),
    (18.65, (-0.4642, -1.1674, -0.142, -0.1898), (-0.549, -1.2175, 0.57), (-0.3487, -1.2101, 2.8456)),
    (18.6667, (-0.4676, -1.1688, -0.1623, -0.0931), (-0.5487, -1.2225, 0.6121), (-0.3614, -1.206, 2.85)),
    (18.6833, (-0.485, -1.1549, -0.5972, 0.4149), (-0.5484, -1.2255, 0.646), (-0.374, -1.202, 2.8458)),
    (18.7, (-0.5224, -1.0975, -0.5561, 0.3864), (-0.553, -1.2272, 0.6618), (-0.3824, -1.1981, 2.8752)),
    (18.7167, (-0.5502, -1.036, -1.6667, 3.6866), (-0.5587, -1.2286, 0.6662), (-0.3897, -1.1947, 2.9255)),
    (18.7333, (-0.5779, -0.9753, -1.652, 3.6205), (-0.5636, -1.2292, 0.6615), (-0.3971, -1.1904, 2.9767)),
)


def squeezed_autoref(frames: tuple[tuple[float, tuple[float, ...], tuple[float, ...], tuple[float, ...]], ...]
                     = SQUEEZED) -> AutoRef:
    """The autoref after the recorded ``frames`` (:data:`SQUEEZED`), in normal play, the first of
    them held for 0.2 s before (blue 5 holding the ball before the recording)."""
    auto = AutoRef(scene()[0].field, [("blue", 5), ("yellow", 4)], RefereeParams())
    auto.referee.give(RefereeCommand.NORMAL)
    t0, *first = frames[0]
    held = tuple((t0 - 0.2 + k * DT, *first) for k in range(12))
    for k, (t, ball, blue, yellow) in enumerate((*held, *frames)):
        auto.observe(WorldState(t, BallState(*ball), (RobotState("blue", 5, *blue), RobotState("yellow", 4, *yellow)),
                                k))
    return auto


def test_a_ball_kicked_into_another_robots_front_was_touched_last_by_that_robot() -> None:
    """Yellow 4 kicks the ball blue 5 holds into blue 5's front; the track shows the kick (along
    yellow's heading, late) and the turn off blue's face to +y, 56 degrees off yellow's heading: the
    last touch is blue's (the simulator's), not yellow's kick seen late."""
    assert squeezed_autoref().referee.watch.last_touch == ("blue", 5)
    assert squeezed_autoref(SQUEEZED_AGAIN).referee.watch.last_touch == ("blue", 5)


def test_a_kick_seen_late_beside_another_robot_stays_the_kickers() -> None:
    """The same two robots, the ball kicked by yellow 4 along its heading with blue 5 beside it in reach:
    the track's velocity shows the kick in two steps (a third of its speed, then all of it, both along
    the heading; yellow's face the nearer in both): both steps are yellow's kick, blue never touched it."""
    theta = 2.8
    hx, hy = math.cos(theta), math.sin(theta)
    yellow = RobotState("yellow", 4, 0.0, 0.0, theta)
    bx, by = FRONT * hx, FRONT * hy  # the ball at yellow's front ...
    side = REACH + 0.045  # ... blue beside it, its body 0.045 m from the ball (in the kick detector's reach)
    blue = RobotState("blue", 5, bx + side * hy, by - side * hx, theta - math.pi / 2)
    auto = AutoRef(scene()[0].field, [("blue", 5), ("yellow", 4)], RefereeParams())
    auto.referee.give(RefereeCommand.NORMAL)
    speed, t_kick = 4.0, 10.5 * DT
    for k in range(30):
        t = k * DT
        d = max(t - t_kick, 0.0) * speed
        seen = 0.0 if k <= 10 else speed / 3 if k == 11 else speed
        auto.observe(WorldState(t, BallState(bx + d * hx, by + d * hy, seen * hx, seen * hy), (blue, yellow), k))
    assert auto.referee.watch.last_touch == ("yellow", 4)


@pytest.mark.parametrize("seen_beyond", [False, True])
def test_a_ball_track_coasting_unseen_past_the_wall_is_no_boundary_crossing(seen_beyond: bool) -> None:
    """A ball blue kicked rolls over the touch line at 2.3 m/s to the boundary wall, where no camera sees
    it any more and its track coasts on through the wall (recorded at seed 6, 20.35-20.55 s: the
    autoref called a boundary crossing the truth referee did not): a ball out, no boundary crossing.
    The same track seen past the wall is one."""
    auto = AutoRef(scene()[0].field, [("blue", 5), ("yellow", 4)], RefereeParams())
    auto.referee.give(RefereeCommand.NORMAL)
    f = auto.crossing.field
    blue = RobotState("blue", 5, -1.0, 0.0, 0.0)
    yellow = RobotState("yellow", 4, 1.0, 0.0, 0.0)
    kinds = []
    x0, y0 = -2.0, f.half_width - 0.3
    for k in range(40):
        t = k * DT
        ball = BallState(x0, y0 + 2.3 * t, 0.0, 2.3)
        if k == 0:  # blue at the ball: its touch
            auto.observe(WorldState(t, dataclasses.replace(ball, vy=0.0),
                                    (dataclasses.replace(blue, x=x0, y=y0 - FRONT, theta=math.pi / 2),
                                     yellow), k))
            continue
        seen = seen_beyond or ball.y + R_BALL <= f.boundary_half_width
        auto.observe(WorldState(t, dataclasses.replace(ball, visible=seen), (blue, yellow), k))
        kinds += [(c.kind, c.team) for c in auto.calls]
    assert auto.referee.watch.last_touch == ("blue", 5)
    assert ("ball_out", "blue") in kinds
    assert (("boundary_crossing", "blue") in kinds) == seen_beyond


@pytest.mark.parametrize("seen_in", [False, True])
def test_a_ball_track_coasting_unseen_past_the_goal_line_is_no_goal(seen_in: bool) -> None:
    """A ball blue kicked rolls at 2.25 m/s onto the +x goal's post and back (recorded in grSim: camera
    0's frame passed over, the track coasted on to 2 cm past the line, 1 cm inside the post, and the
    autoref called the goal 0.27 s before the ball went in): no goal on a track no camera shows. The same
    ball seen past the line is a goal."""
    auto = AutoRef(scene()[0].field, [("blue", 5), ("yellow", 4)], RefereeParams())
    auto.referee.give(RefereeCommand.NORMAL)
    f = auto.crossing.field
    blue = RobotState("blue", 5, -1.0, 2.0, 0.0)
    yellow = RobotState("yellow", 4, 1.0, 2.0, 0.0)
    y = f.dims.goal_width_m / 2.0 - 0.01
    line = f.half_length + R_BALL
    kinds = []
    xs = [line - 0.3 + 0.0375 * k for k in range(11)]  # to 0.11 m past the line, 2.25 m/s
    for k, x in enumerate(xs):
        past = x > line
        auto.observe(WorldState(k * DT, BallState(x, y, 2.25, 0.0, visible=seen_in or not past), (blue, yellow), k))
        kinds += [c.kind for c in auto.calls]
    # off the post, seen back on the field
    for j in range(1, 6):
        k = len(xs) + j
        auto.observe(WorldState(k * DT, BallState(line - 0.02 * j, y, -0.5, 0.0), (blue, yellow), k))
        kinds += [c.kind for c in auto.calls]
    assert ("goal" in kinds) == seen_in


# a recorded penalty (``cmdragons bench autoref``, seed 9, 27.10-27.48 s, the autoref's tracked frames): blue
# dribbled the ball from the mark to (2.90, 0.00) and left it at rest; blue 2's front reaches it and the ball's
# track moves back 4 mm (vision's blob pulled toward the robot's), at 0.06 and 0.13 m/s away from the goal,
# before the kick scores (the truth referee: the goal at 27.47 s; the autoref called the penalty over at
# 27.13 s and then no goal). Per frame: t, ball (x, y, vx, vy), blue 2 and the yellow keeper (x, y, theta).
PENALTY = (
    (27.1000, (2.9027, -0.0042, 0.004, -0.042), (2.7732, -0.0362, 0.193), (4.3508, -0.0004, 3.138)),
    (27.1167, (2.9027, -0.0043, 0.000, 0.020), (2.7815, -0.0348, 0.192), (4.3509, -0.0008, 3.139)),
    (27.1333, (2.9019, -0.0047, -0.056, -0.034), (2.7898, -0.0327, 0.182), (4.3510, -0.0007, 3.136)),
    (27.1500, (2.8990, -0.0051, -0.126, -0.009), (2.7977, -0.0305, 0.181), (4.3507, -0.0005, 3.136)),
    (27.1667, (2.9001, -0.0050, 0.053, 0.002), (2.8060, -0.0288, 0.183), (4.3508, -0.0008, 3.135)),
    (27.1833, (2.9703, 0.0091, 0.003, 0.000), (2.8136, -0.0266, 0.184), (4.3508, -0.0004, 3.137)),
    (27.2000, (3.0703, 0.0277, 5.998, 1.117), (2.8220, -0.0244, 0.191), (4.3507, -0.0003, 3.138)),
    (27.2167, (3.1695, 0.0463, 5.934, 1.112), (2.8299, -0.0230, 0.194), (4.3508, -0.0006, 3.138)),
    (27.2333, (3.2680, 0.0647, 5.886, 1.100), (2.8380, -0.0212, 0.187), (4.3508, 0.0004, -3.134)),
    (27.2500, (3.3657, 0.0830, 5.837, 1.094), (2.8469, -0.0194, 0.180), (4.3504, 0.0017, -3.123)),
    (27.2667, (3.4623, 0.1013, 5.778, 1.090), (2.8563, -0.0167, 0.167), (4.3497, 0.0035, -3.107)),
    (27.2833, (3.5583, 0.1195, 5.730, 1.082), (2.8664, -0.0146, 0.130), (4.3499, 0.0062, -3.089)),
    (27.3000, (3.6534, 0.1374, 5.682, 1.071), (2.8777, -0.0122, 0.069), (4.3497, 0.0107, -3.073)),
    (27.3167, (3.7478, 0.1551, 5.638, 1.059), (2.8895, -0.0097, 0.003), (4.3495, 0.0154, -3.052)),
    (27.3333, (3.8412, 0.1728, 5.583, 1.054), (2.9018, -0.0070, -0.074), (4.3498, 0.0207, -3.038)),
    (27.3500, (3.9339, 0.1904, 5.535, 1.048), (2.9154, -0.0043, -0.146), (4.3499, 0.0273, -3.029)),
    (27.3667, (4.0257, 0.2075, 5.485, 1.031), (2.9298, -0.0012, -0.215), (4.3498, 0.0340, -3.022)),
    (27.3833, (4.1169, 0.2247, 5.443, 1.024), (2.9444, 0.0024, -0.278), (4.3500, 0.0417, -3.024)),
    (27.4000, (4.2072, 0.2417, 5.391, 1.015), (2.9610, 0.0063, -0.345), (4.3499, 0.0510, -3.015)),
    (27.4167, (4.2965, 0.2585, 5.339, 1.005), (2.9776, 0.0098, -0.425), (4.3500, 0.0601, -3.013)),
    (27.4333, (4.3852, 0.2751, 5.293, 0.992), (2.9950, 0.0142, -0.520), (4.3502, 0.0712, -3.006)),
    (27.4500, (4.4724, 0.2916, 5.225, 0.985), (3.0130, 0.0195, -0.631), (4.3505, 0.0825, -3.002)),
    (27.4667, (4.5596, 0.3080, 5.191, 0.977), (3.0318, 0.0247, -0.761), (4.3503, 0.0918, -2.995)),
    (27.4833, (4.6459, 0.3243, 5.151, 0.972), (3.0492, 0.0303, -0.904), (4.3503, 0.1020, -2.997)),
)


@pytest.mark.parametrize("back_m_s", [None, 0.5])
def test_a_penalty_ball_at_rest_whose_track_moves_as_the_kicker_reaches_it_is_still_the_kickers(
        back_m_s: float | None) -> None:
    """Blue's penalty, the ball dribbled forward and at rest, then the recorded frames (:data:`PENALTY`):
    the track's 0.13 m/s back as blue 2's front reaches the ball is no ball turned back, the kick goes on
    and scores (the goal for blue, as the truth referee called it). The same ball instead rolling back
    from the goal at 0.5 m/s (a keeper's save, well over the tracks' noise) ends the kick."""
    params = RefereeParams()
    params = dataclasses.replace(params, figures=dataclasses.replace(params.figures, prepare_timeout_s=0.5))
    auto = AutoRef(scene()[0].field, [("blue", 2), ("yellow", 0)], params)
    r = auto.referee
    r.start_penalty("blue")
    pen = r.game.penalty
    assert pen is not None
    t0, _, kicker, keeper = PENALTY[0]
    at_rest = (2.9027, -0.0042, 0.0, 0.0)
    calls: list[GameEvent] = []

    def see(k: int, t: float, ball: tuple[float, ...], blue: tuple[float, ...], yellow: tuple[float, ...]) -> None:
        auto.observe(WorldState(t, BallState(*ball), (RobotState("blue", 2, *blue), RobotState("yellow", 0, *yellow)),
                                k))
        calls.extend(auto.calls)

    frames = round(3.0 / DT)
    for k in range(frames):  # prepared on the mark, run, then the ball dribbled forward and left at rest
        t = t0 - 3.0 + k * DT
        on_mark = k < frames // 2
        ball = (*pen.mark, 0.0, 0.0) if on_mark else at_rest
        blue = (pen.mark[0] - 0.3, 0.0, 0.0) if on_mark else kicker
        see(k, t, ball, blue, keeper)
    assert r.game.command == RefereeCommand.PENALTY and r.game.ready
    recorded = PENALTY if back_m_s is None else PENALTY[:5]
    for k, (t, ball, blue, yellow) in enumerate(recorded, start=frames):
        see(k, t, ball, blue, yellow)
    if back_m_s is not None:  # turned back from where it lay
        for j in range(1, 10):
            t = PENALTY[4][0] + j * DT
            see(frames + 4 + j, t, (at_rest[0] - back_m_s * j * DT, at_rest[1], -back_m_s, 0.0), PENALTY[4][2],
                PENALTY[4][3])
    kinds = [(c.kind, c.team) for c in calls]
    assert (("penalty_over", "blue") in kinds) == (back_m_s is not None), kinds
    assert (("goal", "blue") in kinds) == (back_m_s is None), kinds


# a recorded kick out of sight (``cmdragons bench autoref``, seed 6, 44.30-44.47 s, the autoref's tracked
# frames): blue 3 kicks the ball at 5.3 m/s along its heading into yellow 2's side 7 cm away, off which it
# leaves to -y; no camera shows the ball in the two frames between (the truth referee: yellow touched it last,
# the ball out at 44.62 s blue's free kick; the autoref gave it to yellow). Per frame: t, ball (x, y, vx, vy,
# seen), blue 3 and yellow 2 (x, y, theta).
TURNED_UNSEEN = (
    (44.3000, (1.4908, -2.3106, 0.344, -0.203, True), (1.3914, -2.4064, 0.784), (1.5890, -2.1559, 2.483)),
    (44.3167, (1.4957, -2.3153, 0.296, -0.275, True), (1.4036, -2.4030, 0.781), (1.5940, -2.1634, 2.482)),
    (44.3333, (1.5012, -2.3191, 0.322, -0.233, True), (1.4164, -2.3986, 0.777), (1.5999, -2.1705, 2.477)),
    (44.3500, (1.5063, -2.3236, 0.289, -0.247, True), (1.4297, -2.3946, 0.782), (1.6063, -2.1768, 2.468)),
    (44.3667, (1.5072, -2.3257, 0.769, 0.249, False), (1.4426, -2.3904, 0.787), (1.6136, -2.1828, 2.447)),
    (44.3833, (1.5200, -2.3213, 0.773, 0.265, False), (1.4554, -2.3861, 0.787), (1.6218, -2.1874, 2.400)),
    (44.4000, (1.5995, -2.3778, 3.706, -2.426, True), (1.4684, -2.3819, 0.786), (1.6297, -2.1912, 2.339)),
    (44.4167, (1.6164, -2.4379, 1.018, -3.601, True), (1.4802, -2.3776, 0.786), (1.6372, -2.1948, 2.299)),
    (44.4333, (1.6331, -2.4947, 0.988, -3.338, True), (1.4904, -2.3738, 0.801), (1.6462, -2.1981, 2.268)),
    (44.4500, (1.6496, -2.5506, 0.981, -3.326, True), (1.4998, -2.3707, 0.801), (1.6553, -2.2017, 2.230)),
    (44.4667, (1.6658, -2.6058, 0.969, -3.282, True), (1.5092, -2.3689, 0.809), (1.6629, -2.2058, 2.194)),
)


@pytest.mark.parametrize(("aside_m", "last"), [(0.0, ("yellow", 2)), (0.35, ("blue", 3))])
def test_a_kick_out_of_sight_turned_by_the_robot_on_the_kickers_heading_was_touched_last_by_it(
        aside_m: float, last: tuple[str, int]) -> None:
    """The recorded frames (:data:`TURNED_UNSEEN`), blue 3 at the ball before them: the ball reappears
    moving 79 degrees off blue 3's heading, and yellow 2's body lies on that heading within what the ball
    could roll unseen, the reappeared ball moving away from where it met it: yellow 2 turned it and
    touched it last (the frame after, the track's velocity settling from the tracker's blend, is no new
    touch by blue 3 the ball passes). With yellow 2 moved ``aside_m`` off that heading nobody turned it:
    blue 3's kick stays the last touch."""
    auto = AutoRef(scene()[0].field, [("blue", 3), ("yellow", 2)], RefereeParams())
    auto.referee.give(RefereeCommand.NORMAL)
    t0, *first = TURNED_UNSEEN[0]
    held = tuple((t0 - 0.2 + k * DT, *first) for k in range(12))
    dx, dy = aside_m * math.sin(0.784), -aside_m * math.cos(0.784)  # square to blue 3's heading
    for k, (t, ball, blue, yellow) in enumerate((*held, *TURNED_UNSEEN)):
        x, y, vx, vy, seen = ball
        auto.observe(WorldState(t, BallState(x, y, vx, vy, seen),
                                (RobotState("blue", 3, *blue),
                                 RobotState("yellow", 2, yellow[0] + dx, yellow[1] + dy, yellow[2])), k))
    assert auto.referee.watch.last_touch == last


def test_the_other_teams_touch_before_a_kickoff_does_not_make_it_the_kickoffs_taker() -> None:
    """Blue 5 touches the ball, then yellow's kickoff: the ball is put on the centre spot, and the
    track seen moving off it (a vision track catching up with the teleported ball, the ER-Force
    simulator's second half) gives the normal start. Blue 5, last to touch the ball before the
    kickoff, did not take it: its next touch is no double touch (it was called)."""
    auto = AutoRef(scene()[0].field, [("blue", 5), ("yellow", 4)], RefereeParams())
    auto.referee.give(RefereeCommand.NORMAL)
    yellow = RobotState("yellow", 4, -3.0, -2.0, 0.0)
    k, calls = 0, []

    def see(ball: tuple[float, float], blue: tuple[float, float]) -> None:
        nonlocal k
        auto.observe(WorldState(k * DT, BallState(*ball, 0.0, 0.0), (RobotState("blue", 5, *blue, 0.0), yellow), k))
        calls.extend(auto.calls)
        k += 1

    for _ in range(12):  # blue 5 at the ball, then off
        see((1.0 + FRONT, 0.5), (1.0, 0.5))
    for _ in range(12):
        see((1.0 + FRONT, 0.5), (0.0, 1.5))
    assert auto.referee.watch.last_touch == ("blue", 5)
    auto.referee.kickoff_setup("yellow")
    for _ in range(12):
        see((0.0, 0.0), (-1.0, 1.5))
    see((0.3, 0.0), (-1.0, 1.5))  # seen moving off the spot: the kickoff taken
    assert auto.referee.game.command == RefereeCommand.NORMAL
    for _ in range(6):
        see((0.0, 0.0), (-1.0, 1.5))
    for _ in range(30):  # blue 5 plays the ball
        see((0.0, 0.0), (-FRONT, 0.0))
    assert not [e for e in calls if e.kind == "double_touch"], calls
