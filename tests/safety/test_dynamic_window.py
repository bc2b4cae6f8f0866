"""The dynamic window (Bruce 2006 §5.2) and the contract every registered safety method keeps."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.control import ControlParams, MotionTarget
from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import RobotCommand, RobotState, WorldState
from cmdragons.planning.world import field_world
from cmdragons.safety import _kernels as K
from cmdragons.safety import _reference as R
from cmdragons.safety.base import KEPT, STOP_ASKED
from cmdragons.safety.dynamic_window import DynamicWindow, DynamicWindowParams
from cmdragons.safety.registry import SAFETY, SafetyParams, make_safety

CONTROL = ControlParams()
M = CONTROL.motion
WORLD = field_world(Field(LeagueParams()), defense_areas=False)


def test_window_choice_is_admissible_against_robots_standing_still() -> None:
    dw = DynamicWindow(DynamicWindowParams(), CONTROL, 0.09, WORLD)
    rng = np.random.default_rng(0)
    radius = 0.18 + DynamicWindowParams().margin_m
    for _ in range(40):
        n = 5
        states = np.column_stack([rng.uniform(-1.2, 1.2, (n, 2)), rng.normal(0.0, 1.0, (n, 2))])
        commands = states[:, 2:4] + rng.normal(0.0, 0.5, (n, 2))
        r = dw.filter(states, commands, np.zeros((0, 4)))
        for i in range(n):
            v = r.velocities[i]
            if not v.any():
                continue
            # the chosen velocity, then braking, stops short of every other robot where it stands
            tr = K.trajectory(*states[i, :2], *v, 0.0, 0.0, M.period_s, M.max_accel_m_s2, M.max_brake_m_s2)
            for j in range(n):
                if j == i:
                    continue
                rest = np.array([[0.0, np.inf, *states[j, :2], 0, 0, 0, 0]])
                start = float(np.hypot(*(states[i, :2] - states[j, :2])))
                gap = float(np.min(np.hypot(*(R.positions(tr, R.sample_times(tr)) - rest[0, 2:4]).T)))
                assert gap >= min(radius, start) - 1e-3


def test_free_commands_pass_and_the_navigator_drives_toward_the_goal() -> None:
    dw = DynamicWindow(DynamicWindowParams(), CONTROL, 0.09, WORLD)
    r = dw.filter(np.array([[0.0, 0.0, 1.0, 0.0]]), np.array([[1.02, 0.0]]), np.zeros((0, 4)))
    assert r.status[0] == KEPT and r.velocities[0] == pytest.approx([1.02, 0.0])
    robot = RobotState("blue", 0, 0.0, 0.0, 0.0)
    world = WorldState(0.0, None, (robot, RobotState("yellow", 0, 0.0, 2.0, 0.0)))
    vx, vy, omega = dw.command(robot, MotionTarget(2.0, 0.0), world)
    assert vx == pytest.approx(M.max_accel_m_s2 * M.period_s) and vy == pytest.approx(0.0, abs=1e-9)
    # an opponent right in front: no speeding into it
    world = WorldState(
        0.0, None, (RobotState("blue", 0, 0.0, 0.0, 0.0, 2.5, 0.0), RobotState("yellow", 0, 0.4, 0.0, 0.0))
    )
    vx, _, _ = dw.command(world.robots[0], MotionTarget(2.0, 0.0), world)
    assert vx < 2.5


@pytest.mark.parametrize("name", sorted(SAFETY))
def test_every_method_keeps_the_contract(name: str) -> None:
    safety = make_safety(SafetyParams(), CONTROL, 0.09, WORLD, name)
    robots = tuple(RobotState("blue", i, -1.0 + 0.5 * i, 0.0, 0.0, 1.0, 0.0) for i in range(4))
    world = WorldState(0.0, None, (*robots, RobotState("yellow", 2, 2.0, 0.0, 0.0)))
    commands = [RobotCommand("blue", i, 1.05, 0.0, 0.5) for i in range(4)] + [RobotCommand("blue", 9, 1.0)]
    out = safety.make_safe(commands, world)
    assert [(c.team, c.id, c.omega) for c in out] == [(c.team, c.id, c.omega) for c in commands]
    assert out[-1] == commands[-1]  # a robot the world does not show passes unchanged
    stop = safety.filter(np.array([[0.0, 0.0, 2.0, 0.0]]), np.zeros((1, 2)), np.zeros((0, 4)))
    assert stop.velocities[0] == pytest.approx([0.0, 0.0]) and stop.status[0] in (KEPT, STOP_ASKED)
    with pytest.raises(KeyError, match="unknown safety method"):
        make_safety(SafetyParams(), CONTROL, 0.09, WORLD, "magic")
