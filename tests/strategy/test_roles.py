"""Role assignment: priority order, hysteresis, the fixed goalie; roles as values."""

from __future__ import annotations

import pytest

from strategy.roles import Objective, Role, RoleAssigner, RoleKind, RoleParams

GOALIE, ATTACKER, DEFENDER = Role(RoleKind.GOALIE), Role(RoleKind.ATTACKER), Role(RoleKind.DEFENDER)


def test_roles_by_priority_with_hysteresis() -> None:
    roles = RoleAssigner(RoleParams(hysteresis_m=0.3))
    objectives = [Objective(GOALIE, -4.2, 0.0, fixed_robot=0), Objective(ATTACKER, 0.0, 0.0),
                  Objective(DEFENDER, -3.0, 0.0)]
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


def test_roles_of_one_kind_are_told_apart_by_index() -> None:
    first, second = Role(RoleKind.SUPPORTER, 0), Role(RoleKind.SUPPORTER, 1)
    assert first != second and first == Role(RoleKind.SUPPORTER, 0)
    objectives = [Objective(first, 2.0, 0.0), Objective(second, -2.0, 0.0)]
    out = RoleAssigner(RoleParams(hysteresis_m=0.0)).assign({5: (-1.9, 0.0), 7: (1.9, 0.0)}, objectives)
    assert out == {7: first, 5: second}


def test_more_objectives_than_robots_leave_the_last_ones_open() -> None:
    objectives = [Objective(GOALIE, -4.2, 0.0, fixed_robot=0), Objective(ATTACKER, 0.0, 0.0),
                  Objective(DEFENDER, -3.0, 0.0)]
    out = RoleAssigner(RoleParams()).assign({0: (-4.0, 0.0), 1: (-2.9, 0.0)}, objectives)
    assert out == {0: GOALIE, 1: ATTACKER}  # priority first, however near robot 1 is to the defender's point


def test_per_robot_costs_replace_the_distance() -> None:
    objectives = [Objective(ATTACKER, 0.0, 0.0, costs={1: 5.0, 2: 0.5})]
    out = RoleAssigner(RoleParams()).assign({1: (0.1, 0.0), 2: (3.0, 0.0)}, objectives)
    assert out == {2: ATTACKER}


@pytest.mark.parametrize("value", [-0.1, 10.5])
def test_hysteresis_out_of_range_is_refused(value: float) -> None:
    with pytest.raises(ValueError, match="hysteresis_m"):
        RoleParams(hysteresis_m=value)


def test_two_robots_of_one_kind_never_cross_each_others_way() -> None:
    # defender 0 was robot 3's and defender 1 robot 1's; the points moved past each other: hysteresis
    # alone keeps the roles, and the two would drive through each other
    d0, d1 = Role(RoleKind.DEFENDER, 0), Role(RoleKind.DEFENDER, 1)
    roles = RoleAssigner(RoleParams(hysteresis_m=0.5, swap_margin_m=0.05))
    roles.roles = {3: d0, 1: d1}
    robots = {1: (-3.41, 1.21), 3: (-3.23, 1.19)}
    objectives = [Objective(d0, -3.36, 1.11), Objective(d1, -3.27, 1.26)]
    assert roles.assign(robots, objectives) == {1: d0, 3: d1}
    assert roles.roles == {1: d0, 3: d1}  # kept for the next frame's hysteresis
    # a swap that gains less than the margin (here 0.018 m) does not happen (no flicker)
    near = [Objective(d0, 0.5, 1.0), Objective(d1, 0.52, 1.0)]
    roles.roles = {3: d0, 1: d1}
    assert roles.assign({1: (0.0, 0.0), 3: (1.0, 0.0)}, near) == {3: d0, 1: d1}
    eager = RoleAssigner(RoleParams(hysteresis_m=0.5, swap_margin_m=0.0))
    eager.roles = {3: d0, 1: d1}
    assert eager.assign({1: (0.0, 0.0), 3: (1.0, 0.0)}, near) == {1: d0, 3: d1}
    # roles of different kinds are never swapped
    mixed = [Objective(d0, -3.36, 1.11), Objective(Role(RoleKind.SUPPORTER, 0), -3.27, 1.26)]
    roles.roles = {3: d0, 1: Role(RoleKind.SUPPORTER, 0)}
    assert roles.assign(robots, mixed) == {3: d0, 1: Role(RoleKind.SUPPORTER, 0)}
