"""The game controller's Referee message <-> our GameState: our referee's states round-trip; a game
controller's sequence (prepare, normal start, the ball taken) reads as our commands; the bytes decode
with protoc; in a match our referee's packets over loopback are what our brains play to."""

from __future__ import annotations

import math
import shutil
import subprocess
from typing import Any

import pytest

from cmdragons import messages as msg
from cmdragons.runtime.match import Match
from cmdragons.runtime.proto import ssl_referee_pb2 as ref_pb
from cmdragons.runtime.proto.generate import PROTO_DIR, ROOT
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.referee import RefereeReader, referee_packet, referee_proto
from cmdragons.runtime.ssl.stages import RefereeInStage
from cmdragons.runtime.ssl.udp import DatagramQueue
from cmdragons.runtime.stages import Tap

R = ref_pb.Referee
FULL = msg.GameState(41.5, "ball_placement", "blue", 1, 0, True, (-2.0, 1.5), stage="second_half",
                     stage_time_left_s=187.25, command_counter=17, command_t=40.0, action_time_left_s=28.5,
                     next_command="free_kick", next_for_team="blue",
                     blue_team=msg.TeamInfo(fouls=2, goalkeeper=1, placement_failures=1, max_robots=6),
                     yellow_team=msg.TeamInfo(red_cards=1, yellow_cards=2, yellow_card_times_s=(75.5, 3.25), fouls=6,
                                              timeouts=3, timeout_time_s=120.0, can_place_ball=False,
                                              max_robots=3))
STATES = [
    FULL, msg.GameState(0.0), msg.GameState(0.0, "kickoff", "blue"),
    msg.GameState(3.1, "kickoff", "yellow", ready=False),
    msg.GameState(7.25, "penalty", "yellow", 2, 3, False, (3.5, 0.0), ready=False, stage="penalty_shootout"),
    msg.GameState(7.5, "penalty", "yellow", 2, 3, False, (3.5, 0.0), stage="penalty_shootout"),
    msg.GameState(9.0, "halt", stage="half_time"), msg.GameState(9.5, "stop", next_command="kickoff",
                                                                 next_for_team="yellow"),
    msg.GameState(10.0, "force_start", stage="post_game"), msg.GameState(11.0, "timeout", "yellow", stage="pre_game"),
    msg.GameState(12.0, "free_kick", "yellow", placement=(1.0, -2.8)),
]


