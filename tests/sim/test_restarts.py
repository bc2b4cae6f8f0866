"""Restarts alone: the command each kind leads to, the placement before a free kick, the calls'
restarts, which team defends a half, the penalty mark and when a kick is taken, where the robots go
and one frame's moves gathered into a teleport (field frame, m)."""

from __future__ import annotations

import math

import pytest

from cmdragons.geometry import Field, LeagueParams, Team
from cmdragons.messages import RefereeCommand, RobotTruth, Teleport
from sim.restarts import (
    Moves,
    Restart,
    RestartKind,
    aside,
    attack_sign,
    ball_out_taker,
    defender_of,
    entry_spot,
    formation,
    kick_taken,
    other,
    park,
    penalty_mark,
    restart_of_call,
    shootout_poses,
)

C, K = RefereeCommand, RestartKind
FIELD = Field(LeagueParams())


@pytest.mark.parametrize(("kind", "command"), [
    (K.KICKOFF, C.KICKOFF), (K.FREE_KICK, C.FREE_KICK), (K.PLACED_FREE_KICK, C.FREE_KICK),
    (K.REFEREE_FREE_KICK, C.FREE_KICK), (K.PENALTY, C.PENALTY), (K.FORCE_START, C.FORCE_START),
])
def test_each_kind_leads_to_its_command(kind: RestartKind, command: RefereeCommand) -> None:
    assert kind.command is command
    team: Team | None = None if kind is K.FORCE_START else "blue"
    assert Restart(1.0, kind, team, (0.0, 0.0)).next_command(may_place=False) == (command, team)


@pytest.mark.parametrize(("kind", "may_place", "expected"), [
    (K.FREE_KICK, True, C.BALL_PLACEMENT), (K.FREE_KICK, False, C.FREE_KICK),
    (K.PLACED_FREE_KICK, True, C.FREE_KICK), (K.REFEREE_FREE_KICK, True, C.FREE_KICK),
    (K.KICKOFF, True, C.KICKOFF), (K.PENALTY, True, C.PENALTY),
])
def test_only_a_free_kick_to_be_placed_is_preceded_by_the_teams_placement(
        kind: RestartKind, may_place: bool, expected: RefereeCommand) -> None:
    assert Restart(0.0, kind, "yellow", (1.0, 2.0)).next_command(may_place) == (expected, "yellow")


def test_a_force_start_is_for_both_teams_even_where_placing_is_allowed() -> None:
    assert Restart(0.0, K.FORCE_START, None, (1.0, 2.0)).next_command(may_place=True) == (C.FORCE_START, None)


@pytest.mark.parametrize(("call", "kind"), [(C.FREE_KICK, K.FREE_KICK), (C.PENALTY, K.PENALTY)])
def test_a_calls_restart(call: RefereeCommand, kind: RestartKind) -> None:
    assert restart_of_call(call) is kind


@pytest.mark.parametrize("call", [C.STOP, C.HALT, C.NORMAL, C.KICKOFF])
def test_a_call_restarts_with_nothing_else(call: RefereeCommand) -> None:
    with pytest.raises(ValueError, match="free kick or a penalty"):
        restart_of_call(call)


@pytest.mark.parametrize(("x", "blue_sign", "defender"), [
    (-1.0, -1, "blue"), (1.0, -1, "yellow"), (-1.0, 1, "yellow"), (1.0, 1, "blue"), (0.0, -1, "yellow"),
])
def test_the_team_defending_a_half(x: float, blue_sign: int, defender: Team) -> None:
    assert defender_of(x, blue_sign) == defender
    assert attack_sign(other(defender), blue_sign) == (1.0 if x >= 0.0 else -1.0)


@pytest.mark.parametrize(("team", "blue_sign", "side"), [("blue", -1, 1.0), ("yellow", -1, -1.0),
                                                         ("blue", 1, -1.0), ("yellow", 1, 1.0)])
