"""A contested ball in the simulator, through the whole brain (strategy, planning, control, safety):
our attacker behind a ball lying still, an opponent's body beside the ball where ours must stand to
kick it at the goal. The attacker must get the ball away (it kicks it within ``KICK_WITHIN_S``)
instead of lining up again and again for a kick its planner and the safety search never let it make."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from cmdragons.messages import BallState, GameState, Kick, RobotCommand, RobotState, WorldState
from cmdragons.runtime.settings import load_settings
from cmdragons.team import Brain
from sim.world import World

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")
KICK_WITHIN_S = 2.0  # lining up and driving through takes well under a second; the stall time is 2 s


def test_the_attacker_kicks_a_ball_whose_kicking_position_an_opponent_takes() -> None:
    s = SETTINGS.sim
    # the brain sees the truth of now: the robots act on their commands at once
    robot_model = dataclasses.replace(s.robot, command_latency_s=0.0)
    world = World(SETTINGS.field, s.physics, robot_model, s.ball, s.kicker, s.dribbler,
                  robots_per_team={"blue": 2, "yellow": 1})
    half = SETTINGS.field_geometry().half_length
    world.place_robot("blue", 0, -half + 0.2, 0.0, 0.0)  # our goalie at home
    world.place_robot("blue", 1, 1.75, 0.3, 0.0)  # behind the ball, facing their goal
    world.place_robot("yellow", 0, 1.95, 0.13, math.pi)  # beside the ball, where our kick at the goal needs us
    world.place_ball(2.0, 0.3)
    brain = Brain("blue", SETTINGS)  # blue defends -x: it attacks the goal at +x
    game = GameState(0.0)
    kicked_at = None
    for _ in range(round(KICK_WITHIN_S * 60)):
        truth = world.ground_truth()
        b = truth.ball
        robots = tuple(RobotState(r.team, r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega) for r in truth.robots)
        out = brain.step(WorldState(truth.t, BallState(b.x, b.y, b.vx, b.vy), robots), game)
        events = world.step_frame([*out.commands, RobotCommand("yellow", 0)])  # the opponent stands still
        kicks = [e for e in events if isinstance(e, Kick) and e.team == "blue" and e.id == 1]
        if kicks:
            kicked_at = truth.t
            break
    assert kicked_at is not None, f"no kick in {KICK_WITHIN_S} s"
    b = world.ground_truth().ball
    assert b.vx > 0.0  # forward, toward their goal
