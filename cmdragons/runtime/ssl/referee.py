"""The game controller's Referee message <-> our :class:`GameState`: the one place that maps them.

Times go as microseconds: the packet's and the command's in Unix time, as the game controller sends
them (our match time and a :class:`~cmdragons.runtime.ssl.clock.UnixEpoch`), durations as they
are; the designated position as millimetres. Our commands name the team apart; the league's
carry it (``DIRECT_FREE_BLUE``). A kickoff or penalty whose normal start is given is
``NORMAL_START`` after its ``PREPARE_...``: our referee adds which restart it starts (field 101) and
whether it judges the ball in play already (field 100); from a game controller, which sends neither,
:class:`RefereeReader` keeps the last prepare command and reads the normal start as that restart
taken, until :meth:`RefereeReader.ball_moved` says the ball is in play. Extra time is not played
here: its halves read as halves and every break as half time.
"""

from __future__ import annotations

import math
from typing import Any

from google.protobuf.message import DecodeError

from cmdragons.geometry import Team
from cmdragons.messages import GameStage, GameState, MessageError, RefereeCommand, TeamInfo
from cmdragons.runtime.proto import ssl_referee_pb2 as ref_pb
from cmdragons.runtime.ssl.clock import UnixEpoch, run_epoch

__all__ = ["RefereeReader", "referee_packet", "referee_proto"]

US = 1e6  # microseconds a second
MM = 1000.0
R = ref_pb.Referee
C, S = RefereeCommand, GameStage

# (our command, its team) <-> the league's command; kickoff and penalty as their prepare commands
_TEAM_COMMANDS: dict[tuple[RefereeCommand, Team], Any] = {
    (C.KICKOFF, "yellow"): R.PREPARE_KICKOFF_YELLOW, (C.KICKOFF, "blue"): R.PREPARE_KICKOFF_BLUE,
    (C.PENALTY, "yellow"): R.PREPARE_PENALTY_YELLOW, (C.PENALTY, "blue"): R.PREPARE_PENALTY_BLUE,
    (C.FREE_KICK, "yellow"): R.DIRECT_FREE_YELLOW, (C.FREE_KICK, "blue"): R.DIRECT_FREE_BLUE,
    (C.TIMEOUT, "yellow"): R.TIMEOUT_YELLOW, (C.TIMEOUT, "blue"): R.TIMEOUT_BLUE,
    (C.BALL_PLACEMENT, "yellow"): R.BALL_PLACEMENT_YELLOW, (C.BALL_PLACEMENT, "blue"): R.BALL_PLACEMENT_BLUE,
}
_PLAIN = {C.HALT: R.HALT, C.STOP: R.STOP, C.NORMAL: R.NORMAL_START, C.FORCE_START: R.FORCE_START}
_FROM_LEAGUE: dict[int, tuple[RefereeCommand, Team | None]] = {
    **{v: k for k, v in _TEAM_COMMANDS.items()}, **{v: (k, None) for k, v in _PLAIN.items()},
    R.INDIRECT_FREE_YELLOW: (C.FREE_KICK, "yellow"), R.INDIRECT_FREE_BLUE: (C.FREE_KICK, "blue"),
    R.GOAL_YELLOW: (C.STOP, None), R.GOAL_BLUE: (C.STOP, None),  # deprecated: the game stopped for a goal
}
_PREPARED = (C.KICKOFF, C.PENALTY)  # the commands a normal start starts
_STAGE_TO = {S.PRE_GAME: R.NORMAL_FIRST_HALF_PRE, S.FIRST_HALF: R.NORMAL_FIRST_HALF, S.HALF_TIME: R.NORMAL_HALF_TIME,
             S.SECOND_HALF: R.NORMAL_SECOND_HALF, S.PENALTY_SHOOTOUT: R.PENALTY_SHOOTOUT,
             S.POST_GAME: R.POST_GAME}
_STAGE_FROM = {**{v: k for k, v in _STAGE_TO.items()},
               R.NORMAL_SECOND_HALF_PRE: S.HALF_TIME, R.EXTRA_TIME_BREAK: S.HALF_TIME,
               R.EXTRA_FIRST_HALF_PRE: S.HALF_TIME, R.EXTRA_FIRST_HALF: S.FIRST_HALF,
               R.EXTRA_HALF_TIME: S.HALF_TIME, R.EXTRA_SECOND_HALF_PRE: S.HALF_TIME,
               R.EXTRA_SECOND_HALF: S.SECOND_HALF, R.PENALTY_SHOOTOUT_BREAK: S.HALF_TIME}


def _us(seconds: float) -> int:
    return round(seconds * US)


def _command_code(command: RefereeCommand, team: Team | None) -> Any:
    if command in _PLAIN:
        return _PLAIN[command]
    if team is None:
        raise MessageError(f"game command {command} needs the team it is for")
    return _TEAM_COMMANDS[(command, team)]


def _team_to(info: TeamInfo, score: int, name: str, into: Any) -> None:
    into.name, into.score, into.red_cards, into.yellow_cards = name, score, info.red_cards, info.yellow_cards
    into.yellow_card_times.extend(_us(t) for t in info.yellow_card_times_s)
    into.timeouts, into.timeout_time, into.goalkeeper = info.timeouts, _us(info.timeout_time_s), info.goalkeeper
    into.foul_counter, into.ball_placement_failures = info.fouls, info.placement_failures
    into.can_place_ball, into.max_allowed_bots = info.can_place_ball, info.max_robots


