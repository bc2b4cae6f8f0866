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
from sim.world import World
from strategy.skills import dribble

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
