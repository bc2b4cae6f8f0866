"""The brain's safety call: own robots the tracker lost stay in the safety search and are stopped."""

from __future__ import annotations

from pathlib import Path

import pytest

from cmdragons.messages import BallState, GameState, RobotCommand, RobotState, WorldState
from cmdragons.runtime.settings import load_settings
from cmdragons.team import Brain

SETTINGS = load_settings(Path(__file__).resolve().parents[1] / "configs")
BALL = BallState(2.0, 1.0, 0.0, 0.0)


def world(t: float, *robots: RobotState) -> WorldState:
    return WorldState(t, BALL, robots)


def test_a_lost_robot_is_stopped_and_kept_where_it_brakes_to() -> None:
    brain = Brain("blue", SETTINGS)
    game = GameState(0.0)
    brain.step(world(0.0, RobotState("blue", 0, -1.0, 0.0, 0.0), RobotState("blue", 1, 0.0, 0.0, 0.0, 1.2, 0.0)),
               game)  # fmt: skip
    later = world(0.1, RobotState("blue", 0, -1.0, 0.0, 0.0))
    out = {c.id: c for c in brain.step(later, game)}
    assert (out[1].vx, out[1].vy, out[1].omega) == (0.0, 0.0, 0.0)
    brake = SETTINGS.control.motion.max_brake_m_s2
    (ghost,) = brain._lost_robots(later)
    # braking at full strength for 0.1 s from 1.2 m/s along +x
    assert ghost.x == pytest.approx(1.2 * 0.1 - 0.5 * brake * 0.01) and ghost.vx == pytest.approx(1.2 - brake * 0.1)
    (rest,) = brain._lost_robots(world(2.0, RobotState("blue", 0, -1.0, 0.0, 0.0)))
    assert rest.x == pytest.approx(1.2**2 / (2 * brake)) and rest.vx == pytest.approx(0.0, abs=1e-12)
    # seen again: no longer lost
    both = world(2.1, RobotState("blue", 0, -1.0, 0.0, 0.0), RobotState("blue", 1, 0.5, 0.0, 0.0))
    assert brain._lost_robots(both) == ()


def test_team_mates_do_not_drive_into_a_lost_robot() -> None:
    brain = Brain("blue", SETTINGS)
    safety = brain.safety
    ghost = RobotState("blue", 1, 0.3, 0.0, 0.0, visible=False)
    cmd = [RobotCommand("blue", 0, 2.0, 0.0), RobotCommand("blue", 1)]
    robot0 = RobotState("blue", 0, 0.0, 0.0, 0.0, 2.0, 0.0)
    blind = safety.make_safe(cmd[:1], world(0.0, robot0))
    assert blind[0].vx == pytest.approx(2.0)  # without the lost robot nothing is in the way
    seen = safety.make_safe(cmd, world(0.0, robot0, ghost))
    assert seen[0].vx < 2.0