def _team_from(m: Any) -> TeamInfo:
    d = TeamInfo()
    return TeamInfo(m.red_cards, m.yellow_cards, tuple(t / US for t in m.yellow_card_times), m.foul_counter,
                    m.goalkeeper, m.timeouts, m.timeout_time / US, m.ball_placement_failures,
                    m.can_place_ball if m.HasField("can_place_ball") else d.can_place_ball,
                    m.max_allowed_bots if m.HasField("max_allowed_bots") else d.max_robots)


def referee_proto(g: GameState, source: str = "cmdragons", names: tuple[str, str] = ("blue", "yellow"),
                  epoch: UnixEpoch | None = None) -> Any:
    """The league's Referee message of our game state (``names``: the blue and yellow teams'), its
    times in Unix time (``epoch``, by default the run's)."""
    e = run_epoch() if epoch is None else epoch
    ready_start = g.command in _PREPARED and g.ready
    code = R.NORMAL_START if ready_start else _command_code(g.command, g.for_team)
    m = R(packet_timestamp=e.to_unix_us(g.t), stage=_STAGE_TO[g.stage], command=code,
          command_counter=g.command_counter, command_timestamp=e.to_unix_us(g.command_t),
          blue_team_on_positive_half=not g.blue_defends_negative_x, source_identifier=source)
    _team_to(g.blue_team, g.score_blue, names[0], m.blue)
    _team_to(g.yellow_team, g.score_yellow, names[1], m.yellow)
    if math.isfinite(g.stage_time_left_s):
        m.stage_time_left = _us(g.stage_time_left_s)
    if math.isfinite(g.action_time_left_s):
        m.current_action_time_remaining = _us(g.action_time_left_s)
    if g.placement is not None:
        m.designated_position.x, m.designated_position.y = g.placement[0] * MM, g.placement[1] * MM
    if g.next_command is not None and (g.next_command in _PLAIN or g.next_for_team is not None):
        m.next_command = _command_code(g.next_command, g.next_for_team)
    if code == R.NORMAL_START:
        m.ball_in_play = not ready_start
        if ready_start:
            m.started = _command_code(g.command, g.for_team)
    return m


def referee_packet(g: GameState, source: str = "cmdragons", names: tuple[str, str] = ("blue", "yellow"),
                   epoch: UnixEpoch | None = None) -> bytes:
    """:func:`referee_proto`'s bytes."""
    m = referee_proto(g, source, names, epoch)
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


class RefereeReader:
    """Referee messages -> game states (in match time: the packets' Unix times less ``epoch``, by
    default the run's), remembering the last prepare command (what a normal start starts) and
    whether the ball has moved since."""

    def __init__(self, epoch: UnixEpoch | None = None) -> None:
        self.epoch = run_epoch() if epoch is None else epoch
        self._prepared: tuple[RefereeCommand, Team] | None = None  # kickoff or penalty and its team
        self._in_play = False
        self.last: GameState | None = None

    def ball_moved(self) -> None:
        """The ball is in play (the restart of a normal start was taken): normal play from now on."""
        self._in_play = True

    def read(self, data: bytes | Any) -> GameState:
        """The game state of a Referee message (bytes or the parsed message); :class:`MessageError`
        for bytes that are not one."""
        if isinstance(data, bytes | bytearray):
            m = R()
            try:
                m.ParseFromString(bytes(data))
            except DecodeError as exc:
                raise MessageError(f"not a Referee message: {exc}") from None
        else:
            m = data
        if m.command not in _FROM_LEAGUE:
            raise MessageError(f"unknown referee command code {m.command}")
        if m.stage not in _STAGE_FROM:
            raise MessageError(f"unknown referee stage code {m.stage}")
        command, team = _FROM_LEAGUE[m.command]
        ready = True
        if command in _PREPARED:
            ready = False
            if self._prepared != (command, team):
                self._in_play = False
            assert team is not None
            self._prepared = (command, team)
        elif m.command == R.NORMAL_START:
            if m.HasField("started") and m.started in _FROM_LEAGUE:
                kind, started_for = _FROM_LEAGUE[m.started]
                if kind in _PREPARED and started_for is not None:
                    self._prepared = (kind, started_for)
            if m.HasField("ball_in_play"):
                self._in_play = m.ball_in_play
            if self._prepared is not None and not self._in_play:
                command, team = self._prepared
        else:
            self._prepared, self._in_play = None, False
        nxt: tuple[RefereeCommand | None, Team | None] = (None, None)
        if m.HasField("next_command") and m.next_command in _FROM_LEAGUE:
            nxt = _FROM_LEAGUE[m.next_command]
        p = m.designated_position
        self.last = GameState(
            self.epoch.from_unix_us(m.packet_timestamp), command, team, m.blue.score, m.yellow.score,
            not m.blue_team_on_positive_half,
            (p.x / MM, p.y / MM) if m.HasField("designated_position") else None, ready, _STAGE_FROM[m.stage],
            m.stage_time_left / US if m.HasField("stage_time_left") else math.inf, m.command_counter,
            self.epoch.from_unix_us(m.command_timestamp),
            m.current_action_time_remaining / US if m.HasField("current_action_time_remaining") else math.inf,
            nxt[0], nxt[1], _team_from(m.blue), _team_from(m.yellow))
        return self.last
