"""Dribbling in the simulator: the robot takes the ball from behind and carries it to the target on
its kicker face, the dribbler holding it, through the brain's own navigation (planner and motion
control)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from cmdragons.messages import BallState, GameState, RobotState, WorldState
from cmdragons.runtime.settings import load_settings
from cmdragons.team import Brain
from sim.world import Kick, World
from strategy.skills import dribble, pass_speed, turn_with_ball

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")


@pytest.mark.parametrize(("start", "target"), [
    ((-1.0, 0.5, 0.0), (1.5, -0.5)),  # the ball ahead, on the way
    ((1.0, 0.3, math.pi), (-1.5, 1.0)),  # the target behind the robot: round the ball first
])
def test_dribble_carries_the_ball_to_the_target(start: tuple[float, float, float], target: tuple[float, float]) -> None:
    s = SETTINGS.sim
    # in a match the tracker predicts the robots through the command latency; here the brain sees
    # the truth of now, so the robots act on their commands at once
    robot_model = dataclasses.replace(s.robot, command_latency_s=0.0)
    world = World(SETTINGS.field, s.physics, robot_model, s.ball, s.kicker, s.dribbler,
                  robots_per_team={"blue": 1, "yellow": 0})
    world.place_robot("blue", 0, *start)
    world.place_ball(0.0, 0.0)
    brain = Brain("blue", SETTINGS)
    game = GameState(0.0)
    skills = SETTINGS.strategy.skills
    held_frames = 0
    for _ in range(10 * 60):
        truth = world.ground_truth()
        r, b = truth.robots[0], truth.ball
        robot = RobotState("blue", 0, r.x, r.y, r.theta, r.vx, r.vy, r.omega)
        ball = BallState(b.x, b.y, b.vx, b.vy)
        if math.hypot(b.x - target[0], b.y - target[1]) < 0.05 and math.hypot(b.vx, b.vy) < 0.05:
            break
        intent = dribble(robot, ball, target, skills)
        (cmd,) = brain.drive(WorldState(truth.t, ball, (robot,)), {0: intent}, game)
        world.step_frame([cmd])
        held_frames += world.holding("blue", 0)
    b = world.ground_truth().ball
    # on the target (within 5 cm), at rest, carried on the dribbler (not kicked or pushed there)
    assert math.hypot(b.x - target[0], b.y - target[1]) < 0.05
    assert math.hypot(b.vx, b.vy) < 0.05
    assert world.holding("blue", 0)
    carried = math.hypot(target[0], target[1]) / skills.dribble_speed_m_s
    assert held_frames / 60 > carried


@pytest.mark.parametrize("aim", [0.0, 1.0, -2.0])  # from facing -x: half a turn, and less either way
def test_a_held_ball_is_turned_with_and_kicked_at_the_aim(aim: float) -> None:
    """The ball on the kicker face: the robot turns with it (at most ``ball_turn_rad_s``), the
    dribbler holding it, and kicks it within 5 degrees of the aim, within 2 s."""
    s = SETTINGS.sim
    robot_model = dataclasses.replace(s.robot, command_latency_s=0.0)  # the brain sees the truth of now
    world = World(SETTINGS.field, s.physics, robot_model, s.ball, s.kicker, s.dribbler,
                  robots_per_team={"blue": 1, "yellow": 0})
    skills = SETTINGS.strategy.skills
    world.place_robot("blue", 0, 0.0, 0.0, math.pi)
    world.place_ball(-skills.contact_m, 0.0)
    brain = Brain("blue", SETTINGS)
    target = (-skills.contact_m + 2.0 * math.cos(aim), 2.0 * math.sin(aim))
    kicked = None
    for _ in range(2 * 60):
        truth = world.ground_truth()
        r, b = truth.robots[0], truth.ball
        robot = RobotState("blue", 0, r.x, r.y, r.theta, r.vx, r.vy, r.omega)
        ball = BallState(b.x, b.y, b.vx, b.vy)
        intent = turn_with_ball(robot, ball, target, 4.0, skills)
        assert intent is not None, "the ball got away while turning"
        (cmd,) = brain.drive(WorldState(truth.t, ball, (robot,)), {0: intent}, GameState(0.0))
        if any(isinstance(e, Kick) for e in world.step_frame([cmd])):
            kicked = world.ground_truth().ball
            break
    assert kicked is not None
    assert abs(math.degrees(math.remainder(math.atan2(kicked.vy, kicked.vx) - aim, 2 * math.pi))) < 5.0
    assert turn_with_ball(RobotState("blue", 0, 0.0, 0.0, 0.0), BallState(0.3, 0.0, 0.0, 0.0), target, 4.0,
                          skills) is None  # a ball not on the face is not held


def rest_to_rest_turn_s(angle_rad: float, omega_rad_s: float, alpha_rad_s2: float) -> float:
    """The fastest turn through ``angle_rad`` from rest to rest at most ``omega_rad_s`` fast, speeding up
    and slowing down at ``alpha_rad_s2``: a triangle, or a trapezoid once the peak reaches the cap."""
    a = abs(angle_rad)
    if a <= omega_rad_s * omega_rad_s / alpha_rad_s2:
        return 2.0 * math.sqrt(a / alpha_rad_s2)
    return a / omega_rad_s + omega_rad_s / alpha_rad_s2


TURN_SLACK_S = 0.1  # six frames: the command holds a frame, the motors follow it, the kick fires on the next touch


@pytest.mark.parametrize("turn_deg", [80.0, -80.0, 90.0, -90.0])
def test_a_held_ball_is_turned_with_as_fast_as_the_limits_allow(turn_deg: float) -> None:
    """A robot holding the ball on its dribbler turns 80-90 degrees with it toward a pass target, through
    the brain's own navigation and motion control: it kicks within ``TURN_SLACK_S`` of the fastest turn
    its limits allow (the turn rate cap with a held ball, ``skills.ball_turn_rad_s``, and the robot's
    angular acceleration, field.yaml ``robot.max_alpha_rad_s2``; rest to rest through the angle it
    turned), never turning faster than the cap, the dribbler holding the ball every frame. (The turn as a
    heading 0.15 rad ahead each frame, a target the profile stopped on: 3.4 rad/s, kicked after 0.50-0.55 s
    where the limits allow 0.31-0.33.)"""
    s = SETTINGS.sim
    robot_model = dataclasses.replace(s.robot, command_latency_s=0.0)  # the brain sees the truth of now
    world = World(SETTINGS.field, s.physics, robot_model, s.ball, s.kicker, s.dribbler,
                  robots_per_team={"blue": 1, "yellow": 0})
    skills = SETTINGS.strategy.skills
    theta0 = math.pi
    world.place_robot("blue", 0, 0.0, 0.0, theta0)
    world.place_ball(-skills.contact_m, 0.0)
    aim = theta0 + math.radians(turn_deg)
    target = (3.0 * math.cos(aim), 3.0 * math.sin(aim))  # a pass of 3 m
    brain = Brain("blue", SETTINGS)
    dt = 1.0 / s.physics.frame_rate_hz
    kicked_at, fastest, theta = None, 0.0, theta0
    for frame in range(round(1.5 / dt)):
        truth = world.ground_truth()
        r, b = truth.robots[0], truth.ball
        fastest, theta = max(fastest, abs(r.omega)), r.theta
        robot = RobotState("blue", 0, r.x, r.y, r.theta, r.vx, r.vy, r.omega)
        ball = BallState(b.x, b.y, b.vx, b.vy)
        intent = turn_with_ball(robot, ball, target, pass_speed(3.0, skills), skills)
        assert intent is not None, f"the ball left the kicker face at {frame * dt:.3f} s"
        (cmd,) = brain.drive(WorldState(truth.t, ball, (robot,)), {0: intent}, GameState(0.0))
        if any(isinstance(e, Kick) for e in world.step_frame([cmd])):
            kicked_at = (frame + 1) * dt
            break
        assert world.holding("blue", 0), f"the dribbler let the ball go at {(frame + 1) * dt:.3f} s"
    assert kicked_at is not None, "no kick within 1.5 s"
    limits = SETTINGS.field.robot
    turned = math.remainder(theta - theta0, 2.0 * math.pi)
    assert abs(turned) > math.radians(70.0)  # the turn asked for was made
    cap = min(skills.ball_turn_rad_s, limits.max_omega_rad_s)
    assert kicked_at <= rest_to_rest_turn_s(turned, cap, limits.max_alpha_rad_s2) + TURN_SLACK_S
    assert fastest <= cap * 1.02  # the cap held (2 %: the motors' joint settles within a step)
