"""The navigator contract (after OMPL's PlannerTest, for Nav2-style controllers): every registered
navigator drives a simulated robot (ground truth, robots that act on a command at once) along a
path to a free goal, never commands beyond the robot's limits, brings it to rest there, and
commands the stop when its termination leaves it no work at all."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.control import ControlParams
from cmdragons.geometry import Field, LeagueParams, wrap_angle
from cmdragons.messages import RobotCommand, RobotState
from cmdragons.navigation import NAVIGATORS, STOP, Arrival, make_navigator
from cmdragons.planning import budget, deadline, field_world
from cmdragons.team import TeamParams
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World

NAMES = sorted(NAVIGATORS)
CONTROL = ControlParams()
M = CONTROL.motion
FIELD = Field(LeagueParams())
RADIUS = 0.09
# free goals, with the straight path or one around a corner; the last one turns round on the spot
CASES = [
    ((-3.0, -2.0, 0.0), [(-3.0, -2.0), (3.0, 1.0)], 1.5),
    ((0.0, 0.0, 0.0), [(0.0, 0.0), (0.3, -0.2)], -2.0),
    ((-2.0, 1.5, 0.0), [(-2.0, 1.5), (0.0, 2.2), (2.0, 0.5)], 3.0),
]


def drive(name: str, start: tuple[float, float, float], path: list[tuple[float, float]], heading: float,
          seconds: float) -> tuple[World, list[RobotCommand], list[np.ndarray]]:
    """Run navigator ``name`` in the simulator for ``seconds``: the world, its commands, the states."""
    w = World(LeagueParams(), PhysicsParams(), RobotParams(command_latency_s=0.0), BallParams(), KickerParams(),
              DribblerParams(), robots_per_team={"blue": 1, "yellow": 0})
    w.place_ball(0.0, 3.1)
    w.place_robot("blue", 0, *start)
    nav = make_navigator(name, TeamParams().navigator_sections, CONTROL, RADIUS)
    nav.set_plan(np.array(path), Arrival(heading))
    world = field_world(FIELD)
    commands, states = [], []
    for _ in range(round(seconds * 60)):
        row = w.snapshot().robots[0]
        states.append(row[2:8].copy())
        robot = RobotState("blue", 0, *(float(v) for v in row[2:8]))
        # a deadline out of reach (a loaded machine, a kernel compiling on first use): the limits are
        # what is tested here, not the stop a navigator gives when its time runs out
        vx, vy, omega = nav.command(robot, world, deadline(60.0))
        nav.sent(vx, vy)
        commands.append(RobotCommand("blue", 0, vx, vy, omega))
        w.step_frame(commands[-1:])
    return w, commands, states


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize(("start", "path", "heading"), CASES)
def test_every_navigator_reaches_a_free_goal_within_the_limits_and_rests_there(
    name: str, start: tuple[float, float, float], path: list[tuple[float, float]], heading: float
) -> None:
    w, commands, states = drive(name, start, path, heading, 7.0)
    goal = path[-1]
    # reached and at rest for the last second: within 1 cm, 0.02 rad, 1 cm/s
    for s in states[-60:]:
        assert math.hypot(s[0] - goal[0], s[1] - goal[1]) < 0.01
        assert math.hypot(s[3], s[4]) < 0.01
    assert abs(wrap_angle(states[-1][2] - heading)) < 0.02
    # the limits: speed, the acceleration set A(v) between two commands, the turn rate
    v = np.array([(c.vx, c.vy) for c in commands])
    assert np.all(np.hypot(v[:, 0], v[:, 1]) <= M.max_speed_m_s + 1e-9)
    assert np.all(np.abs([c.omega for c in commands]) <= M.max_omega_rad_s + 1e-9)
    dv = np.diff(np.vstack([[0.0, 0.0], v]), axis=0) / M.period_s
    assert np.all(np.hypot(dv[:, 0], dv[:, 1]) <= M.max_brake_m_s2 + 1e-6)
    speeding_up = np.einsum("ij,ij->i", dv, np.vstack([[0.0, 0.0], v[:-1]])) >= 0.0
    assert np.all(np.hypot(dv[speeding_up, 0], dv[speeding_up, 1]) <= M.max_accel_m_s2 + 1e-6)
    assert w.faults.clamped == 0


@pytest.mark.parametrize("name", NAMES)
def test_a_speed_cap_is_kept(name: str) -> None:
    nav = make_navigator(name, TeamParams().navigator_sections, CONTROL, RADIUS)
    nav.set_plan(np.array([(0.0, 0.0), (3.0, 0.0)]), Arrival(0.0, max_speed_m_s=1.0))
    robot = RobotState("blue", 0, 0.0, 0.0, 0.0, 1.0, 0.0)
    for _ in range(30):
        vx, vy, _ = nav.command(robot, field_world(FIELD), deadline(60.0))
        assert math.hypot(vx, vy) <= 1.0 + 1e-9


@pytest.mark.parametrize("name", NAMES)
def test_no_work_allowed_is_the_stop(name: str) -> None:
    nav = make_navigator(name, TeamParams().navigator_sections, CONTROL, RADIUS)
    nav.set_plan(np.array([(0.0, 0.0), (3.0, 0.0)]), Arrival(0.0))
    robot = RobotState("blue", 0, 0.0, 0.0, 0.0, 2.0, 0.0)
    world = field_world(FIELD)
    assert nav.command(robot, world, budget(0)) == STOP
    assert nav.command(robot, world, deadline(-1.0)) == STOP
    assert nav.command(robot, world, deadline(60.0)) != STOP
    with pytest.raises(KeyError, match="unknown navigator"):
        make_navigator("magic", TeamParams().navigator_sections, CONTROL, RADIUS)
