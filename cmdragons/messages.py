"""What crosses stage and process boundaries.

Every message is a frozen dataclass with ``to_dict``/``from_dict`` (the JSONL forms of DESIGN.md:
metres, radians, team as "blue"/"yellow"). Their protobuf forms, for the bus and the logs, are
the runtime's (:mod:`cmdragons.runtime.wire`).
"""

from __future__ import annotations

import base64
import binascii
import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any, Self, TypeVar

import numpy as np
from numpy.typing import NDArray

from cmdragons.geometry import TEAMS, Team

__all__ = [
    "BallDetection",
    "BallOut",
    "BallState",
    "BallTruth",
    "CameraFrame",
    "Contact",
    "DetectionFrame",
    "Event",
    "Fact",
    "FactEstimate",
    "GameEvent",
    "GameEvents",
    "GameStage",
    "GameState",
    "Goal",
    "GroundTruth",
    "Kick",
    "KickPurpose",
    "MessageError",
    "RefereeCommand",
    "NodeControl",
    "PhysicsFacts",
    "RobotCommand",
    "RobotDetection",
    "PassReport",
    "RobotReport",
    "RobotState",
    "RobotTruth",
    "SimEvents",
    "StageSummary",
    "TeamCommands",
    "TeamInfo",
    "TeamReport",
    "Teleport",
    "Tick",
    "Timing",
    "WorldState",
]


class MessageError(ValueError):
    """A message that cannot be decoded or read from its dict form."""


def _team(team: Any) -> Team:
    if team not in TEAMS:
        raise MessageError(f"team must be 'blue' or 'yellow', got {team!r}")
    return team  # type: ignore[no-any-return]


def _f(d: Mapping[str, Any], key: str, default: float | None = None) -> float:
    try:
        value = d[key]
    except KeyError:
        if default is None:
            raise MessageError(f"missing key {key!r}") from None
        return default
    if value is None:
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        raise MessageError(f"{key!r} must be a number, got {value!r}") from None


def _pixel(value: Any) -> tuple[float, float]:
    if value is None:
        return (math.nan, math.nan)
    try:
        u, v = value
        return (float(u), float(v))
    except (TypeError, ValueError):
        raise MessageError(f"pixel must be [u, v], got {value!r}") from None


def _num(x: float) -> float | None:
    """JSON has no NaN: unknown numbers are written as null."""
    return None if math.isnan(x) else x


def _finite(x: float) -> float | None:
    """JSON has no infinity either: no limit is written as null."""
    return x if math.isfinite(x) else None


# --- detections ------------------------------------------------------------------------------


@dataclass(frozen=True)
class BallDetection:
    x: float
    y: float
    confidence: float
    pixel: tuple[float, float]
    # the position's standard deviation per axis (m) as vision judges this view (a ball partly
    # hidden or cut by the image's edge is less certain); NaN: not known, the tracker's configured one
    sigma_m: float = math.nan


@dataclass(frozen=True)
class RobotDetection:
    team: Team
    id: int
    x: float
    y: float
    theta: float
    confidence: float
    pixel: tuple[float, float]