def test_the_penalty_mark_is_in_front_of_the_goal_the_team_attacks(team: Team, blue_sign: int, side: float) -> None:
    x, y = penalty_mark(FIELD, 1.5, team, blue_sign)
    assert (x, y) == pytest.approx((side * (FIELD.half_length - 1.5), 0.0), abs=1e-12)


@pytest.mark.parametrize(("moved", "taken"), [(0.0, False), (0.049, False), (0.0499, False), (0.0501, True),
                                              (1.0, True)])
def test_a_kick_is_taken_once_the_ball_moved_the_rules_distance(moved: float, taken: bool) -> None:
    placed = (1.0, -2.0)
    for ux, uy in ((1.0, 0.0), (0.0, -1.0), (0.6, 0.8)):
        assert kick_taken((placed[0] + ux * moved, placed[1] + uy * moved), placed, 0.05) is taken


@pytest.mark.parametrize(("last_touch", "x", "blue_sign", "taker"), [
    ("blue", 3.0, -1, "yellow"), ("yellow", 3.0, -1, "blue"), (None, 3.0, -1, "yellow"), (None, -3.0, -1, "blue"),
    (None, -3.0, 1, "yellow"), ("blue", -3.0, 1, "yellow"),
])
def test_the_free_kick_after_the_ball_left_the_field(last_touch: Team | None, x: float, blue_sign: int,
                                                     taker: Team) -> None:
    assert ball_out_taker(last_touch, x, blue_sign) == taker


def _robot(team: Team, rid: int, x: float, y: float, theta: float = 0.0) -> RobotTruth:
    return RobotTruth(team, rid, x, y, theta, 0.0, 0.0, 0.0)


def test_a_formation_is_mirrored_through_the_centre_for_the_team_at_plus_x() -> None:
    poses = [(-4.0, 1.0, 0.0), (-2.0, -0.5, 0.5), (-1.0, 0.0, -3.0)]
    assert formation(poses, 2, -1) == poses[:2]
    mirrored = formation(poses, 3, 1)
    assert [(x, y) for x, y, _ in mirrored] == [(4.0, -1.0), (2.0, 0.5), (1.0, -0.0)]
    assert [th for _, _, th in mirrored] == pytest.approx([math.pi, 0.5 - math.pi, math.pi - 3.0])


def test_robots_off_the_field_wait_outside_the_boundary_on_their_side() -> None:
    for index, team, side in ((0, "blue", -1.0), (3, "yellow", 1.0)):
        x, y = park(FIELD, index, team, 3.0)  # type: ignore[arg-type]
        assert x == pytest.approx(-FIELD.half_length + 0.4 * index)
        assert y == pytest.approx(side * (FIELD.boundary_half_width + 3.0)) and abs(y) > FIELD.boundary_half_width


def test_a_robot_comes_back_in_its_half_by_its_touch_line_on_the_first_free_spot() -> None:
    r = FIELD.league.robot.radius_m
    y = -(FIELD.half_width - 2.0 * r)
    assert entry_spot(FIELD, [], "blue", -1) == pytest.approx((-2.0 * r, y))
    blocked = [_robot("yellow", 0, -2.0 * r, y), _robot("yellow", 1, -4.0 * r, y + r)]
    x, yy = entry_spot(FIELD, blocked, "blue", -1)
    assert yy == pytest.approx(y) and x == pytest.approx(-8.0 * r)  # -6 r: 2.2 r from the second robot, too near
    assert all(math.hypot(o.x - x, o.y - yy) > 4.0 * r for o in blocked)
    assert entry_spot(FIELD, [], "yellow", -1) == pytest.approx((2.0 * r, -y))


