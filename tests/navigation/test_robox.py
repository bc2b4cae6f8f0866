"""The Robox stack (global path -> elastic band -> dynamic window) in the simulator: the band pulls a
wide detour taut round a robot standing in the way, the robot gets to its goal without touching
it, and the band gives way to a robot that moves into it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cmdragons.control import ControlParams
from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import RobotCommand, RobotState
from cmdragons.navigation import Arrival, RoboxNavigator, make_navigator
from cmdragons.navigation.robox import along
from cmdragons.planning import deadline, field_world
from cmdragons.planning.errt import ERRTPlanner
from cmdragons.planning.gridplan import EStarPlanner
from cmdragons.runtime.match import Match
from cmdragons.runtime.settings import load_settings, load_team_settings
from cmdragons.runtime.stages import TeamStage
from cmdragons.team import TeamParams
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
CONTROL = ControlParams()
FIELD = Field(LeagueParams())
RADIUS = 0.09
MARGIN = TeamParams().navigator_sections["dynamic_window"].margin_m


def run(obstacle_path: list[tuple[float, float]], plan: list[tuple[float, float]], seconds: float) -> tuple[
        np.ndarray, np.ndarray, RoboxNavigator]:
    """Drive blue 0 from the plan's start with the robox navigator while yellow 0 is placed along
    ``obstacle_path`` (one point a frame, the last held): our positions and the obstacle's (n, 2)."""
    w = World(LeagueParams(), PhysicsParams(), RobotParams(command_latency_s=0.0), BallParams(), KickerParams(),
              DribblerParams(), robots_per_team={"blue": 1, "yellow": 1})
    w.place_ball(0.0, 3.1)
    w.place_robot("blue", 0, *plan[0], 0.0)
    nav = make_navigator("robox", TeamParams().navigator_sections, CONTROL, RADIUS)
    assert isinstance(nav, RoboxNavigator)
    ours, theirs = [], []
    for k in range(round(seconds * 60)):
        ox, oy = obstacle_path[min(k, len(obstacle_path) - 1)]
        w.place_robot("yellow", 0, ox, oy, 0.0)
        row = w.snapshot().robots[0]
        robot = RobotState("blue", 0, *(float(v) for v in row[2:8]))
        nav.set_plan(np.array(plan), Arrival(0.0))  # the same plan every frame, as a planner that keeps it
        vx, vy, omega = nav.command(robot, field_world(FIELD, [(ox, oy)]), deadline(60.0))
        nav.sent(vx, vy)
        w.step_frame([RobotCommand("blue", 0, vx, vy, omega)])
        ours.append(w.snapshot().robots[0][2:4].copy())
        theirs.append((ox, oy))
    return np.array(ours), np.array(theirs), nav


def test_a_wide_detour_is_pulled_taut_round_a_robot_in_the_way() -> None:
    plan = [(-2.0, 0.0), (0.0, 1.2), (2.0, 0.0)]  # 4.66 m, a metre wider than it needs
    ours, theirs, _ = run([(0.0, 0.0)], plan, 6.0)
    assert math.dist(tuple(ours[-1]), plan[-1]) < 0.01
    gaps = np.hypot(*(ours - theirs).T) - 2 * RADIUS
    assert gaps.min() >= MARGIN - 5e-3  # the window's margin, to the simulator's contact slack
    driven = float(np.sum(np.hypot(*np.diff(ours, axis=0).T)))
    assert driven < 4.2  # the straight line is 4.0 m, the plan 4.66 m


def test_the_band_gives_way_to_a_robot_moving_into_it() -> None:
    # a robot walks up across the straight way while ours drives along it
    crossing = [(0.5, -1.0 + 0.012 * k) for k in range(90)]  # 0.72 m/s, it stops on the line
    plan = [(-2.0, 0.0), (2.0, 0.0)]
    ours, theirs, nav = run(crossing, plan, 7.0)
    assert math.dist(tuple(ours[-1]), plan[-1]) < 0.01
    gaps = np.hypot(*(ours - theirs).T) - 2 * RADIUS
    assert gaps.min() >= MARGIN - 5e-3


def test_along_a_polyline() -> None:
    path = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 2.0)])
    np.testing.assert_allclose(along(path, 0.5), (0.5, 0.0))
    np.testing.assert_allclose(along(path, 1.5), (1.0, 0.5))
    np.testing.assert_allclose(along(path, 9.0), (1.0, 2.0))


@pytest.mark.slow
def test_a_match_of_the_errt_team_against_the_robox_stack() -> None:
    # what `cmdragons play --opponent self --opponent-set team.navigator=robox --opponent-set
    # planner.planner=estar` runs (on truth, for speed): each team plans and navigates with its own
    # the stall deadlines out of reach: on a loaded machine a plan cut off by the clock is no_path
    calm = ["team.brain.navigate_deadline_ms=10000", "planner.deadline_ms=10000"]
    theirs = load_team_settings(CONFIGS, calm, ["team.navigator=robox", "planner.planner=estar"])
    match = Match(load_settings(CONFIGS, calm), "self", "truth", seed=2, opponent_settings=theirs)
    summary = match.run(10.0)
    brains = {s.team: s.brain for s in match.bus.stages if isinstance(s, TeamStage)}
    assert all(isinstance(p, ERRTPlanner) for p in brains["blue"].planners.values())
    assert all(isinstance(p, EStarPlanner) for p in brains["yellow"].planners.values())
    assert all(isinstance(n, RoboxNavigator) for n in brains["yellow"].navigators.values())
    # the planners' statuses (no path to a blocked goal is one: a value, not an error; a robot inside the
    # ball's circle escapes straight off the ball)
    assert {p.status.value for p in brains["yellow"].plans.values()} <= {"solved", "approximate", "direct", "halt",
                                                                         "no_path", "escape"}
    assert summary["collisions"]["own"] == 0 and summary["opponent_team"]["collisions"]["own"] == 0
    assert summary["cycle_ms"]["opponent_brain"]["median"] > 0.0
