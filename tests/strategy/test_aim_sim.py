"""A kick from a moving robot in the simulator: the kick is relative to the robot, so its velocity
carries over to the ball; a robot driving sideways while it shoots faces the heading that sends the
ball at the target (strategy.onetouch.kick_heading through strategy.skills.aiming)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from cmdragons.control.motion import relative_kick
from cmdragons.geometry import Field, wrap_angle
from cmdragons.messages import BallState, RobotCommand, RobotState
from cmdragons.runtime.settings import load_settings
from sim.world import Kick, World
from strategy.onetouch import kick_heading
from strategy.skills import drive_through, receive, turn_with_ball

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")
SHOT_M_S = 6.0
HEADING_GAIN = 0.3  # the scripted turn: this share of the heading error a frame
TOLERANCE_M = 0.05  # a one-touch shot crosses the goal line this near the goal centre (the goal is 1 m wide)


def one_robot_world() -> World:
    """Our simulator with one robot of ours, acting on its commands at once (the skill sees the
    truth of now)."""
    s = SETTINGS.sim
    return World(SETTINGS.field, s.physics, dataclasses.replace(s.robot, command_latency_s=0.0), s.ball, s.kicker,
                 s.dribbler, robots_per_team={"blue": 1, "yellow": 0})


@pytest.mark.parametrize("sideways_m_s", [1.0, -1.0, 0.0])
def test_a_robot_driving_sideways_shoots_at_the_goal_centre(sideways_m_s: float) -> None:
    """A robot carries the ball on its dribbler across the field at ``sideways_m_s`` (scripted, the
    heading toward the goal), then turns with it toward the goal centre (the team's skill; the turn
    scripted) while still driving sideways, and kicks: the ball crosses the goal line within
    ``skills.aim_tolerance_m`` of the goal centre, the skill's promise (a robot facing the goal centre
    at 1 m/s sideways would send it 0.5 m off)."""
    s, world = SETTINGS.sim, one_robot_world()
    skills, field = SETTINGS.strategy.skills, Field(SETTINGS.field)
    shape = SETTINGS.field.robot
    x0, y0 = field.half_length - 3.0, -0.6 * math.copysign(1.0, sideways_m_s)
    world.place_robot("blue", 0, x0, y0, 0.0)
    world.place_ball(x0 + skills.contact_m, y0)
    target = (field.half_length, 0.0)
    dt = 1.0 / s.physics.frame_rate_hz
    for _ in range(round(0.4 / dt)):  # up to speed sideways, the ball held
        world.step_frame([RobotCommand("blue", 0, vy=sideways_m_s, dribbler=1.0)])
    assert world.holding("blue", 0)
    kicked = None
    for _ in range(round(1.0 / dt)):
        truth = world.ground_truth()
        r, b = truth.robots[0], truth.ball
        robot = RobotState("blue", 0, r.x, r.y, r.theta, r.vx, r.vy, r.omega)
        assert abs(r.vy - sideways_m_s) < 0.1  # still driving sideways at the speed asked
        intent = turn_with_ball(robot, BallState(b.x, b.y, b.vx, b.vy), target, SHOT_M_S, skills)
        assert intent is not None, "the ball got away"
        omega = HEADING_GAIN * wrap_angle(intent.theta - r.theta) / dt
        cmd = RobotCommand("blue", 0, vy=sideways_m_s, omega=omega, kick_speed=intent.kick_speed,
                           dribbler=intent.dribbler)
        if any(isinstance(e, Kick) for e in world.step_frame([relative_kick(cmd, r.theta, (r.vx, r.vy), shape)])):
            kicked = world.ground_truth().ball
            break
    assert kicked is not None, "no kick"
    assert math.hypot(kicked.vx, kicked.vy) == pytest.approx(SHOT_M_S, abs=0.3)
    assert abs(goal_line_crossing(world, target[0]) - target[1]) < skills.aim_tolerance_m


def goal_line_crossing(world: World, goal_x: float) -> float:
    """Where the kicked ball crosses the line x = ``goal_x`` (m), within 3 s."""
    dt = 1.0 / SETTINGS.sim.physics.frame_rate_hz
    for _ in range(round(3.0 / dt)):
        before = world.ground_truth().ball
        world.step_frame([])
        after = world.ground_truth().ball
        if after.x >= goal_x:
            share = (goal_x - before.x) / (after.x - before.x)
            return before.y + share * (after.y - before.y)
    raise AssertionError("the ball did not reach the goal line")


@pytest.mark.parametrize("sideways_m_s", [1.0, -1.0, 0.0])
@pytest.mark.parametrize("incoming_deg", [150.0, 210.0])  # the pass comes from ahead, either side
def test_a_robot_driving_sideways_shoots_a_pass_one_touch_at_the_goal_centre(sideways_m_s: float,
                                                                             incoming_deg: float) -> None:
    """A pass rolls at 2 m/s to a robot driving sideways at ``sideways_m_s`` (scripted), which meets
    it one-touch (the team's skill sets the heading and arms the kicker; the turn scripted) with a
    6 m/s shot at the goal centre 3 m away: the ball crosses the goal line within ``TOLERANCE_M`` of
    it (aimed with the robot standing still in mind, 0.4 m off and more)."""
    s, world = SETTINGS.sim, one_robot_world()
    skills, field = SETTINGS.strategy.skills, Field(SETTINGS.field)
    target = (field.half_length, 0.0)
    meet_t, pass_m_s, dt = 0.4, 2.0, 1.0 / s.physics.frame_rate_hz
    u = (math.cos(math.radians(incoming_deg)), math.sin(math.radians(incoming_deg)))  # the ball's way
    # up to speed sideways first, facing about where it will (the ball away, at rest)
    world.place_robot("blue", 0, target[0] - 3.0, -sideways_m_s * (0.5 + meet_t), -0.1 * sideways_m_s)
    world.place_ball(0.0, 0.0)
    for _ in range(round(0.5 / dt)):
        world.step_frame([RobotCommand("blue", 0, vy=sideways_m_s)])
    r = world.ground_truth().robots[0]
    # where the ball meets the kicker face at meet_t, the robot then facing the heading that sends it at the target
    meet_robot = (r.x, r.y + sideways_m_s * meet_t)
    aim = math.atan2(target[1] - meet_robot[1], target[0] - meet_robot[0])
    h = kick_heading(aim, SHOT_M_S, (0.0, sideways_m_s), (pass_m_s * u[0], pass_m_s * u[1]),
                     s.kicker.tangential_retention)
    meet_ball = (meet_robot[0] + skills.contact_m * math.cos(h), meet_robot[1] + skills.contact_m * math.sin(h))
    # rolling (not sliding) from its start, arriving at pass_m_s
    roll = SETTINGS.field.ball.acc_roll_m_s2
    start_m_s = pass_m_s + roll * meet_t
    back = start_m_s * meet_t - 0.5 * roll * meet_t**2
    world.place_ball(meet_ball[0] - u[0] * back, meet_ball[1] - u[1] * back, start_m_s * u[0], start_m_s * u[1])
    world._start_slide(0.0)  # already rolling: keep the rolling deceleration  # noqa: SLF001
    kicked = None
    for _ in range(round(1.5 * meet_t / dt)):
        truth = world.ground_truth()
        r, b = truth.robots[0], truth.ball
        robot = RobotState("blue", 0, r.x, r.y, r.theta, r.vx, r.vy, r.omega)
        intent = receive(robot, BallState(b.x, b.y, b.vx, b.vy), meet_ball, skills, target, SHOT_M_S)
        omega = HEADING_GAIN * wrap_angle(intent.theta - r.theta) / dt
        cmd = RobotCommand("blue", 0, vy=sideways_m_s, omega=omega, kick_speed=intent.kick_speed,
                           dribbler=intent.dribbler)
        sent = relative_kick(cmd, r.theta, (r.vx, r.vy), SETTINGS.field.robot)
        if any(isinstance(e, Kick) for e in world.step_frame([sent])):
            kicked = world.ground_truth()
            break
    assert kicked is not None, "no kick"
    assert abs(kicked.robots[0].vy - sideways_m_s) < 0.1  # it kicked driving sideways at the speed asked
    assert abs(goal_line_crossing(world, target[0]) - target[1]) < TOLERANCE_M


GRAVITY_M_S2 = 9.81
CHIP_REACH_M = 2.0  # the chip's target this far from the ball, where a chip from a robot standing still lands
CHIP_TOLERANCE_M = 0.15  # the aimed chip's first bounce this near its target (unaimed, 0.6 m off at 1 m/s sideways)


@pytest.mark.parametrize("sideways_m_s", [1.0, -1.0, 0.0])
def test_a_robot_driving_sideways_chips_onto_its_target(sideways_m_s: float) -> None:
    """A robot carries the ball on its dribbler across the field at ``sideways_m_s`` (scripted), turns
    with it toward a target ``CHIP_REACH_M`` ahead (the team's skill sets the heading, the turn
    scripted) and chips at the kicker's speed that lands a chip from a robot standing still on the
    target: the first bounce is within ``CHIP_TOLERANCE_M`` of the target. (The robot's sideways
    motion carries over to the ball in the air for the whole flight, 0.6 s: a chip facing the target
    lands 0.6 m to its side. What remains is the chip's length, which the heading does not set: the
    kicker's horizontal speed K, turned against the motion, leaves sqrt(K² - v²) along the way.)"""
    s, world = SETTINGS.sim, one_robot_world()
    skills = SETTINGS.strategy.skills
    angle = s.kicker.chip_angle_rad
    kicker_m_s = math.sqrt(CHIP_REACH_M * GRAVITY_M_S2 / math.sin(2.0 * angle))
    x0, y0 = -1.0, -0.6 * math.copysign(1.0, sideways_m_s)
    world.place_robot("blue", 0, x0, y0, 0.0)
    world.place_ball(x0 + skills.contact_m, y0)
    target = (x0 + skills.contact_m + CHIP_REACH_M, 0.0)
    dt = 1.0 / s.physics.frame_rate_hz
    for _ in range(round(0.4 / dt)):  # up to speed sideways, the ball held
        world.step_frame([RobotCommand("blue", 0, vy=sideways_m_s, dribbler=1.0)])
    assert world.holding("blue", 0)
    kicked, last = False, None
    for _ in range(round(1.0 / dt)):
        truth = world.ground_truth()
        r, b = truth.robots[0], truth.ball
        robot = RobotState("blue", 0, r.x, r.y, r.theta, r.vx, r.vy, r.omega)
        ball = BallState(b.x, b.y, b.vx, b.vy)
        aim = math.atan2(target[1] - b.y, target[0] - b.x)
        heading = drive_through(robot, ball, aim, kicker_m_s, skills, chip=True).theta
        error = wrap_angle(heading - r.theta)
        armed = abs(error) < LINED_UP_RAD
        # the scripted turn: a share of the error a frame, plus how fast the heading asked turns (the aim
        # turns as the robot drives across it)
        follow = 0.0 if last is None else wrap_angle(heading - last) / dt
        last = heading
        cmd = RobotCommand("blue", 0, vy=sideways_m_s, omega=HEADING_GAIN * error / dt + follow,
                           kick_speed=kicker_m_s if armed else 0.0, chip=armed, dribbler=1.0)
        sent = relative_kick(cmd, r.theta, (r.vx, r.vy), SETTINGS.field.robot)
        if any(isinstance(e, Kick) for e in world.step_frame([sent])):
            kicked = True
            break
    assert kicked, "no chip"
    landing = first_bounce(world)
    assert math.dist(landing, target) < CHIP_TOLERANCE_M


LINED_UP_RAD = 0.005  # the scripted chip fires facing the skill's heading this near


def first_bounce(world: World) -> tuple[float, float]:
    """Where a chipped ball first comes down (m), from the last frame of its flight (no drag in the air)."""
    dt = 1.0 / SETTINGS.sim.physics.frame_rate_hz
    before = world.ground_truth().ball
    for _ in range(round(3.0 / dt)):
        world.step_frame([])
        after = world.ground_truth().ball
        if after.vz > before.vz or after.z <= 0.0:  # bounced (or rolled out) since the last frame
            t = (before.vz + math.sqrt(before.vz**2 + 2.0 * GRAVITY_M_S2 * before.z)) / GRAVITY_M_S2
            return before.x + before.vx * t, before.y + before.vy * t
        before = after
    raise AssertionError("the chipped ball did not come down")