def test_robots_on_the_spot_are_moved_aside_to_the_clearance() -> None:
    robots = [_robot("blue", 0, 0.1, 0.0, 1.0), _robot("yellow", 1, 0.0, 0.0), _robot("yellow", 2, 1.0, 0.0),
              _robot("blue", 3, 0.0, -0.05)]
    moved = aside(robots, (0.0, 0.0), 0.2, attack=1.0, off={("blue", 3)})
    assert moved == [("blue", 0, pytest.approx(0.2), pytest.approx(0.0), 1.0),
                     ("yellow", 1, pytest.approx(-0.2), pytest.approx(0.0), 0.0)]


def test_a_shootout_kick_puts_the_kicker_behind_the_mark_and_the_other_keeper_on_its_line() -> None:
    keys: list[tuple[Team, int]] = [("blue", 0), ("blue", 1), ("yellow", 0), ("yellow", 1), ("yellow", 2)]
    parked = {k: (float(i), 9.0) for i, k in enumerate(keys)}
    mark = penalty_mark(FIELD, 1.5, "yellow", -1)  # yellow attacks -x
    moves = shootout_poses(FIELD, keys, {("yellow", 2)}, {"blue": 0, "yellow": 0}, "yellow", mark, -1.0, 1.0, parked)
    r = FIELD.league.robot.radius_m
    assert moves == [
        ("blue", 0, pytest.approx(-(FIELD.half_length - 0.5 * r)), 0.0, 0.0),  # the keeper on its line
        ("blue", 1, 1.0, 9.0, 0.0),  # off: the other team's field player
        ("yellow", 0, 2.0, 9.0, 0.0),  # off: the kicking team's keeper
        ("yellow", 1, pytest.approx(mark[0] + 1.0), 0.0, math.pi),  # the kicker, facing -x
    ]


def test_a_frames_moves_are_one_teleport_robots_in_order_the_last_ball() -> None:
    keys: list[tuple[Team, int]] = [("blue", 0), ("blue", 1), ("yellow", 0)]
    moves = Moves(FIELD, keys, {"B": ((-4.0, 0.0, 0.0), (-2.0, 1.0, 0.0))}, 3.0)
    assert moves.take(1.0) is None
    moves.add(1.0, ball=(1.0, 1.0))
    only = moves.pending[0]
    assert moves.take(1.0) is only  # one part: itself
    moves.send_off(2.0, ("blue", 1))
    moves.add(2.0, [("yellow", 0, 0.5, 0.5, 0.0)], ball=(2.0, 0.0))
    moves.add(2.0, ball=(3.0, 0.0))
    moves.add(2.0, [("blue", 0, -1.0, 0.0, 0.0)])
    assert moves.moving() == {("blue", 1), ("yellow", 0), ("blue", 0)}
    px, py = park(FIELD, 1, "blue", 3.0)
    assert moves.take(2.5) == Teleport(2.5, (("blue", 1, px, py, 0.0), ("yellow", 0, 0.5, 0.5, 0.0),
                                             ("blue", 0, -1.0, 0.0, 0.0)), (3.0, 0.0))
    assert moves.take(3.0) is None and moves.moving() == set()


def test_the_kickoff_puts_both_teams_in_formation_and_leaves_robots_off_the_field_off() -> None:
    keys: list[tuple[Team, int]] = [("blue", 0), ("blue", 1), ("yellow", 3), ("yellow", 4)]
    poses = ((-4.0, 0.0, 0.0), (-2.0, 1.0, 0.0))
    kickoff = Moves(FIELD, keys, {"B": poses}, 3.0).kickoff(1.0, -1, off={("yellow", 4)})
    mirrored = formation(poses, 1, 1)[0]
    assert kickoff.ball == (0.0, 0.0) and kickoff.robots == (("blue", 0, *poses[0]), ("blue", 1, *poses[1]),
                                                             ("yellow", 3, *mirrored))
    with pytest.raises(ValueError, match=r"sim.referee.formations.B lists 1 poses but the team has 2"):
        Moves(FIELD, keys, {"B": poses[:1]}, 3.0).kickoff(1.0, -1, off=())