def _same(a: Any, b: Any) -> None:
    """Equal dict forms, times to the microsecond (the league's unit) and positions to 1 µm."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys()
        for k in a:
            _same(a[k], b[k])
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _same(x, y)
    elif isinstance(a, float):
        assert b == pytest.approx(a, abs=1e-6)
    else:
        assert a == b, (a, b)


@pytest.mark.parametrize("g", STATES, ids=lambda g: f"{g.command}-{g.for_team}-{g.ready}")
def test_our_referees_states_round_trip(g: msg.GameState) -> None:
    _same(g.to_dict(), RefereeReader().read(referee_packet(g)).to_dict())


def test_the_leagues_fields_say_what_the_state_says() -> None:
    m = referee_proto(FULL, "field A", ("cmdragons", "them"), UnixEpoch(1_764_000_000))
    assert m.command == R.BALL_PLACEMENT_BLUE and m.next_command == R.DIRECT_FREE_BLUE
    assert m.stage == R.NORMAL_SECOND_HALF and m.stage_time_left == 187_250_000
    assert (m.designated_position.x, m.designated_position.y) == (-2000.0, 1500.0)
    # the packet's and the command's times in Unix microseconds, as the game controller's
    assert m.packet_timestamp == 1_764_000_041_500_000 and m.command_timestamp == 1_764_000_040_000_000
    assert RefereeReader(UnixEpoch(1_764_000_000)).read(m).t == 41.5
    assert m.blue_team_on_positive_half is False
    assert (m.blue.name, m.blue.score, m.blue.goalkeeper, m.blue.foul_counter) == ("cmdragons", 1, 1, 2)
    assert list(m.yellow.yellow_card_times) == [75_500_000, 3_250_000] and m.yellow.timeout_time == 120_000_000
    assert m.source_identifier == "field A" and not m.HasField("ball_in_play")


def _gc(command: int, counter: int, t_s: float, **fields: Any) -> bytes:
    """A game controller's packet: the league's fields only."""
    team = dict(name="x", score=0, red_cards=0, yellow_cards=0, timeouts=4, timeout_time=300_000_000, goalkeeper=0)
    m = R(packet_timestamp=round(t_s * 1e6), stage=fields.pop("stage", R.NORMAL_FIRST_HALF), command=command,
          command_counter=counter, command_timestamp=round(t_s * 1e6), yellow=R.TeamInfo(**team),
          blue=R.TeamInfo(**team), **fields)
    return m.SerializeToString()  # type: ignore[no-any-return]


def test_a_game_controllers_sequence_reads_as_our_commands() -> None:
    r = RefereeReader()
    at = R.Point(x=0.0, y=0.0)
    seq = [(_gc(R.STOP, 1, 1.0), ("stop", None, True)),
           (_gc(R.PREPARE_KICKOFF_BLUE, 2, 2.0, designated_position=at), ("kickoff", "blue", False)),
           (_gc(R.NORMAL_START, 3, 3.0, designated_position=at), ("kickoff", "blue", True)),
           (_gc(R.NORMAL_START, 3, 3.1, designated_position=at), ("kickoff", "blue", True))]  # fmt: skip
    for data, want in seq:
        g = r.read(data)
        assert (g.command, g.for_team, g.ready) == want
    r.ball_moved()
    assert r.read(_gc(R.NORMAL_START, 3, 3.5)).command == msg.RefereeCommand.NORMAL
    g = r.read(_gc(R.INDIRECT_FREE_YELLOW, 4, 9.0, stage=R.EXTRA_FIRST_HALF, blue_team_on_positive_half=True))
    assert (g.command, g.for_team, g.stage, g.blue_defends_negative_x) == ("free_kick", "yellow", "first_half", False)
    assert math.isinf(g.stage_time_left_s) and g.placement is None
    g = r.read(_gc(R.PREPARE_PENALTY_YELLOW, 5, 10.0, stage=R.PENALTY_SHOOTOUT_BREAK))
    assert (g.command, g.for_team, g.ready, g.stage) == ("penalty", "yellow", False, "half_time")
    assert (r.read(_gc(R.NORMAL_START, 6, 11.0)).command, r.read(_gc(R.STOP, 7, 12.0)).command) == ("penalty", "stop")
    # a normal start after a stop: normal play
    assert r.read(_gc(R.NORMAL_START, 8, 13.0)).command == msg.RefereeCommand.NORMAL


def _ball_at(x: float, y: float) -> msg.WorldState:
    return msg.WorldState(0.0, msg.BallState(x, y, 0.0, 0.0, True), ())


@pytest.mark.parametrize("prepare_at", [(0.0, 0.0), None], ids=["prepare-says-the-spot", "no-spot-at-all"])
def test_a_game_controllers_normal_start_without_designated_position_ends_when_the_ball_moves(
        prepare_at: tuple[float, float] | None) -> None:
    """A game controller clears designated_position at NORMAL_START: the kickoff still ends by the
    ball moving the rules' ball-in-play distance (0.05 m) from its spot, and not before."""
    queue = DatagramQueue()
    stage = RefereeInStage(load_settings().protocols, "world/blue", 0.05, receiver=queue)
    states: list[msg.GameState] = []
    spot = {} if prepare_at is None else {"designated_position": R.Point(x=prepare_at[0], y=prepare_at[1])}
    queue.push(_gc(R.PREPARE_KICKOFF_BLUE, 2, 2.0, **spot))
    queue.push(_gc(R.NORMAL_START, 3, 3.0))  # no designated position, no ball_in_play: the league's fields
    stage.on_message("clock", msg.Tick(0), lambda _t, g: states.append(g))
    assert [(g.command, g.ready, g.placement) for g in states] == [
        ("kickoff", False, prepare_at), ("kickoff", True, None)]
    for x in (0.0, 0.02, 0.049):  # the ball resting on the mark, nudged less than 0.05 m
        stage.on_message("world/blue", _ball_at(x, 0.0), lambda _t, g: states.append(g))
    assert len(states) == 2
    stage.on_message("world/blue", _ball_at(0.04, 0.035), lambda _t, g: states.append(g))  # 0.053 m away
    assert len(states) == 3 and states[-1].command == msg.RefereeCommand.NORMAL and stage.restarts_taken == 1
    queue.push(_gc(R.NORMAL_START, 3, 3.1))  # the start repeated: play stays normal
    stage.on_message("clock", msg.Tick(1), lambda _t, g: states.append(g))
    assert states[-1].command == msg.RefereeCommand.NORMAL


@pytest.mark.parametrize("data", [b"\x08", b"garbage\xff\xff", _gc(R.HALT, 1, 1.0)[:-3]])
def test_garbage_and_cut_short_packets_are_message_errors(data: bytes) -> None:
    with pytest.raises(msg.MessageError):
        RefereeReader().read(data)


@pytest.mark.skipif(shutil.which("protoc") is None, reason="Debian's protoc (protobuf-compiler) decodes independently")
def test_referee_bytes_decode_with_protoc() -> None:
    schema = str((PROTO_DIR / "ssl_referee.proto").relative_to(ROOT))
    out = subprocess.run(["protoc", f"-I{ROOT}", "--decode=cmdragons.league.Referee", schema],
                         input=referee_packet(FULL), capture_output=True, check=True).stdout.decode()
    for line in ("command: BALL_PLACEMENT_BLUE", "stage: NORMAL_SECOND_HALF", "x: -2000", "foul_counter: 6"):
        assert line in out, (line, out)


@pytest.mark.slow
def test_a_match_plays_to_our_referees_packets_over_loopback(udp_port: int) -> None:
    settings = load_settings(None, [f"protocols.referee.port={udp_port}", "protocols.referee.send=true",
                                    "protocols.referee.source=game_controller"])
    sent: list[msg.GameState] = []
    got: list[msg.GameState] = []
    taps = [Tap("sent", ("referee",), lambda _t, g: sent.append(g)),
            Tap("got", ("referee/gc",), lambda _t, g: got.append(g))]
    match = Match(settings, "simple", "vision", seed=2, extra=taps)
    try:
        summary = match.run(1.0)
    finally:
        match.close()
    assert summary["protocols"]["ssl/referee_in"]["dropped"] == {}
    assert summary["protocols"]["ssl/referee_out"]["packets"] == len(sent) > 60
    first_at: dict[float, msg.GameState] = {}
    for g in got:
        first_at.setdefault(round(g.t, 6), g)
    assert len(first_at) >= len(sent) - 1  # the last frame's word goes out after the last tick
    for s in sent[: len(first_at)]:
        _same(s.to_dict(), first_at[round(s.t, 6)].to_dict())
