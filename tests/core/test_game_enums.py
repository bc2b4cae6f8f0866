"""The referee's commands, the game's stages and the kick purposes are enums whose values are the
JSONL forms: every member survives the dict form and the protobuf form, is written as its plain
string, and a string that names none is refused with the choices."""

from __future__ import annotations

import json

import pytest

from cmdragons.messages import (
    GameEvent,
    GameEvents,
    GameStage,
    GameState,
    KickPurpose,
    MessageError,
    RefereeCommand,
    TeamReport,
)
from cmdragons.runtime import wire
from cmdragons.runtime.ssl.referee import RefereeReader, referee_proto


def _wire(m: GameState | GameEvents | TeamReport, topic: str) -> object:
    return wire.decode(wire.schema(m), wire.encode(m))


@pytest.mark.parametrize("command", list(RefereeCommand))
@pytest.mark.parametrize("stage", list(GameStage))
def test_every_command_and_stage_survives_the_dict_and_wire_forms(command: RefereeCommand, stage: GameStage) -> None:
    g = GameState(1.0, command, "blue", stage=stage, next_command=command, next_for_team="yellow")
    d = g.to_dict()
    assert json.dumps(d["command"]) == json.dumps(command.value)  # the plain string, as before the enum
    assert (d["command"], d["stage"], d["next_command"]) == (command.value, stage.value, command.value)
    for back in (GameState.from_dict(json.loads(json.dumps(d))), _wire(g, "referee")):
        assert isinstance(back, GameState)
        assert back == g and back.command is command and back.stage is stage and back.next_command is command


@pytest.mark.parametrize("command", [c for c in RefereeCommand if c.kick_restart or c.prepared or c in (
    RefereeCommand.TIMEOUT, RefereeCommand.BALL_PLACEMENT)])  # the commands for one team
@pytest.mark.parametrize("team", ["blue", "yellow"])
def test_a_team_command_reads_back_from_the_leagues_referee_message(command: RefereeCommand, team: str) -> None:
    g = GameState(2.0, command, team, ready=False)  # type: ignore[arg-type]
    back = RefereeReader().read(referee_proto(g))
    assert (back.command, back.for_team) == (command, team)


@pytest.mark.parametrize(("field", "value"), [("command", "kick_off"), ("stage", "extra_time"),
                                              ("next_command", "go")])
def test_a_string_that_names_no_member_is_refused_with_the_choices(field: str, value: str) -> None:
    with pytest.raises(MessageError, match="must be one of"):
        GameState(0.0, **{field: value})  # type: ignore[arg-type]


@pytest.mark.parametrize("restart", [None, RefereeCommand.FREE_KICK, RefereeCommand.PENALTY])
def test_a_calls_restart_is_an_empty_string_on_disk_when_none(restart: RefereeCommand | None) -> None:
    e = GameEvent(3.0, "crash", "blue", 1, 2.0, 1.5, "m/s", restart, "yellow" if restart else None)
    assert e.to_dict()["restart"] == ("" if restart is None else restart.value)
    assert GameEvent.from_dict(e.to_dict()).restart is restart
    back = _wire(GameEvents(3.0, (e,)), "referee/events")
    assert isinstance(back, GameEvents) and back.events[0].restart is restart


def test_kick_purposes_survive_a_team_report() -> None:
    r = TeamReport("blue", 7, 0.5, actions={i: p for i, p in enumerate(KickPurpose)})
    d = r.to_dict()
    assert d["actions"] == {str(i): p.value for i, p in enumerate(KickPurpose)}
    back = _wire(r, "report/blue")
    assert isinstance(back, TeamReport)
    assert all(back.actions[i] is p for i, p in enumerate(KickPurpose))
    with pytest.raises(MessageError, match="must be one of"):
        TeamReport("blue", 7, 0.5, actions={0: "dribble"})  # type: ignore[dict-item]