@dataclass(frozen=True)
class DetectionFrame:
    """One camera frame's detections: the content of an SSL-Vision detection packet."""

    camera_id: int
    frame_number: int
    t_capture: float
    t_sent: float
    balls: tuple[BallDetection, ...] = ()
    robots: tuple[RobotDetection, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {
            "camera_id": self.camera_id,
            "frame_number": self.frame_number,
            "t_capture": self.t_capture,
            "t_sent": self.t_sent,
            "balls": [
                {"x": b.x, "y": b.y, "confidence": b.confidence, "pixel": [b.pixel[0], b.pixel[1]]}
                | ({"sigma": b.sigma_m} if math.isfinite(b.sigma_m) else {})
                for b in self.balls
            ],
            "robots": [
                {"team": r.team, "id": r.id, "x": r.x, "y": r.y, "theta": r.theta,
                 "confidence": r.confidence, "pixel": [r.pixel[0], r.pixel[1]]}
                for r in self.robots
            ],
        }  # fmt: skip

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(
                camera_id=int(d["camera_id"]),
                frame_number=int(d["frame_number"]),
                t_capture=_f(d, "t_capture"),
                t_sent=_f(d, "t_sent", default=_f(d, "t_capture")),
                balls=tuple(
                    BallDetection(_f(b, "x"), _f(b, "y"), _f(b, "confidence", 1.0), _pixel(b.get("pixel")),
                                  _f(b, "sigma", math.nan))
                    for b in d.get("balls", ())
                ),
                robots=tuple(
                    RobotDetection(_team(r["team"]), int(r["id"]), _f(r, "x"), _f(r, "y"), _f(r, "theta"),
                                   _f(r, "confidence", 1.0), _pixel(r.get("pixel")))
                    for r in d.get("robots", ())
                ),
            )
        except (KeyError, TypeError, AttributeError) as exc:
            raise MessageError(f"bad detection frame: {exc!r}") from None

# --- tracked world state ----------------------------------------------------------------------


@dataclass(frozen=True)
class BallState:
    x: float
    y: float
    vx: float
    vy: float
    visible: bool = True
    covariance: NDArray[np.float64] | None = field(default=None, compare=False, repr=False)  # in memory only


@dataclass(frozen=True)
class RobotState:
    team: Team
    id: int
    x: float
    y: float
    theta: float
    vx: float = 0.0
    vy: float = 0.0
    omega: float = 0.0
    visible: bool = True


@dataclass(frozen=True)
class WorldState:
    """The tracker's estimate at time ``t`` (s); ``ball`` is None until a ball was ever seen."""

    t: float
    ball: BallState | None
    robots: tuple[RobotState, ...] = ()
    frame_number: int = 0  # the camera frame the state was estimated from

    def robot(self, team: Team, robot_id: int) -> RobotState | None:
        for r in self.robots:
            if r.team == team and r.id == robot_id:
                return r
        return None

    def to_dict(self) -> dict[str, Any]:
        b = self.ball
        return {
            "t": self.t,
            "frame_number": self.frame_number,
            "ball": None if b is None else {"x": b.x, "y": b.y, "vx": b.vx, "vy": b.vy, "visible": b.visible},
            "robots": [
                {"team": r.team, "id": r.id, "x": r.x, "y": r.y, "theta": r.theta, "vx": r.vx, "vy": r.vy,
                 "omega": r.omega, "visible": r.visible}
                for r in self.robots
            ],
        }  # fmt: skip

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            b = d.get("ball")
            ball = None if b is None else BallState(_f(b, "x"), _f(b, "y"), _f(b, "vx", 0.0), _f(b, "vy", 0.0),
                                                     bool(b.get("visible", True)))
            robots = tuple(
                RobotState(_team(r["team"]), int(r["id"]), _f(r, "x"), _f(r, "y"), _f(r, "theta"),
                           _f(r, "vx", 0.0), _f(r, "vy", 0.0), _f(r, "omega", 0.0), bool(r.get("visible", True)))
                for r in d.get("robots", ())
            )
            return cls(_f(d, "t"), ball, robots, int(d.get("frame_number", 0)))
        except (KeyError, TypeError, AttributeError) as exc:
            raise MessageError(f"bad world state: {exc!r}") from None

# --- commands ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class RobotCommand:
    """Velocity command for one robot: vx, vy in the field frame (m/s), omega (rad/s); a kick of
    ``kick_speed`` m/s fires when the ball touches the front (0 = kicker off); ``dribbler`` is the
    dribbler power from 0 (off) to 1."""

    team: Team
    id: int
    vx: float = 0.0
    vy: float = 0.0
    omega: float = 0.0
    kick_speed: float = 0.0
    chip: bool = False
    dribbler: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"team": self.team, "id": self.id, "vx": _num(self.vx), "vy": _num(self.vy),
                "omega": _num(self.omega), "kick_speed": _num(self.kick_speed), "chip": self.chip,
                "dribbler": _num(self.dribbler)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(_team(d["team"]), int(d["id"]), _f(d, "vx", 0.0), _f(d, "vy", 0.0), _f(d, "omega", 0.0),
                       _f(d, "kick_speed", 0.0), bool(d.get("chip", False)), _f(d, "dribbler", 0.0))
        except (KeyError, TypeError, AttributeError) as exc:
            raise MessageError(f"bad robot command: {exc!r}") from None

# --- ground truth (simulator only) -----------------------------------------------------------


@dataclass(frozen=True)
class BallTruth:
    x: float
    y: float
    z: float
    vx: float
    vy: float
    vz: float = 0.0
    # per camera id: (u, v) of the ball centre and the fraction of its silhouette not occluded
    pixels: Mapping[int, tuple[float, float, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class RobotTruth:
    team: Team
    id: int
    x: float
    y: float
    theta: float
    vx: float
    vy: float
    omega: float
    # per camera id: (u, v) of the centre of the robot's top, for cameras whose image holds the whole top
    pixels: Mapping[int, tuple[float, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class GroundTruth:
    """The simulator's true state for one camera frame (what vision, tracking and safety are
    scored against)."""

    frame_number: int
    t: float
    ball: BallTruth
    robots: tuple[RobotTruth, ...] = ()

    def world(self) -> WorldState:
        """The truth as a world state: what a team with perfect perception would see (the simple
        opponent's input, scripted tests, benchmarks)."""
        b = self.ball
        return WorldState(self.t, BallState(b.x, b.y, b.vx, b.vy), tuple(
            RobotState(r.team, r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega) for r in self.robots),
            self.frame_number)

    def to_dict(self) -> dict[str, Any]:
        b = self.ball
        ball: dict[str, Any] = {"x": b.x, "y": b.y, "z": b.z, "vx": b.vx, "vy": b.vy, "vz": b.vz}
        if b.pixels:
            ball["cameras"] = {str(k): {"pixel": [u, v], "visible_fraction": f} for k, (u, v, f) in b.pixels.items()}
        robots = []
        for r in self.robots:
            rd: dict[str, Any] = {"team": r.team, "id": r.id, "x": r.x, "y": r.y, "theta": r.theta, "vx": r.vx,
                                  "vy": r.vy, "omega": r.omega}
            if r.pixels:
                rd["cameras"] = {str(k): {"pixel": [u, v]} for k, (u, v) in r.pixels.items()}
            robots.append(rd)
        return {"frame_number": self.frame_number, "t": self.t, "ball": ball, "robots": robots}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            b = d["ball"]
            ball = BallTruth(
                _f(b, "x"), _f(b, "y"), _f(b, "z", 0.0), _f(b, "vx", 0.0), _f(b, "vy", 0.0), _f(b, "vz", 0.0),
                {int(k): (*_pixel(c["pixel"]), float(c.get("visible_fraction", 1.0)))
                 for k, c in b.get("cameras", {}).items()},
            )
            robots = tuple(
                RobotTruth(_team(r["team"]), int(r["id"]), _f(r, "x"), _f(r, "y"), _f(r, "theta"),
                           _f(r, "vx", 0.0), _f(r, "vy", 0.0), _f(r, "omega", 0.0),
                           {int(k): _pixel(c["pixel"]) for k, c in r.get("cameras", {}).items()})
                for r in d.get("robots", ())
            )
            return cls(int(d["frame_number"]), _f(d, "t"), ball, robots)
        except (KeyError, TypeError, AttributeError, ValueError) as exc:
            raise MessageError(f"bad ground truth: {exc!r}") from None

# --- referee ------------------------------------------------------------------------------------

_E = TypeVar("_E", bound=StrEnum)


class RefereeCommand(StrEnum):
    """The league's Referee commands with the team named apart (each but halt, stop, normal and force
    start is for one team). The values are the JSONL forms."""

    HALT = "halt"
    STOP = "stop"
    KICKOFF = "kickoff"  # prepare kickoff (``ready`` once the normal start is given)
    FREE_KICK = "free_kick"  # direct free kick
    NORMAL = "normal"  # normal start, the ball in play
    FORCE_START = "force_start"
    PENALTY = "penalty"  # prepare penalty (``ready`` once the normal start is given)
    TIMEOUT = "timeout"
    BALL_PLACEMENT = "ball_placement"

    @property
    def kick_restart(self) -> bool:
        """A kickoff or free kick: one team's kick to take, the other's robots at the rules' distance."""
        return self in (RefereeCommand.KICKOFF, RefereeCommand.FREE_KICK)

    @property
    def running(self) -> bool:
        """Normal play: a normal start or a force start, the ball for both teams."""
        return self in (RefereeCommand.NORMAL, RefereeCommand.FORCE_START)

    @property
    def prepared(self) -> bool:
        """A kickoff or penalty: prepared, then started by a normal start (``GameState.ready``)."""
        return self in (RefereeCommand.KICKOFF, RefereeCommand.PENALTY)

    @property
    def halted(self) -> bool:
        """A halt or a timeout: no robot moves."""
        return self in (RefereeCommand.HALT, RefereeCommand.TIMEOUT)


class KickPurpose(StrEnum):
    """What the strategy kicks for (a team report's actions); the values are the JSONL forms and the
    match statistics' names."""

    SHOT = "shot"
    PASS = "pass"
    CLEAR = "clear"
    WAIT = "wait"  # no kick: the ball is theirs to play (in their defense area)


class GameStage(StrEnum):
    """The league's stages, pre-game and the breaks included (extra time is not played here); the
    values are the JSONL forms."""

    PRE_GAME = "pre_game"
    FIRST_HALF = "first_half"
    HALF_TIME = "half_time"
    SECOND_HALF = "second_half"
    PENALTY_SHOOTOUT = "penalty_shootout"
    POST_GAME = "post_game"


def _member(kind: type[_E], value: object, what: str) -> _E:
    """``value`` as a member of ``kind`` (its member or its JSONL form), else a :class:`MessageError`."""
    try:
        return kind(value)  # type: ignore[arg-type]  # (a member, or a value to look up)
    except ValueError:
        raise MessageError(f"{what} must be one of {', '.join(kind)}, got {value!r}") from None


@dataclass(frozen=True)
class TeamInfo:
    """One team as the league's Referee message has it (the score is the game state's own)."""

    red_cards: int = 0
    yellow_cards: int = 0  # given in the match so far
    yellow_card_times_s: tuple[float, ...] = ()  # time left on each card still running (s)
    fouls: int = 0
    goalkeeper: int = 0  # the robot id the rules treat as the keeper
    timeouts: int = 4  # timeouts left
    timeout_time_s: float = 300.0  # timeout time left (s)
    placement_failures: int = 0
    can_place_ball: bool = True
    max_robots: int = 11  # robots allowed on the field now (the division's count less the cards running)

    def to_dict(self) -> dict[str, Any]:
        return {"red_cards": self.red_cards, "yellow_cards": self.yellow_cards,
                "yellow_card_times": list(self.yellow_card_times_s), "fouls": self.fouls,
                "goalkeeper": self.goalkeeper, "timeouts": self.timeouts, "timeout_time": self.timeout_time_s,
                "placement_failures": self.placement_failures, "can_place_ball": self.can_place_ball,
                "max_robots": self.max_robots}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        return cls(int(d.get("red_cards", 0)), int(d.get("yellow_cards", 0)),
                   tuple(float(v) for v in d.get("yellow_card_times", ())), int(d.get("fouls", 0)),
                   int(d.get("goalkeeper", 0)), int(d.get("timeouts", 4)), _f(d, "timeout_time", 300.0),
                   int(d.get("placement_failures", 0)), bool(d.get("can_place_ball", True)),
                   int(d.get("max_robots", 11)))


@dataclass(frozen=True)
class GameState:
    """The referee's word at time ``t``, what the league's Referee message carries: the command in
    force and for which team (``ready``: a kickoff's or penalty's normal start is given), the score,
    which goal blue defends, the designated position (where the ball is, or is to be, placed for a
    restart), the stage and its time left, the command's counter and time, the next command, the
    time left for the current action (a restart to be taken, a placement), and each team's info."""

    t: float
    command: RefereeCommand = RefereeCommand.NORMAL
    for_team: Team | None = None  # the team the command is for (kickoff, free kick, penalty, placement, timeout)
    score_blue: int = 0
    score_yellow: int = 0
    blue_defends_negative_x: bool = True
    placement: tuple[float, float] | None = None  # the designated position (field frame, m)
    ready: bool = True  # kickoff or penalty: the normal start is given, the kicker may play the ball
    stage: GameStage = GameStage.FIRST_HALF
    stage_time_left_s: float = math.inf
    command_counter: int = 0
    command_t: float = 0.0  # when the command was given (s)
    action_time_left_s: float = math.inf  # time left to take the restart or place the ball (s)
    next_command: RefereeCommand | None = None  # what follows a placement or a stop, when known
    next_for_team: Team | None = None
    blue_team: TeamInfo = TeamInfo()
    yellow_team: TeamInfo = TeamInfo()

    def __post_init__(self) -> None:
        # the JSONL forms are taken too (a scripted scene's "stop"): held as the members
        object.__setattr__(self, "command", _member(RefereeCommand, self.command, "game command"))
        if self.next_command is not None:
            object.__setattr__(self, "next_command", _member(RefereeCommand, self.next_command, "next command"))
        object.__setattr__(self, "stage", _member(GameStage, self.stage, "game stage"))

    def team_info(self, team: Team) -> TeamInfo:
        return self.blue_team if team == "blue" else self.yellow_team

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "command": self.command, "for_team": self.for_team,
                "score": {"blue": self.score_blue, "yellow": self.score_yellow},
                "blue_defends": "negative_x" if self.blue_defends_negative_x else "positive_x",
                "placement": None if self.placement is None else list(self.placement),
                "ready": self.ready, "stage": self.stage, "stage_time_left": _finite(self.stage_time_left_s),
                "command_counter": self.command_counter, "command_t": self.command_t,
                "action_time_left": _finite(self.action_time_left_s), "next_command": self.next_command,
                "next_for_team": self.next_for_team,
                "teams": {"blue": self.blue_team.to_dict(), "yellow": self.yellow_team.to_dict()}}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            team = d.get("for_team")
            placement = d.get("placement")
            nxt = d.get("next_for_team")
            teams = d.get("teams", {})
            stage_left, action_left = d.get("stage_time_left", math.inf), d.get("action_time_left", math.inf)
            return cls(
                _f(d, "t"), RefereeCommand(str(d.get("command", "normal"))), None if team is None else _team(team),
                int(d.get("score", {}).get("blue", 0)), int(d.get("score", {}).get("yellow", 0)),
                d.get("blue_defends", "negative_x") == "negative_x",
                None if placement is None else (float(placement[0]), float(placement[1])),
                bool(d.get("ready", True)), GameStage(str(d.get("stage", "first_half"))),
                math.inf if stage_left is None else float(stage_left), int(d.get("command_counter", 0)),
                float(d.get("command_t", 0.0)), math.inf if action_left is None else float(action_left),
                d.get("next_command"), None if nxt is None else _team(nxt),
                TeamInfo.from_dict(teams.get("blue", {})), TeamInfo.from_dict(teams.get("yellow", {})),
            )
        except (KeyError, TypeError, AttributeError, ValueError, IndexError) as exc:
            raise MessageError(f"bad game state: {exc!r}") from None


@dataclass(frozen=True)
class GameEvent:
    """One call of the referee: a foul (``kind`` as the rules name it: "crash", "ball_too_fast", ...),
    a card, a placement's end, a stage's change. ``team`` and ``robot``: who committed it (None when
    no one); ``value`` the figure that broke the rule and ``limit`` the rule's, in ``unit``;
    ``restart``: the command play goes on with (a free kick, a penalty; None when the call does not
    change it)."""

    t: float
    kind: str
    team: Team | None = None
    robot: int | None = None
    value: float = math.nan
    limit: float = math.nan
    unit: str = ""
    restart: RefereeCommand | None = None  # "" in the JSONL and protobuf forms
    for_team: Team | None = None  # the team the restart is for

    def __post_init__(self) -> None:
        if self.restart is not None:
            restart = _member(RefereeCommand, self.restart, "a call's restart") if self.restart else None
            object.__setattr__(self, "restart", restart)

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "kind": self.kind, "team": self.team, "robot": self.robot, "value": _num(self.value),
                "limit": _num(self.limit), "unit": self.unit, "restart": self.restart or "",
                "for_team": self.for_team}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            team, robot, for_team = d.get("team"), d.get("robot"), d.get("for_team")
            return cls(_f(d, "t"), str(d["kind"]), None if team is None else _team(team),
                       None if robot is None else int(robot), _f(d, "value", math.nan), _f(d, "limit", math.nan),
                       str(d.get("unit", "")), RefereeCommand(str(d["restart"])) if d.get("restart") else None,
                       None if for_team is None else _team(for_team))
        except (KeyError, TypeError, ValueError) as exc:
            raise MessageError(f"bad game event: {exc!r}") from None


@dataclass(frozen=True)
class GameEvents:
    """The referee's calls of one frame (topic ``referee/events``)."""

    t: float
    events: tuple[GameEvent, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "events": [e.to_dict() for e in self.events]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(_f(d, "t"), tuple(GameEvent.from_dict(e) for e in d.get("events", ())))
        except (TypeError, AttributeError) as exc:
            raise MessageError(f"bad game events: {exc!r}") from None


# --- simulator events --------------------------------------------------------------------------


@dataclass(frozen=True)
class Goal:
    t: float
    scoring_team: Team
    x: float
    y: float


@dataclass(frozen=True)
class BallOut:
    t: float
    x: float  # where the ball crossed the line
    y: float
    last_touch: Team | None


@dataclass(frozen=True)
class Kick:
    t: float
    team: Team
    id: int
    speed_m_s: float
    chip: bool


@dataclass(frozen=True)
class Contact:
    """One robot-robot contact, from first touch to separation."""

    t_start: float
    duration_s: float
    a: tuple[Team, int]
    b: tuple[Team, int]
    max_depth_m: float  # deepest interpenetration seen
    relative_speed_m_s: float  # closing speed along the contact normal at first touch
    # two robots of one team: the first robot of the other team seen touching either of them during
    # the contact (it pushed one into the other), else None
    pushed_by: tuple[Team, int] | None = None


Event = Goal | BallOut | Kick | Contact
_EVENT_TYPES: dict[str, type[Any]] = {"goal": Goal, "ballout": BallOut, "kick": Kick, "contact": Contact}


def _event_dict(e: Event) -> dict[str, Any]:
    d: dict[str, Any] = {"type": type(e).__name__.lower()}
    for f in dataclasses.fields(e):
        v = getattr(e, f.name)
        d[f.name] = list(v) if isinstance(v, tuple) else v
    return d


def _event_from_dict(d: Mapping[str, Any]) -> Event:
    cls = _EVENT_TYPES.get(str(d.get("type")))
    if cls is None:
        raise MessageError(f"unknown event type {d.get('type')!r}")
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name not in d and f.default is not dataclasses.MISSING:
            continue  # an optional field a log from before it was added does not have
        v = d[f.name]
        kwargs[f.name] = (_team(v[0]), int(v[1])) if f.name in ("a", "b", "pushed_by") and v is not None else v
    return cls(**kwargs)  # type: ignore[no-any-return]


@dataclass(frozen=True)
class SimEvents:
    """What happened in one simulated frame (published after the physics stepped it): its events and
    where the ball lies now, before any restart moves it (what a referee judges)."""

    frame_number: int
    t: float
    ball_xy: tuple[float, float]
    events: tuple[Event, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"frame_number": self.frame_number, "t": self.t, "ball": list(self.ball_xy),
                "events": [_event_dict(e) for e in self.events]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            bx, by = d["ball"]
            return cls(int(d["frame_number"]), _f(d, "t"), (float(bx), float(by)),
                       tuple(_event_from_dict(e) for e in d.get("events", ())))
        except (KeyError, TypeError, ValueError) as exc:
            raise MessageError(f"bad simulator events: {exc!r}") from None


@dataclass(frozen=True)
class Teleport:
    """Objects the simulator puts in place at once (a restart's ball, a kickoff formation), in the
    order given: field frame, metres, radians."""

    t: float
    robots: tuple[tuple[Team, int, float, float, float], ...] = ()  # (team, id, x, y, theta)
    ball: tuple[float, float] | None = None  # placed after the robots, at rest

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "robots": [{"team": t, "id": i, "x": x, "y": y, "theta": th}
                                        for t, i, x, y, th in self.robots],
                "ball": None if self.ball is None else list(self.ball)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            ball = d.get("ball")
            return cls(_f(d, "t"), tuple((_team(r["team"]), int(r["id"]), _f(r, "x"), _f(r, "y"), _f(r, "theta"))
                                         for r in d.get("robots", ())),
                       None if ball is None else (float(ball[0]), float(ball[1])))
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise MessageError(f"bad teleport: {exc!r}") from None


# --- runtime messages --------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class CameraFrame:
    """One camera's image at one instant: BGR, uint8, (height, width, 3)."""

    camera_id: int
    frame_number: int
    t_capture: float
    image: NDArray[np.uint8] = field(repr=False)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, CameraFrame) and (self.camera_id, self.frame_number, self.t_capture)
                == (other.camera_id, other.frame_number, other.t_capture)
                and np.array_equal(self.image, other.image))

    __hash__ = None  # type: ignore[assignment]

    def to_dict(self) -> dict[str, Any]:
        """The image as raw bytes in base64 (``bgr8``, rows top to bottom)."""
        h, w = self.image.shape[:2]
        return {"camera_id": self.camera_id, "frame_number": self.frame_number, "t_capture": self.t_capture,
                "width": w, "height": h, "encoding": "bgr8",
                "data": base64.b64encode(np.ascontiguousarray(self.image).tobytes()).decode("ascii")}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            if d.get("encoding", "bgr8") != "bgr8":
                raise MessageError(f"camera frame encoding must be bgr8, got {d['encoding']!r}")
            w, h = int(d["width"]), int(d["height"])
            raw = np.frombuffer(base64.b64decode(d["data"]), dtype=np.uint8)
            if raw.size != w * h * 3:
                raise MessageError(f"camera frame holds {raw.size} bytes, not {w}x{h}x3")
            return cls(int(d["camera_id"]), int(d["frame_number"]), _f(d, "t_capture"), raw.reshape(h, w, 3).copy())
        except (KeyError, TypeError, ValueError, binascii.Error) as exc:
            raise MessageError(f"bad camera frame: {exc!r}") from None


@dataclass(frozen=True)
class Tick:
    """The clock: capture camera frame ``frame_number`` now (lock-step runs)."""

    frame_number: int

    def to_dict(self) -> dict[str, Any]:
        return {"frame_number": self.frame_number}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(int(d["frame_number"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise MessageError(f"bad tick: {exc!r}") from None


@dataclass(frozen=True)
class TeamCommands:
    """One team's commands for one camera frame: ``frame_number`` is the frame they answer, ``t`` the
    time of the world state they were decided on."""

    team: Team
    frame_number: int
    t: float
    commands: tuple[RobotCommand, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"team": self.team, "frame_number": self.frame_number, "t": self.t,
                "commands": [c.to_dict() for c in self.commands]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(_team(d["team"]), int(d["frame_number"]), _f(d, "t"),
                       tuple(RobotCommand.from_dict(c) for c in d.get("commands", ())))
        except (KeyError, TypeError, ValueError) as exc:
            raise MessageError(f"bad team commands: {exc!r}") from None


def _points(value: Any) -> NDArray[np.float64]:
    """Points (k, 2), field frame, m, as a float array (read from a list of [x, y])."""
    return np.asarray(value, dtype=np.float64).reshape(-1, 2)


def _no_points() -> NDArray[np.float64]:
    return np.zeros((0, 2))


@dataclass(frozen=True, eq=False)
class RobotReport:
    """What a brain did for one robot in one frame: the strategy's target, the planner's path and
    status, the command before safety and the braking path the safety search checked (points (k, 2),
    field frame, m)."""

    id: int
    status: str  # the planner's status ("solved", "direct", "halt", ...)
    target: tuple[float, float, float]  # (x, y, theta) the strategy asked for
    path: NDArray[np.float64] = field(default_factory=_no_points)
    command: RobotCommand | None = None  # before safety
    braking: NDArray[np.float64] = field(default_factory=_no_points)

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "status": self.status, "target": list(self.target),
                "path": np.asarray(self.path).tolist(), "braking": np.asarray(self.braking).tolist(),
                "command": None if self.command is None else self.command.to_dict()}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        c = d.get("command")
        x, y, th = d["target"]
        return cls(int(d["id"]), str(d.get("status", "")), (float(x), float(y), float(th)),
                   _points(d.get("path", ())), None if c is None else RobotCommand.from_dict(c),
                   _points(d.get("braking", ())))


@dataclass(frozen=True)
class PassReport:
    """The team's pass of a frame, as its strategy follows it: who passes to whom, the point the
    receiver takes the ball at (field frame, m), the one-touch aim there (None: the receiver traps
    the ball) and whether the ball is under way."""

    passer: int
    receiver: int
    target: tuple[float, float]
    shoot_at: tuple[float, float] | None = None
    kicked: bool = False

    def to_dict(self) -> dict[str, Any]:
        return {"passer": self.passer, "receiver": self.receiver, "target": list(self.target),
                "shoot_at": None if self.shoot_at is None else list(self.shoot_at), "kicked": self.kicked}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        x, y = d["target"]
        aim = d.get("shoot_at")
        return cls(int(d["passer"]), int(d["receiver"]), (float(x), float(y)),
                   None if aim is None else (float(aim[0]), float(aim[1])), bool(d.get("kicked", False)))


@dataclass(frozen=True, eq=False)
class TeamReport:
    """One team's brain in one frame, for statistics, overlays and logs: per robot what it did, each
    robot's last action as the strategy decided it (what its kick is for), and the pass evaluation's
    receiving points (n, 2) and values (n,) when it was redone this frame (empty in the frames
    between: the last one holds), and the pass planned or under way (None: none). Wall-clock times
    go on a topic of their own (:class:`Timing`)."""

    team: Team
    frame_number: int
    t: float
    robots: tuple[RobotReport, ...] = ()
    actions: Mapping[int, KickPurpose] = field(default_factory=dict)
    pass_points: NDArray[np.float64] = field(default_factory=_no_points)
    pass_values: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    passing: PassReport | None = None

    def __post_init__(self) -> None:  # the JSONL and protobuf forms come as their values
        actions = {rid: _member(KickPurpose, a, "a robot's action") for rid, a in self.actions.items()}
        object.__setattr__(self, "actions", actions)

    def robot(self, robot_id: int) -> RobotReport | None:
        return next((r for r in self.robots if r.id == robot_id), None)

    def to_dict(self) -> dict[str, Any]:
        return {"team": self.team, "frame_number": self.frame_number, "t": self.t,
                "robots": [r.to_dict() for r in self.robots],
                "actions": {str(k): v for k, v in self.actions.items()},
                "pass_points": np.asarray(self.pass_points).tolist(),
                "pass_values": np.asarray(self.pass_values).tolist(),
                "passing": None if self.passing is None else self.passing.to_dict()}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(_team(d["team"]), int(d["frame_number"]), _f(d, "t"),
                       tuple(RobotReport.from_dict(r) for r in d.get("robots", ())),
                       {int(k): KickPurpose(str(v)) for k, v in d.get("actions", {}).items()},
                       _points(d.get("pass_points", ())),
                       np.asarray(d.get("pass_values", ()), dtype=np.float64),
                       None if d.get("passing") is None else PassReport.from_dict(d["passing"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise MessageError(f"bad team report: {exc!r}") from None


@dataclass(frozen=True)
class Timing:
    """Wall-clock milliseconds of a stage's parts in one frame (never the same twice: logs that must
    be the same for the same seed leave this topic out)."""

    stage: str
    frame_number: int
    ms: Mapping[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"stage": self.stage, "frame_number": self.frame_number, "ms": dict(self.ms)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(str(d["stage"]), int(d["frame_number"]), {str(k): float(v) for k, v in d["ms"].items()})
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise MessageError(f"bad timing: {exc!r}") from None


# --- physics facts -----------------------------------------------------------------------------


class Fact(StrEnum):
    """A physical fact the tracker measures, named as in ``learn``."""

    BALL_ROLL = "ball_roll"
    BALL_SLIDE = "ball_slide"
    ROBOT_ACCEL = "robot_accel"
    ROBOT_BRAKE = "robot_brake"
    KICK_GAIN = "kick_gain"  # a ratio, not m/s²: the ball's launch speed over the kick asked
    KICK_RETENTION = "kick_retention"  # a share: the ball's velocity across the heading a kick keeps

    @property
    def source(self) -> str:
        """The configuration key the fact is configured at (field.yaml), as derived fields name it."""
        return _SOURCES[self]


_SOURCES = {
    Fact.BALL_ROLL: "field.ball.acc_roll_m_s2",
    Fact.BALL_SLIDE: "field.ball.acc_slide_m_s2",
    Fact.ROBOT_ACCEL: "field.robot.max_accel_m_s2",
    Fact.ROBOT_BRAKE: "field.robot.max_brake_m_s2",
    Fact.KICK_GAIN: "field.robot.kick_gain",
    Fact.KICK_RETENTION: "field.robot.kick_retention",
}


@dataclass(frozen=True)
class FactEstimate:
    """One fact as measured so far (m/s²): the median of ``samples`` windows, their spread as a
    standard deviation, and whether it is confident and used."""

    fact: Fact
    value_m_s2: float
    configured_m_s2: float
    samples: int
    spread_m_s2: float
    confident: bool
    used: bool

    def to_dict(self) -> dict[str, Any]:
        return {"fact": self.fact.value, "value_m_s2": _num(self.value_m_s2), "configured_m_s2": self.configured_m_s2,
                "samples": self.samples, "spread_m_s2": _num(self.spread_m_s2), "confident": self.confident,
                "used": self.used}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        def f(key: str) -> float:
            v = d.get(key)
            return math.nan if v is None else float(v)

        return cls(Fact(d["fact"]), f("value_m_s2"), f("configured_m_s2"), int(d["samples"]), f("spread_m_s2"),
                   bool(d["confident"]), bool(d["used"]))


@dataclass(frozen=True)
class PhysicsFacts:
    """What the tracker learnt of the physics by time ``t`` (s): one estimate per fact."""

    t: float
    estimates: tuple[FactEstimate, ...] = ()

    def in_use(self) -> dict[str, float]:
        """The used facts' values by the configuration key they replace (``field.ball.acc_roll_m_s2``)."""
        return {e.fact.source: e.value_m_s2 for e in self.estimates if e.used}

    def estimate(self, fact: Fact) -> FactEstimate | None:
        return next((e for e in self.estimates if e.fact == fact), None)

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "estimates": [e.to_dict() for e in self.estimates]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        return cls(float(d["t"]), tuple(FactEstimate.from_dict(e) for e in d.get("estimates", ())))

    def summary(self) -> dict[str, Any]:
        """The summary's figures: per fact its estimate (without the fact's name, which is the key)."""
        return {e.fact.value: {k: round(v, 4) if isinstance(v, float) else v for k, v in e.to_dict().items()
                               if k != "fact"} for e in self.estimates}


@dataclass(frozen=True)
class StageSummary:
    """A stage's figures at the end of a run (what summary.json gathers), as plain JSON values."""

    stage: str
    figures: Mapping[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"stage": self.stage, "figures": dict(self.figures)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(str(d["stage"]), dict(d.get("figures", {})))
        except (KeyError, TypeError, ValueError) as exc:
            raise MessageError(f"bad stage summary: {exc!r}") from None


@dataclass(frozen=True)
class NodeControl:
    """The distributed runtime's own word between nodes: a node says it is ``ready``; the match's
    clock says it is ``waiting`` for the others and tells every node to ``start`` (a free-running
    match: ``start_free_running``), ``summarize`` or ``stop``."""

    node: str
    command: str

    def to_dict(self) -> dict[str, Any]:
        return {"node": self.node, "command": self.command}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        try:
            return cls(str(d["node"]), str(d["command"]))
        except (KeyError, TypeError) as exc:
            raise MessageError(f"bad node control: {exc!r}") from None
