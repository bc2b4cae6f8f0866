"""Restarts alone: the command each kind leads to, the placement before a free kick, the calls'
restarts, which team defends a half, the penalty mark and when a kick is taken (field frame, m)."""

from __future__ import annotations

import pytest

from cmdragons.geometry import Field, LeagueParams, Team
from cmdragons.messages import RefereeCommand
from sim.restarts import (
    Restart,
    RestartKind,
    attack_sign,
    defender_of,
    kick_taken,
    other,
    penalty_mark,
    restart_of_call,
)

C, K = RefereeCommand, RestartKind
FIELD = Field(LeagueParams())


@pytest.mark.parametrize(("kind", "command"), [
    (K.KICKOFF, C.KICKOFF), (K.FREE_KICK, C.FREE_KICK), (K.PLACED_FREE_KICK, C.FREE_KICK),
    (K.REFEREE_FREE_KICK, C.FREE_KICK), (K.PENALTY, C.PENALTY), (K.FORCE_START, C.FORCE_START),
])  # fmt: skip
def test_each_kind_leads_to_its_command(kind: RestartKind, command: RefereeCommand) -> None:
    assert kind.command is command
    team: Team | None = None if kind is K.FORCE_START else "blue"
    assert Restart(1.0, kind, team, (0.0, 0.0)).next_command(may_place=False) == (command, team)


@pytest.mark.parametrize(("kind", "may_place", "expected"), [
    (K.FREE_KICK, True, C.BALL_PLACEMENT), (K.FREE_KICK, False, C.FREE_KICK),
    (K.PLACED_FREE_KICK, True, C.FREE_KICK), (K.REFEREE_FREE_KICK, True, C.FREE_KICK),
    (K.KICKOFF, True, C.KICKOFF), (K.PENALTY, True, C.PENALTY),
])  # fmt: skip
def test_only_a_free_kick_to_be_placed_is_preceded_by_the_teams_placement(
        kind: RestartKind, may_place: bool, expected: RefereeCommand) -> None:  # fmt: skip
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
])  # fmt: skip
def test_the_team_defending_a_half(x: float, blue_sign: int, defender: Team) -> None:
    assert defender_of(x, blue_sign) == defender
    assert attack_sign(other(defender), blue_sign) == (1.0 if x >= 0.0 else -1.0)


@pytest.mark.parametrize(("team", "blue_sign", "side"), [("blue", -1, 1.0), ("yellow", -1, -1.0),
                                                         ("blue", 1, -1.0), ("yellow", 1, 1.0)])  # fmt: skip
def test_the_penalty_mark_is_in_front_of_the_goal_the_team_attacks(team: Team, blue_sign: int, side: float) -> None:
    x, y = penalty_mark(FIELD, 1.5, team, blue_sign)
    assert (x, y) == pytest.approx((side * (FIELD.half_length - 1.5), 0.0), abs=1e-12)


@pytest.mark.parametrize(("moved", "taken"), [(0.0, False), (0.049, False), (0.0499, False), (0.0501, True),
                                              (1.0, True)])  # fmt: skip
def test_a_kick_is_taken_once_the_ball_moved_the_rules_distance(moved: float, taken: bool) -> None:
    placed = (1.0, -2.0)
    for ux, uy in ((1.0, 0.0), (0.0, -1.0), (0.6, 0.8)):
        assert kick_taken((placed[0] + ux * moved, placed[1] + uy * moved), placed, 0.05) is taken
