"""Physics against known values: kicks, the two-phase ball, motor limits, walls, goals, contacts."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from cmdragons.control.motion import relative_kick
from cmdragons.geometry import LeagueParams
from cmdragons.messages import RefereeCommand, RobotCommand
from sim.referee import Referee
from sim.referee_params import RefereeParams
from sim.rules import RulesParams
from sim.world import (
    BallOut,
    BallParams,
    Contact,
    DribblerParams,
    Goal,
    Kick,
    KickerParams,
    PhysicsParams,
    RobotParams,
    World,
)

LEAGUE = LeagueParams()
FRONT = LEAGUE.robot.front_distance_m + LEAGUE.ball.radius_m


def make_world(blue: int = 1, yellow: int = 0, robot: RobotParams | None = None) -> World:
    w = World(LEAGUE, PhysicsParams(), robot or RobotParams(), BallParams(), KickerParams(), DribblerParams(),
              robots_per_team={"blue": blue, "yellow": yellow})
    for i, (team, rid) in enumerate(w.robot_keys()):
        w.place_robot(team, rid, -3.5 + 1.0 * i, -2.5, 0.0)  # parked apart, out of the way
    w.place_ball(0.0, 1.5)
    return w


def run(w: World, seconds: float, commands: list[RobotCommand] | None = None) -> list[object]:
    events: list[object] = []
    for _ in range(round(seconds * 60)):
        events += w.step_frame(commands or [])
    return events


def ball_speed(w: World) -> float:
    return float(w.ball_body.velocity.length)


@pytest.mark.parametrize("kick", [2.0, 4.0, 6.5])
def test_kick_speed(kick: float) -> None:
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(FRONT + 0.01, 0.0)
    speeds = []
    kicked = None
    before = after = 0.0  # the robot's speed before and after the frame of the kick
    for _ in range(60):
        before = next(r.vx for r in w.ground_truth().robots if (r.team, r.id) == ("blue", 0))
        events = w.step_frame([RobotCommand("blue", 0, vx=0.3, kick_speed=kick)])
        kicked = kicked or next((e for e in events if isinstance(e, Kick)), None)
        if kicked:
            speeds.append(ball_speed(w))
            after = next(r.vx for r in w.ground_truth().robots if (r.team, r.id) == ("blue", 0))
            break
    assert kicked is not None and kicked.speed_m_s == kick
    assert 0.0 < before <= after <= 0.3
    # the kick is relative to the robot: the kick speed plus the robot's own (within a frame's
    # acceleration), less at most one frame of sliding friction, along its heading
    assert kick + before - BallParams().acc_slide_m_s2 / 60 - 1e-6 <= speeds[0] <= kick + after + 1e-6
    assert abs(w.ball_body.velocity.y) < 1e-6


def test_kick_is_clamped_to_the_kicker_limit() -> None:
    w = make_world()
    cmd = w.sanitize(RobotCommand("blue", 0, kick_speed=20.0))
    assert cmd is not None and cmd.kick_speed == KickerParams().max_speed_m_s
    assert w.faults.clamped == 1


def model_distance(v0: float, p: BallParams) -> float:
    vs = p.slide_to_roll_fraction * v0
    return (v0**2 - vs**2) / (2 * p.acc_slide_m_s2) + vs**2 / (2 * p.acc_roll_m_s2)


@pytest.mark.parametrize("v0", [0.5, 1.5, 3.0])
def test_rolling_distance_matches_two_phase_model(v0: float) -> None:
    w = make_world(blue=0)
    w.place_ball(-3.0, 0.0, vx=v0)
    run(w, 12.0)
    assert ball_speed(w) == 0.0
    travelled = w.ball_body.position.x + 3.0
    assert travelled == pytest.approx(model_distance(v0, BallParams()), rel=0.05)


def test_robots_never_exceed_their_limits() -> None:
    p = RobotParams()
    w = make_world(blue=3, yellow=3, robot=p)
    for i, (team, rid) in enumerate(w.robot_keys()):
        w.place_robot(team, rid, -3.0 + 1.2 * i, 0.0, 0.0)
    rng = np.random.default_rng(7)
    prev = None
    dt = 1.0 / 60
    worst_acc = worst_speed = worst_omega = 0.0
    for k in range(600):
        cmds = []
        for team, rid in w.robot_keys():
            # wild commands, including far out of limits; robots keep apart (each in its lane)
            vx, vy = rng.normal(0, 4, size=2) if k % 30 < 20 else (0.0, 0.0)
            cmds.append(RobotCommand(team, rid, vx * 0.1, vy, rng.normal(0, 30)))
        w.step_frame(cmds)
        snap = w.snapshot().robots
        vel = snap[:, 5:7]
        worst_speed = max(worst_speed, float(np.max(np.hypot(vel[:, 0], vel[:, 1]))))
        worst_omega = max(worst_omega, float(np.max(np.abs(snap[:, 7]))))
        if prev is not None:
            worst_acc = max(worst_acc, float(np.max(np.hypot(*(vel - prev).T))) / dt)
        prev = vel.copy()
        # keep them inside their lanes
        for i, (team, rid) in enumerate(w.robot_keys()):
            x, y = snap[i, 2], snap[i, 3]
            if abs(y) > 2.0 or abs(x - (-3.0 + 1.2 * i)) > 0.45:
                w.place_robot(team, rid, -3.0 + 1.2 * i, 0.0, snap[i, 4])
                prev = None
    assert worst_speed <= p.max_speed_m_s * 1.001
    assert worst_omega <= p.max_omega_rad_s * 1.001
    assert worst_acc <= p.max_brake_m_s2 * 1.02
    assert w.faults.clamped > 0


def test_acceleration_and_braking_limits() -> None:
    p = RobotParams()
    w = make_world(robot=p)
    w.place_robot("blue", 0, -3.0, 0.0, 0.0)
    speeds = []
    for _ in range(120):  # 2 s at full speed forward
        w.step_frame([RobotCommand("blue", 0, vx=p.max_speed_m_s)])
        speeds.append(w.snapshot().robots[0, 5])
    # reaches 3 m/s after 1 s (+ latency) accelerating at 3 m/s^2
    t_reach = next(i for i, s in enumerate(speeds) if s >= p.max_speed_m_s - 1e-6) / 60
    assert t_reach == pytest.approx(p.max_speed_m_s / p.max_accel_m_s2 + p.command_latency_s, abs=2 / 60)
    stop = []
    for _ in range(60):
        w.step_frame([RobotCommand("blue", 0)])
        stop.append(w.snapshot().robots[0, 5])
    t_stop = next(i for i, s in enumerate(stop) if s <= 1e-6) / 60
    assert t_stop == pytest.approx(p.max_speed_m_s / p.max_brake_m_s2 + p.command_latency_s, abs=2 / 60)


def test_command_latency() -> None:
    p = RobotParams(command_latency_s=0.1)
    w = make_world(robot=p)
    moved_at = None
    for k in range(30):
        w.step_frame([RobotCommand("blue", 0, vx=1.0)] if k == 0 else [RobotCommand("blue", 0, vx=1.0)])
        if moved_at is None and w.snapshot().robots[0, 5] > 1e-6:
            moved_at = w.t
    assert moved_at is not None and 0.1 <= moved_at <= 0.1 + 2 / 60


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_commands_brake_and_are_counted(bad: float) -> None:
    w = make_world()
    run(w, 1.0, [RobotCommand("blue", 0, vx=1.0)])
    assert w.snapshot().robots[0, 5] == pytest.approx(1.0)
    run(w, 1.0, [RobotCommand("blue", 0, vx=bad, vy=0.5)])
    assert abs(w.snapshot().robots[0, 5]) < 1e-9 and abs(w.snapshot().robots[0, 6]) < 1e-9
    assert w.faults.non_finite == 60
    run(w, 0.1, [RobotCommand("yellow", 9, vx=1.0)])
    assert w.faults.unknown_robot == 6


def test_robot_without_commands_brakes_after_timeout() -> None:
    w = make_world()
    run(w, 1.0, [RobotCommand("blue", 0, vx=1.0)])
    run(w, 1.0)
    assert w.snapshot().robots[0, 5] == 0.0
    assert w.faults.timed_out == 1


def test_ball_kicked_into_a_wall_comes_back() -> None:
    w = make_world(blue=0)
    w.place_ball(0.0, 2.0, vx=0.0, vy=3.0)
    run(w, 1.0)
    vy = w.ball_body.velocity.y
    assert vy < 0.0  # bounced off the boundary wall at y = 3.3
    assert w.ball_body.position.y < LEAGUE.dims.width_m / 2 + LEAGUE.dims.boundary_width_m


def judge(ref: Referee, w: World, events: list[Any]) -> None:
    """The referee observes a frame; the world carries out its teleport (as the simulator does)."""
    teleport = ref.observe(w.t, events, tuple(w.ball_body.position))
    if teleport is not None:
        w.apply(teleport)


def test_goal_counted_and_kickoff_restart() -> None:
    w = make_world(blue=1, yellow=1)
    ref = Referee(w.field, w.robot_keys(), RefereeParams(rules="basic"))
    w.place_ball(3.5, 0.1, vx=4.0)
    events = []
    for _ in range(120):
        ev = w.step_frame()
        judge(ref, w, ev)
        events += ev
    goals = [e for e in events if isinstance(e, Goal)]
    assert len(goals) == 1 and goals[0].scoring_team == "blue"  # blue attacks the goal at +x
    assert ref.score == {"blue": 1, "yellow": 0}
    # after the restart delay: ball on the centre spot, yellow kicks off
    assert tuple(w.ball_body.position) == pytest.approx((0.0, 0.0))
    assert ref.game.command == RefereeCommand.KICKOFF and ref.game.for_team == "yellow"


def test_ball_out_gives_a_free_kick_at_a_legal_spot() -> None:
    w = make_world(blue=1, yellow=1)
    ref = Referee(w.field, w.robot_keys(), RefereeParams(rules="basic"))
    w.place_robot("yellow", 0, 1.0, 2.0, math.pi / 2)
    w.place_ball(1.0, 2.0 + FRONT + 0.005)
    events = []
    for k in range(120):
        ev = w.step_frame([RobotCommand("yellow", 0, vy=0.3, kick_speed=3.0)] if k < 10 else [])
        judge(ref, w, ev)
        events += ev
    outs = [e for e in events if isinstance(e, BallOut)]
    assert len(outs) == 1 and outs[0].last_touch == "yellow"
    x, y = w.ball_body.position
    assert (x, y) == pytest.approx((1.0, 3.0 - 0.2), abs=1e-6)
    assert ref.game.command == RefereeCommand.FREE_KICK and ref.game.for_team == "blue"


def test_ball_held_in_a_defense_area_gives_the_other_team_a_free_kick() -> None:
    w = make_world(blue=1, yellow=1)
    ref = Referee(w.field, w.robot_keys(), RefereeParams(rules="basic", keeper_held_ball_s=2.0, restart_delay_s=0.5))
    ref.give(RefereeCommand.NORMAL)
    w.place_ball(4.2, 0.3)  # at rest in the defense area at +x: yellow defends it
    for _ in range(round(1.9 * 60)):
        judge(ref, w, w.step_frame())
    assert ref.game.command == RefereeCommand.NORMAL  # not yet
    for _ in range(round(0.7 * 60)):
        judge(ref, w, w.step_frame())
    assert ref.keeper_held_ball == 1
    assert ref.game.command == RefereeCommand.FREE_KICK and ref.game.for_team == "blue"
    x, y = w.ball_body.position
    assert w.field.in_defense_area(x, y, margin=0.2 - 1e-6) == 0  # placed outside the area, at the rules' distance
    assert math.hypot(x - 4.2, y - 0.3) < 1.0


def test_robot_contacts_are_reported() -> None:
    w = make_world(blue=1, yellow=1)
    w.place_robot("blue", 0, -1.0, 0.0, 0.0)
    w.place_robot("yellow", 0, 1.0, 0.0, math.pi)
    events = run(w, 1.5, [RobotCommand("blue", 0, vx=2.0), RobotCommand("yellow", 0, vx=-2.0)])
    events += run(w, 1.0, [RobotCommand("blue", 0, vx=-1.0), RobotCommand("yellow", 0, vx=1.0)])
    contacts = [e for e in events if isinstance(e, Contact)]
    assert len(contacts) >= 1
    c = contacts[0]
    assert {c.a, c.b} == {("blue", 0), ("yellow", 0)}
    assert c.relative_speed_m_s == pytest.approx(4.0, rel=0.1)
    assert c.duration_s > 0.0 and c.max_depth_m >= 0.0


def test_contacts_ending_in_one_step_come_in_the_order_of_their_robots() -> None:
    # six blue-yellow pairs in contact, all parted at once: the frame's contacts by pair, not in the
    # order of the physics library's arbiter hash (the shapes' addresses, which differ between runs)
    n = 6
    w = make_world(blue=n, yellow=n)
    gap = 2 * LEAGUE.robot.radius_m + 0.05  # driven into each other
    for i in range(n):
        w.place_robot("blue", i, -2.5 + 1.0 * i, 0.0, 0.0)
        w.place_robot("yellow", n - 1 - i, -2.5 + 1.0 * i + gap, 0.0, math.pi)
    pushing = [RobotCommand(team, i, vx=0.5 * sign) for team, sign in (("blue", 1), ("yellow", -1)) for i in range(n)]
    run(w, 0.5, pushing)
    assert len(w.open_contacts()) == n
    for i in range(n):
        w.place_robot("blue", i, -2.5 + 1.0 * i, 2.0, 0.0)
        w.place_robot("yellow", n - 1 - i, -2.5 + 1.0 * i, -2.0, math.pi)
    ended = [e for e in w.step_frame([]) if isinstance(e, Contact)]
    assert len(ended) == n
    assert [(c.a, c.b) for c in ended] == sorted((c.a, c.b) for c in ended)


def test_a_contact_between_team_mates_names_the_opponent_pushing_one_into_the_other() -> None:
    # blue 0 and 1 stand side by side, 2 cm apart; yellow drives into blue 0 from behind at 1 m/s
    w = make_world(blue=2, yellow=1)
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_robot("blue", 1, 2 * LEAGUE.robot.radius_m + 0.02, 0.0, 0.0)
    w.place_robot("yellow", 0, -1.0, 0.0, 0.0)
    events = run(w, 1.5, [RobotCommand("yellow", 0, vx=1.0)]) + w.open_contacts()
    own = [e for e in events if isinstance(e, Contact) and e.a[0] == e.b[0] == "blue"]
    assert own and all(c.pushed_by == ("yellow", 0) for c in own)
    # the same two driven into each other by themselves: nobody pushed
    w = make_world(blue=2, yellow=1)
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_robot("blue", 1, 0.5, 0.0, math.pi)
    w.place_robot("yellow", 0, -2.0, 2.0, 0.0)
    events = run(w, 1.0, [RobotCommand("blue", 0, vx=1.0), RobotCommand("blue", 1, vx=-1.0)]) + w.open_contacts()
    own = [e for e in events if isinstance(e, Contact) and e.a[0] == e.b[0] == "blue"]
    assert own and all(c.pushed_by is None for c in own)


def test_dribbler_holds_the_ball_while_turning() -> None:
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(FRONT + 0.003, 0.0)
    run(w, 0.2, [RobotCommand("blue", 0, dribbler=1.0)])
    assert w.holding("blue", 0)
    run(w, 1.0, [RobotCommand("blue", 0, vx=0.5, omega=1.0, dribbler=1.0)])
    r = w.snapshot().robots[0]
    rel = np.array(w.ball_body.position) - r[2:4]
    heading = np.array([math.cos(r[4]), math.sin(r[4])])
    assert np.linalg.norm(rel) == pytest.approx(FRONT, abs=0.01)
    assert rel @ heading / np.linalg.norm(rel) > 0.95
    run(w, 0.2, [RobotCommand("blue", 0)])
    assert not w.holding("blue", 0)


def test_chip_flies_over_robots() -> None:
    w = make_world(blue=2)
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_robot("blue", 1, 0.6, 0.0, 0.0)  # in the way of a flat kick
    w.place_ball(FRONT + 0.005, 0.0)
    heights = []
    for _ in range(90):
        w.step_frame([RobotCommand("blue", 0, kick_speed=4.0, chip=True)])
        heights.append(w.snapshot().ball[2])
    assert max(heights) > LEAGUE.robot.height_m + 0.1
    assert w.ball_body.position.x > 1.0  # passed robot 1
    assert heights[-1] == pytest.approx(LEAGUE.ball.radius_m)


def test_same_seedless_physics_is_deterministic() -> None:
    def trace() -> np.ndarray:
        w = make_world(blue=3, yellow=3)
        w.place_ball(0.0, 0.0, 2.0, 1.0)
        for k in range(120):
            w.step_frame([RobotCommand(t, i, math.sin(k / 10 + i), math.cos(k / 7), 1.0) for t, i in w.robot_keys()])
        s = w.snapshot()
        return np.concatenate([s.ball, s.robots.ravel()])

    assert np.array_equal(trace(), trace())


def test_kick_keeps_part_of_the_velocity_across_the_heading() -> None:
    # a ball rolling across the robot's mouth leaves along heading * kick + retention * across
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(FRONT + 0.002, -0.04, vy=1.0)
    before = None
    for _ in range(10):
        vy_before = w.ball_body.velocity.y
        events = w.step_frame([RobotCommand("blue", 0, kick_speed=4.0)])
        if any(isinstance(e, Kick) for e in events):
            before = vy_before
            break
    assert before is not None
    retention = KickerParams().tangential_retention
    vx, vy = w.ball_body.velocity
    assert vx == pytest.approx(4.0, abs=0.1)
    assert vy == pytest.approx(retention * before, abs=0.05)


@pytest.mark.parametrize(("drive", "heading"), [(1.0, 0.0), (0.6, 0.8)])
def test_a_kick_asked_over_the_ground_leaves_at_that_speed_from_a_moving_robot(drive: float, heading: float) -> None:
    """The team asks the ball's speed over the ground; sent relative to the robot (its forward speed
    taken off), a kick from a robot driving onto the ball leaves at the speed asked, under the rules'
    6.5 m/s, where the speed asked sent as it is would go over it."""
    asked = 6.0
    for relative in (True, False):
        w = make_world()
        c, s = math.cos(heading), math.sin(heading)
        w.place_robot("blue", 0, 0.0, 0.0, heading)
        w.place_ball(0.6 * c, 0.6 * s)
        speed = None
        for _ in range(120):
            cmd = RobotCommand("blue", 0, vx=drive * c, vy=drive * s, kick_speed=asked)
            if relative:
                truth = next(r for r in w.ground_truth().robots if r.id == 0)
                cmd = relative_kick(cmd, heading, (truth.vx, truth.vy), LEAGUE.robot)
                assert cmd.kick_speed == pytest.approx(asked - drive, abs=1e-3)  # not faster than commanded
            if any(isinstance(e, Kick) for e in w.step_frame([cmd])):
                speed = ball_speed(w)
                break
        assert speed is not None
        robot = next(r for r in w.ground_truth().robots if r.id == 0)
        assert math.hypot(robot.vx, robot.vy) == pytest.approx(drive, abs=0.05)  # at its speed when it kicked
        if relative:
            assert speed == pytest.approx(asked, abs=0.1) and speed < 6.5
        else:
            assert speed == pytest.approx(asked + drive, abs=0.1) and speed > 6.5


def kick_from_a_robot_told_to_stop(asked: float, drive: float, stop_gap_m: float) -> tuple[float, float, float]:
    """Blue 0 drives along +x at ``drive`` m/s toward the ball, its kicker armed at ``asked`` m/s over
    the ground; once the ball is ``stop_gap_m`` ahead of its front, its command turns to a stop (as the
    safety search may zero it) with the kick still armed, each kick sent relative to the robot by
    ``relative_kick`` from the robot's true velocity (as tracked). Returns the ball's true speed the
    frame it was kicked, the robot's true forward speed then, and how long after the stop was sent
    the kicker fired (s)."""
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(0.6, 0.0)
    stop_t = None
    for _ in range(120):
        truth = next(r for r in w.ground_truth().robots if r.id == 0)
        gap = float(w.ball_body.position.x) - truth.x - FRONT
        if stop_t is None and gap <= stop_gap_m:
            stop_t = w.t
        cmd = relative_kick(RobotCommand("blue", 0, vx=drive if stop_t is None else 0.0, kick_speed=asked), 0.0,
                            (truth.vx, truth.vy), LEAGUE.robot)
        kicks = [e for e in w.step_frame([cmd]) if isinstance(e, Kick)]
        if kicks:
            robot = next(r for r in w.ground_truth().robots if r.id == 0)
            assert stop_t is not None
            return ball_speed(w), robot.vx, kicks[0].t - stop_t
    raise AssertionError("no kick")


def test_a_shot_from_a_robot_braking_onto_the_ball_never_leaves_faster_than_asked() -> None:
    """A robot at 1 m/s whose command was zeroed just before its kicker fires still moves at about
    1 m/s when it kicks: a shot at the fastest kick (field.yaml robot.max_kick_m_s) sent as if the
    robot stood (its command's velocity) left at 6.9 m/s, over the rules' 6.5; with the robot's own
    speed taken off it leaves at most at the speed asked (the ball's true speed, within the one frame
    of sliding, 3 m/s², it may have lost after the kick: 0.06 m/s), under the rules'."""
    asked = LEAGUE.robot.max_kick_m_s
    limit = RulesParams().ball_speed_limit_m_s
    speed, forward, after = kick_from_a_robot_told_to_stop(asked, drive=1.0, stop_gap_m=0.05)
    assert after >= RobotParams().command_latency_s  # the stop had reached the robot when it kicked ...
    assert forward > 0.8  # ... but its wheels had not stopped it
    assert speed <= asked + 0.06 < limit
    assert speed >= asked - 0.25  # and not much slower: the robot braked at most that much meanwhile


@pytest.mark.parametrize(("asked", "drive"), [(3.0, 0.0), (3.0, 1.0), (1.5, 0.5)])
def test_a_pass_from_a_steady_robot_leaves_at_the_speed_asked(asked: float, drive: float) -> None:
    """A pass from a robot standing or driving steadily onto the ball (its true velocity, as tracked,
    equal to its command's) leaves at the speed asked over the ground, within 0.1 m/s (one frame of
    sliding after the kick, 0.05 m/s, and the robot's speed as it meets the ball)."""
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(FRONT + 0.002 + 0.3 * drive, 0.0)
    speed = None
    for _ in range(120):
        truth = next(r for r in w.ground_truth().robots if r.id == 0)
        cmd = relative_kick(RobotCommand("blue", 0, vx=drive, kick_speed=asked), 0.0, (truth.vx, truth.vy),
                            LEAGUE.robot)
        if any(isinstance(e, Kick) for e in w.step_frame([cmd])):
            speed = ball_speed(w)
            break
    assert speed == pytest.approx(asked, abs=0.1)


@pytest.mark.parametrize("gain", [0.75, 1.2])
def test_a_kicker_off_its_gain_is_asked_that_much_more_and_the_ball_leaves_as_asked(gain: float) -> None:
    """A kicker whose ball leaves at ``gain`` of the kick sent (sim.yaml kicker.gain), and the team
    believing it (field.yaml robot.kick_gain, or as its tracker measured): the ball leaves at the
    speed asked over the ground; a team believing 1 sends it off at ``gain`` of it."""
    asked = 3.0
    for believed in (gain, 1.0):
        w = World(LEAGUE, PhysicsParams(), RobotParams(), BallParams(), KickerParams(gain=gain), DribblerParams(),
                  robots_per_team={"blue": 1, "yellow": 0})
        w.place_robot("blue", 0, 0.0, 0.0, 0.0)
        w.place_ball(FRONT + 0.002, 0.0)
        cmd = relative_kick(RobotCommand("blue", 0, kick_speed=asked), 0.0, (0.0, 0.0), LEAGUE.robot, believed)
        assert cmd.kick_speed == pytest.approx(asked / believed)
        for _ in range(6):
            kicks = [e for e in w.step_frame([cmd]) if isinstance(e, Kick)]
            if kicks:
                break
        assert kicks and kicks[0].speed_m_s == pytest.approx(asked * gain / believed, rel=1e-6)
        # the frame it was kicked in: sliding (3 m/s²) for a frame at most
        assert ball_speed(w) == pytest.approx(asked * gain / believed, abs=0.06)


def test_a_gain_never_makes_a_shot_sent_faster_than_the_robots_fastest_kick() -> None:
    robot = LEAGUE.robot
    shot = relative_kick(RobotCommand("blue", 0, kick_speed=6.0), 0.0, (0.0, 0.0), robot, 0.58)
    assert shot.kick_speed == robot.max_kick_m_s  # not 6 / 0.58 = 10.3: grSim's ball would leave at 8
    fast = relative_kick(RobotCommand("blue", 0, kick_speed=6.5), 0.0, (0.0, 0.0), robot, 0.58)
    assert fast.kick_speed == 6.5  # a kick asked faster still is not made slower by the cap


def test_the_kickers_speed_never_falls_below_its_slowest_and_a_chip_or_no_kick_is_sent_as_asked() -> None:
    robot = LEAGUE.robot
    assert robot.kicker_speed(2.0, 2.5) == robot.min_kick_m_s  # asked slower than the robot drives
    assert robot.kicker_speed(2.0, -1.0) == 3.0  # backing away: faster by as much
    assert robot.kicker_speed(0.0, 1.0) == 0.0  # no kick stays none
    chip = RobotCommand("blue", 0, vx=1.0, kick_speed=3.0, chip=True)
    assert relative_kick(chip, 0.0, (0.0, 0.0), robot) == chip
