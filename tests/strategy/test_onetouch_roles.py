"""One-touch aiming against the kick model; role assignment with hysteresis."""

from __future__ import annotations

import math

import pytest

from strategy.onetouch import aim_heading, redirected_velocity
from strategy.roles import Objective, Role, RoleAssigner, RoleKind, RoleParams

GOALIE, ATTACKER, DEFENDER = Role(RoleKind.GOALIE), Role(RoleKind.ATTACKER), Role(RoleKind.DEFENDER)


@pytest.mark.parametrize("v_in", [(0.0, -2.0), (-3.0, 1.0), (1.0, 2.5), (0.0, 0.0)])
@pytest.mark.parametrize("target", [0.0, 0.6, -1.2])
def test_aimed_kick_leaves_toward_the_target(v_in: tuple[float, float], target: float) -> None:
    h = aim_heading(target, v_in, kick_speed=5.0, retention=0.3)
    vx, vy = redirected_velocity(h, v_in, 5.0, 0.3)
    assert abs(math.remainder(math.atan2(vy, vx) - target, 2 * math.pi)) < 1e-5
    naive = redirected_velocity(target, v_in, 5.0, 0.3)
    across = -math.sin(target) * v_in[0] + math.cos(target) * v_in[1]
    if abs(across) > 0.1:  # aiming straight at the target would miss it
        assert abs(math.remainder(math.atan2(naive[1], naive[0]) - target, 2 * math.pi)) > 0.01


def test_no_retention_means_aim_straight() -> None:
    assert aim_heading(0.7, (1.0, -2.0), 5.0, 0.0) == 0.7


def test_roles_by_priority_with_hysteresis() -> None:
    roles = RoleAssigner(RoleParams(hysteresis_m=0.3))
    objectives = [Objective(GOALIE, -4.2, 0.0, fixed_robot=0), Objective(ATTACKER, 0.0, 0.0),
                  Objective(DEFENDER, -3.0, 0.0)]  # fmt: skip
    robots = {0: (-4.0, 0.0), 1: (0.7, 0.0), 2: (-0.5, 0.0), 3: (-2.5, 0.0)}
    out = roles.assign(robots, objectives)
    assert out == {0: GOALIE, 2: ATTACKER, 3: DEFENDER}
    # robot 1 now slightly nearer: hysteresis keeps robot 2 attacking
    robots[1] = (0.45, 0.0)
    robots[2] = (-0.55, 0.0)
    assert roles.assign(robots, objectives)[2] == ATTACKER
    # clearly nearer: the role moves
    robots[1] = (0.1, 0.0)
    assert roles.assign(robots, objectives)[1] == ATTACKER


def test_goalie_always_assigned_when_present() -> None:
    roles = RoleAssigner(RoleParams())
    objectives = [Objective(GOALIE, -4.2, 0.0, fixed_robot=3), Objective(ATTACKER, 0.0, 0.0)]
    out = roles.assign({3: (4.0, 0.0), 1: (-4.0, 0.0)}, objectives)
    assert out[3] == GOALIE
