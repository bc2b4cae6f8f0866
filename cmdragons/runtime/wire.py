"""The wire format of the bus and the logs: every message as protobuf.

The schemas are ``cmdragons/runtime/proto/*.proto`` (the generated modules beside them are checked
in; ``python -m cmdragons.runtime.proto.generate`` rebuilds them and a test keeps them current).
Where the league has a message for the same thing, ours is it: a :class:`DetectionFrame` goes as the
league's ``SSL_DetectionFrame`` (millimetres), a :class:`WorldState` as its ``TrackedFrame``
(metres), a :class:`TeamCommands` as the simulation protocol's ``RobotControl`` (field-frame
velocities as ``MoveGlobalVelocity``); the rest are cmdragons' own (``cmdragons.proto``).

Those three carry 32-bit floats, so a message that crossed the wire is not the one sent to the last
bit. What a stage on another process would receive is what every stage receives:
:func:`canonical` passes detections and commands through their wire form, and the in-process
transport delivers them so, which keeps an embedded match and a distributed one the same.

:func:`schema` names a message's protobuf type; a transport sends it with the bytes (zenoh's encoding;
an MCAP channel's schema), and :func:`decode` reads bytes by it. So the wire keeps no list of
topics: which message a topic carries is the stages' contracts' word (runtime/topics.py), checked
when a set-up's table is built.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from cmdragons.geometry import Team
from cmdragons.messages import (
    BallDetection,
    BallOut,
    BallState,
    BallTruth,
    CameraFrame,
    Contact,
    DetectionFrame,
    Event,
    Fact,
    FactEstimate,
    GameEvent,
    GameEvents,
    GameStage,
    GameState,
    Goal,
    GroundTruth,
    Kick,
    MessageError,
    NodeControl,
    PassReport,
    PhysicsFacts,
    RefereeCommand,
    RobotCommand,
    RobotDetection,
    RobotReport,
    RobotState,
    RobotTruth,
    SimEvents,
    StageSummary,
    TeamCommands,
    TeamInfo,
    TeamReport,
    Teleport,
    Tick,
    Timing,
    WorldState,
)
from cmdragons.runtime.proto import cmdragons_pb2 as pb
from cmdragons.runtime.proto import ssl_detection_pb2 as det_pb
from cmdragons.runtime.proto import ssl_simulation_control_pb2 as ctl_pb
from cmdragons.runtime.proto import ssl_tracked_pb2 as trk_pb

__all__ = ["CODECS", "LOSSY", "Codec", "canonical", "canonical_and_chunks", "decode", "encode",
           "encode_chunks", "from_proto", "is_known", "parse", "schema", "to_proto"]

MM = 1000.0  # millimetres a metre: the league's vision speaks millimetres

_TEAM_PB = {"blue": trk_pb.BLUE, "yellow": trk_pb.YELLOW}
_PB_TEAM: dict[int, Team] = {trk_pb.BLUE: "blue", trk_pb.YELLOW: "yellow"}


def _team(code: int) -> Team:
    try:
        return _PB_TEAM[code]
    except KeyError:
        raise MessageError(f"team must be BLUE or YELLOW, got code {code}") from None


def _flat(points: Any) -> list[float]:
    out: list[float] = np.asarray(points, dtype=np.float64).ravel().tolist()
    return out


def _pairs(values: Any) -> np.ndarray[Any, np.dtype[np.float64]]:
    return np.asarray(values, dtype=np.float64).reshape(-1, 2)


# --- detections: SSL_DetectionFrame (mm) -----------------------------------------------------


def _detection_to(d: DetectionFrame) -> Any:
    m = det_pb.SSL_DetectionFrame(frame_number=d.frame_number, t_capture=d.t_capture, t_sent=d.t_sent,
                                  camera_id=d.camera_id)
    for b in d.balls:
        ball = m.balls.add(confidence=b.confidence, x=b.x * MM, y=b.y * MM, pixel_x=b.pixel[0], pixel_y=b.pixel[1])
        if math.isfinite(b.sigma_m):
            ball.position_sigma_mm = b.sigma_m * MM
    for r in d.robots:
        rows = m.robots_blue if r.team == "blue" else m.robots_yellow
        rows.add(confidence=r.confidence, robot_id=r.id, x=r.x * MM, y=r.y * MM, orientation=r.theta,
                 pixel_x=r.pixel[0], pixel_y=r.pixel[1])
    return m


def _rows_by_team(m: Any) -> tuple[tuple[Team, Any], tuple[Team, Any]]:
    return (("blue", m.robots_blue), ("yellow", m.robots_yellow))


def _detection_from(m: Any) -> DetectionFrame:
    balls = tuple(BallDetection(b.x / MM, b.y / MM, b.confidence, (b.pixel_x, b.pixel_y),
                                b.position_sigma_mm / MM if b.HasField("position_sigma_mm") else math.nan)
                  for b in m.balls)
    robots = tuple(RobotDetection(team, r.robot_id, r.x / MM, r.y / MM, r.orientation, r.confidence,
                                  (r.pixel_x, r.pixel_y))
                   for team, rows in _rows_by_team(m) for r in rows)
    return DetectionFrame(m.camera_id, m.frame_number, m.t_capture, m.t_sent, balls, robots)


# --- world state: TrackedFrame (m) -----------------------------------------------------------


def _world_to(w: WorldState) -> Any:
    m = trk_pb.TrackedFrame(frame_number=w.frame_number, timestamp=w.t)
    if w.ball is not None:
        b = w.ball
        m.balls.add(pos=trk_pb.Vector3(x=b.x, y=b.y, z=0.0), vel=trk_pb.Vector3(x=b.vx, y=b.vy, z=0.0),
                    visibility=1.0 if b.visible else 0.0)
    for r in w.robots:
        m.robots.add(robot_id=trk_pb.RobotId(id=r.id, team=_TEAM_PB[r.team]), pos=trk_pb.Vector2(x=r.x, y=r.y),
                     orientation=r.theta, vel=trk_pb.Vector2(x=r.vx, y=r.vy), vel_angular=r.omega,
                     visibility=1.0 if r.visible else 0.0)
    return m


def _world_from(m: Any) -> WorldState:
    ball = None
    if len(m.balls):
        b = m.balls[0]
        ball = BallState(b.pos.x, b.pos.y, b.vel.x, b.vel.y, b.visibility > 0.5)
    robots = tuple(RobotState(_team(r.robot_id.team), r.robot_id.id, r.pos.x, r.pos.y, r.orientation, r.vel.x,
                              r.vel.y, r.vel_angular, r.visibility > 0.5) for r in m.robots)
    return WorldState(m.timestamp, ball, robots, m.frame_number)


# --- commands: RobotControl --------------------------------------------------------------------


def _command_to(c: RobotCommand, into: Any) -> Any:
    into.id = c.id
    v = into.move_command.global_velocity
    v.vel_x, v.vel_y, v.vel_angular = c.vx, c.vy, c.omega
    into.kick_speed = c.kick_speed
    into.chip = c.chip
    into.dribbler_power = c.dribbler
    return into


def _command_from(m: Any, team: Team) -> RobotCommand:
    kind = m.move_command.WhichOneof("command")
    if kind not in (None, "global_velocity"):
        raise MessageError(f"robot {m.id}: only field-frame velocities (global_velocity) are understood, got {kind}")
    v = m.move_command.global_velocity
    chip = m.chip or (m.HasField("kick_angle") and m.kick_angle > 0.0)
    return RobotCommand(team, m.id, v.vel_x, v.vel_y, v.vel_angular, m.kick_speed, chip, m.dribbler_power)


def _commands_to(tc: TeamCommands) -> Any:
    m = ctl_pb.RobotControl(team=_TEAM_PB[tc.team], frame_number=tc.frame_number, t=tc.t)
    for c in tc.commands:
        _command_to(c, m.robot_commands.add())
    return m


def _commands_from(m: Any) -> TeamCommands:
    if not m.HasField("team"):
        raise MessageError("robot control without its team (field 100)")
    team = _team(m.team)
    return TeamCommands(team, m.frame_number, m.t, tuple(_command_from(c, team) for c in m.robot_commands))


# --- game state (the referee's word): the one place that maps GameState -------------------------

# the protobuf enums name ours in capitals: mapped by name, so a command or stage added to one and
# not the other fails here at import
_COMMAND_PB = {c: pb.GameState.Command.Value(c.name) for c in RefereeCommand}
_PB_COMMAND = {v: k for k, v in _COMMAND_PB.items()}
_STAGE_PB = {s: pb.GameState.Stage.Value(s.name) for s in GameStage}
_PB_STAGE = {v: k for k, v in _STAGE_PB.items()}


def _team_info_to(i: TeamInfo, into: Any) -> None:
    into.red_cards, into.yellow_cards, into.fouls, into.goalkeeper = i.red_cards, i.yellow_cards, i.fouls, i.goalkeeper
    into.yellow_card_times.extend(i.yellow_card_times_s)
    into.timeouts, into.timeout_time, into.placement_failures = i.timeouts, i.timeout_time_s, i.placement_failures
    into.can_place_ball, into.max_robots = i.can_place_ball, i.max_robots


def _team_info_from(m: Any) -> TeamInfo:
    return TeamInfo(m.red_cards, m.yellow_cards, tuple(m.yellow_card_times), m.fouls, m.goalkeeper, m.timeouts,
                    m.timeout_time, m.placement_failures, m.can_place_ball, m.max_robots)


def _game_to(g: GameState) -> Any:
    m = pb.GameState(t=g.t, command=_COMMAND_PB[g.command], score_blue=g.score_blue, score_yellow=g.score_yellow,
                     blue_defends_negative_x=g.blue_defends_negative_x, ready=g.ready, stage=_STAGE_PB[g.stage],
                     stage_time_left=g.stage_time_left_s, command_counter=g.command_counter, command_t=g.command_t,
                     action_time_left=g.action_time_left_s)
    if g.for_team is not None:
        m.for_team = _TEAM_PB[g.for_team]
    if g.placement is not None:
        m.placement.x, m.placement.y = g.placement
    if g.next_command is not None:
        m.next_command = _COMMAND_PB[g.next_command]
    if g.next_for_team is not None:
        m.next_for_team = _TEAM_PB[g.next_for_team]
    _team_info_to(g.blue_team, m.blue_team)
    _team_info_to(g.yellow_team, m.yellow_team)
    return m


def _game_from(m: Any) -> GameState:
    for code in (m.command, m.next_command):
        if code not in _PB_COMMAND:
            raise MessageError(f"unknown game command code {code}")
    if m.stage not in _PB_STAGE:
        raise MessageError(f"unknown game stage code {m.stage}")
    return GameState(m.t, _PB_COMMAND[m.command], _team(m.for_team) if m.HasField("for_team") else None,
                     m.score_blue, m.score_yellow, m.blue_defends_negative_x,
                     (m.placement.x, m.placement.y) if m.HasField("placement") else None, m.ready,
                     _PB_STAGE[m.stage], m.stage_time_left, m.command_counter, m.command_t, m.action_time_left,
                     _PB_COMMAND[m.next_command] if m.HasField("next_command") else None,
                     _team(m.next_for_team) if m.HasField("next_for_team") else None,
                     _team_info_from(m.blue_team), _team_info_from(m.yellow_team))


def _game_event_to(e: GameEvent, into: Any) -> None:
    into.t, into.kind, into.value, into.limit = e.t, e.kind, e.value, e.limit
    into.unit, into.restart = e.unit, e.restart or ""
    if e.team is not None:
        into.team = _TEAM_PB[e.team]
    if e.robot is not None:
        into.robot = e.robot
    if e.for_team is not None:
        into.for_team = _TEAM_PB[e.for_team]


def _game_event_from(m: Any) -> GameEvent:
    return GameEvent(m.t, m.kind, _team(m.team) if m.HasField("team") else None,
                     m.robot if m.HasField("robot") else None, m.value, m.limit, m.unit, m.restart or None,
                     _team(m.for_team) if m.HasField("for_team") else None)


def _game_events_to(ev: GameEvents) -> Any:
    m = pb.GameEvents(t=ev.t)
    for e in ev.events:
        _game_event_to(e, m.events.add())
    return m


def _game_events_from(m: Any) -> GameEvents:
    return GameEvents(m.t, tuple(_game_event_from(e) for e in m.events))


# --- ground truth -------------------------------------------------------------------------------


def _truth_to(gt: GroundTruth) -> Any:
    b = gt.ball
    m = pb.GroundTruth(frame_number=gt.frame_number, t=gt.t)
    m.ball.x, m.ball.y, m.ball.z, m.ball.vx, m.ball.vy, m.ball.vz = b.x, b.y, b.z, b.vx, b.vy, b.vz
    for cam, (u, v, f) in b.pixels.items():
        m.ball.cameras.add(camera_id=cam, u=u, v=v, visible_fraction=f)
    for r in gt.robots:
        rm = m.robots.add(team=_TEAM_PB[r.team], id=r.id, x=r.x, y=r.y, theta=r.theta, vx=r.vx, vy=r.vy,
                          omega=r.omega)
        for cam, (u, v) in r.pixels.items():
            rm.cameras.add(camera_id=cam, u=u, v=v)
    return m


def _truth_from(m: Any) -> GroundTruth:
    b = m.ball
    ball = BallTruth(b.x, b.y, b.z, b.vx, b.vy, b.vz, {c.camera_id: (c.u, c.v, c.visible_fraction) for c in b.cameras})
    robots = tuple(RobotTruth(_team(r.team), r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega,
                              {c.camera_id: (c.u, c.v) for c in r.cameras}) for r in m.robots)
    return GroundTruth(m.frame_number, m.t, ball, robots)


# --- simulator events, teleports, the clock, camera images -----------------------------------


def _event_to(e: Event, into: Any) -> None:
    if isinstance(e, Goal):
        into.goal.CopyFrom(pb.Goal(t=e.t, scoring_team=_TEAM_PB[e.scoring_team], x=e.x, y=e.y))
    elif isinstance(e, BallOut):
        into.ball_out.CopyFrom(pb.BallOut(t=e.t, x=e.x, y=e.y))
        if e.last_touch is not None:
            into.ball_out.last_touch = _TEAM_PB[e.last_touch]
    elif isinstance(e, Kick):
        into.kick.CopyFrom(pb.Kick(t=e.t, team=_TEAM_PB[e.team], id=e.id, speed_m_s=e.speed_m_s, chip=e.chip))
    else:
        into.contact.CopyFrom(pb.Contact(
            t_start=e.t_start, duration_s=e.duration_s, a=trk_pb.RobotId(id=e.a[1], team=_TEAM_PB[e.a[0]]),
            b=trk_pb.RobotId(id=e.b[1], team=_TEAM_PB[e.b[0]]), max_depth_m=e.max_depth_m,
            relative_speed_m_s=e.relative_speed_m_s))
        if e.pushed_by is not None:
            into.contact.pushed_by.CopyFrom(trk_pb.RobotId(id=e.pushed_by[1], team=_TEAM_PB[e.pushed_by[0]]))


def _event_from(m: Any) -> Event:
    kind = m.WhichOneof("event")
    if kind == "goal":
        g = m.goal
        return Goal(g.t, _team(g.scoring_team), g.x, g.y)
    if kind == "ball_out":
        o = m.ball_out
        return BallOut(o.t, o.x, o.y, _team(o.last_touch) if o.HasField("last_touch") else None)
    if kind == "kick":
        k = m.kick
        return Kick(k.t, _team(k.team), k.id, k.speed_m_s, k.chip)
    if kind == "contact":
        c = m.contact
        pushed = (_team(c.pushed_by.team), c.pushed_by.id) if c.HasField("pushed_by") else None
        return Contact(c.t_start, c.duration_s, (_team(c.a.team), c.a.id), (_team(c.b.team), c.b.id), c.max_depth_m,
                       c.relative_speed_m_s, pushed)
    raise MessageError("event without a kind")


def _events_to(ev: SimEvents) -> Any:
    m = pb.SimEvents(frame_number=ev.frame_number, t=ev.t, ball=pb.Point(x=ev.ball_xy[0], y=ev.ball_xy[1]))
    for e in ev.events:
        _event_to(e, m.events.add())
    return m


def _events_from(m: Any) -> SimEvents:
    return SimEvents(m.frame_number, m.t, (m.ball.x, m.ball.y), tuple(_event_from(e) for e in m.events))


def _teleport_to(tp: Teleport) -> Any:
    m = pb.Teleport(t=tp.t)
    for team, rid, x, y, theta in tp.robots:
        m.robots.add(team=_TEAM_PB[team], id=rid, x=x, y=y, theta=theta)
    if tp.ball is not None:
        m.ball.x, m.ball.y = tp.ball
    return m


def _teleport_from(m: Any) -> Teleport:
    return Teleport(m.t, tuple((_team(r.team), r.id, r.x, r.y, r.theta) for r in m.robots),
                    (m.ball.x, m.ball.y) if m.HasField("ball") else None)


def _camera_to(f: CameraFrame) -> Any:
    h, w = f.image.shape[:2]
    return pb.CameraFrame(camera_id=f.camera_id, frame_number=f.frame_number, t_capture=f.t_capture, width=w,
                          height=h, encoding="bgr8", data=np.ascontiguousarray(f.image).tobytes())


def _varint(n: int) -> bytes:
    """``n`` as a protobuf varint (seven bits a byte, low bits first)."""
    out = bytearray()
    while n >= 0x80:
        out.append(n & 0x7F | 0x80)
        n >>= 7
    out.append(n)
    return bytes(out)


_IMAGE_KEY = _varint(pb.CameraFrame.DESCRIPTOR.fields_by_name["data"].number << 3 | 2)  # length-delimited


def _camera_chunks(f: CameraFrame) -> tuple[bytes, bytes]:
    """A camera frame's protobuf bytes as two pieces, everything before the image and the image:
    the image is the last field, so the two joined are :func:`encode`'s bytes, and a transport
    copies the image once, into its buffer, instead of through a message and its serialisation."""
    h, w = f.image.shape[:2]
    head = pb.CameraFrame(camera_id=f.camera_id, frame_number=f.frame_number, t_capture=f.t_capture, width=w,
                          height=h, encoding="bgr8")
    image = np.ascontiguousarray(f.image).tobytes()
    return head.SerializePartialToString(deterministic=True) + _IMAGE_KEY + _varint(len(image)), image


def _camera_from(m: Any) -> CameraFrame:
    if m.encoding != "bgr8":
        raise MessageError(f"camera frame encoding must be bgr8, got {m.encoding!r}")
    raw = np.frombuffer(m.data, dtype=np.uint8)
    if raw.size != m.width * m.height * 3:
        raise MessageError(f"camera frame holds {raw.size} bytes, not {m.width}x{m.height}x3")
    return CameraFrame(m.camera_id, m.frame_number, m.t_capture, raw.reshape(m.height, m.width, 3))


# --- the brain's report, timings, summaries ---------------------------------------------------


def _report_to(r: TeamReport) -> Any:
    m = pb.TeamReport(team=_TEAM_PB[r.team], frame_number=r.frame_number, t=r.t, pass_points=_flat(r.pass_points),
                      pass_values=_flat(r.pass_values))
    for rr in r.robots:
        x, y, th = rr.target
        rm = m.robots.add(id=rr.id, status=rr.status, target_x=x, target_y=y, target_theta=th, path=_flat(rr.path),
                          braking=_flat(rr.braking))
        if rr.command is not None:
            _command_to(rr.command, rm.command)
    for rid, action in r.actions.items():
        m.actions.add(id=rid, action=action)
    ps = r.passing
    if ps is not None:
        m.passing.passer, m.passing.receiver, m.passing.kicked = ps.passer, ps.receiver, ps.kicked
        m.passing.target_x, m.passing.target_y = ps.target
        if ps.shoot_at is not None:
            m.passing.shoot_x, m.passing.shoot_y = ps.shoot_at
    return m


def _report_from(m: Any) -> TeamReport:
    team = _team(m.team)
    robots = tuple(RobotReport(r.id, r.status, (r.target_x, r.target_y, r.target_theta), _pairs(r.path),
                               _command_from(r.command, team) if r.HasField("command") else None, _pairs(r.braking))
                   for r in m.robots)
    passing = None
    if m.HasField("passing"):
        ps = m.passing
        aim = (ps.shoot_x, ps.shoot_y) if ps.HasField("shoot_x") else None
        passing = PassReport(ps.passer, ps.receiver, (ps.target_x, ps.target_y), aim, ps.kicked)
    return TeamReport(team, m.frame_number, m.t, robots, {a.id: a.action for a in m.actions}, _pairs(m.pass_points),
                      np.asarray(m.pass_values, dtype=np.float64), passing)


def _timing_to(t: Timing) -> Any:
    return pb.Timing(stage=t.stage, frame_number=t.frame_number, ms=dict(t.ms))


def _timing_from(m: Any) -> Timing:
    return Timing(m.stage, m.frame_number, dict(sorted(m.ms.items())))


def _physics_to(p: PhysicsFacts) -> Any:
    def fact(e: FactEstimate) -> Any:
        out = pb.PhysicsFact(fact=e.fact.value, configured=e.configured_m_s2, samples=e.samples, confident=e.confident,
                             used=e.used)
        if math.isfinite(e.value_m_s2):
            out.value = e.value_m_s2
        if math.isfinite(e.spread_m_s2):
            out.spread = e.spread_m_s2
        return out

    return pb.PhysicsFacts(t=p.t, facts=[fact(e) for e in p.estimates])


def _physics_from(m: Any) -> PhysicsFacts:
    try:
        return PhysicsFacts(m.t, tuple(
            FactEstimate(Fact(f.fact), f.value if f.HasField("value") else math.nan, f.configured, f.samples,
                         f.spread if f.HasField("spread") else math.nan, f.confident, f.used)
            for f in m.facts))
    except ValueError as exc:
        raise MessageError(f"bad physics facts: {exc}") from None


def _summary_to(s: StageSummary) -> Any:
    return pb.StageSummary(stage=s.stage, figures_json=json.dumps(s.figures, separators=(",", ":")))


def _summary_from(m: Any) -> StageSummary:
    try:
        return StageSummary(m.stage, json.loads(m.figures_json))
    except json.JSONDecodeError as exc:
        raise MessageError(f"stage summary figures are not JSON: {exc}") from None


# --- the registry ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Codec:
    """One message type's protobuf form: the generated class and the two conversions."""

    message: type[Any]
    proto: type[Any]
    to_proto: Callable[[Any], Any]
    from_proto: Callable[[Any], Any]


CODECS: dict[type[Any], Codec] = {c.message: c for c in (
    Codec(DetectionFrame, det_pb.SSL_DetectionFrame, _detection_to, _detection_from),
    Codec(WorldState, trk_pb.TrackedFrame, _world_to, _world_from),
    Codec(TeamCommands, ctl_pb.RobotControl, _commands_to, _commands_from),
    Codec(GameState, pb.GameState, _game_to, _game_from),
    Codec(GameEvents, pb.GameEvents, _game_events_to, _game_events_from),
    Codec(GroundTruth, pb.GroundTruth, _truth_to, _truth_from),
    Codec(SimEvents, pb.SimEvents, _events_to, _events_from),
    Codec(Teleport, pb.Teleport, _teleport_to, _teleport_from),
    Codec(Tick, pb.Tick, lambda t: pb.Tick(frame_number=t.frame_number), lambda m: Tick(m.frame_number)),
    Codec(CameraFrame, pb.CameraFrame, _camera_to, _camera_from),
    Codec(TeamReport, pb.TeamReport, _report_to, _report_from),
    Codec(Timing, pb.Timing, _timing_to, _timing_from),
    Codec(StageSummary, pb.StageSummary, _summary_to, _summary_from),
    Codec(PhysicsFacts, pb.PhysicsFacts, _physics_to, _physics_from),
    Codec(NodeControl, pb.NodeControl, lambda c: pb.NodeControl(node=c.node, command=c.command),
          lambda m: NodeControl(m.node, m.command)),
)}
_BY_NAME: dict[str, Codec] = {c.proto.DESCRIPTOR.full_name: c for c in CODECS.values()}

# the messages whose wire form rounds (32-bit floats): what a remote stage receives is not what was sent
LOSSY: frozenset[type[Any]] = frozenset({DetectionFrame, WorldState, TeamCommands})


def schema(message: Any) -> str:
    """The full name of ``message``'s protobuf type: what :func:`decode` reads its bytes by."""
    return _codec(message).proto.DESCRIPTOR.full_name  # type: ignore[no-any-return]


def is_known(schema_name: str) -> bool:
    """Whether :func:`decode` reads bytes of the protobuf type ``schema_name`` into one of our messages."""
    return schema_name in _BY_NAME


def _codec(message: Any) -> Codec:
    try:
        return CODECS[type(message)]
    except KeyError:
        raise MessageError(f"{type(message).__name__} has no protobuf form") from None


def to_proto(message: Any) -> Any:
    """The protobuf object of one of our messages."""
    return _codec(message).to_proto(message)


def from_proto(proto: Any) -> Any:
    """Our message of a protobuf object (by its full type name)."""
    try:
        codec = _BY_NAME[proto.DESCRIPTOR.full_name]
    except KeyError:
        raise MessageError(f"{proto.DESCRIPTOR.full_name} is not one of the bus's messages") from None
    return codec.from_proto(proto)


def encode(message: Any) -> bytes:
    """The protobuf bytes of ``message``."""
    return to_proto(message).SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def encode_chunks(message: Any) -> tuple[bytes, ...]:
    """The protobuf bytes of ``message`` in pieces whose concatenation is :func:`encode`'s: a camera
    frame as its header and its image (copied once, from the array), anything else in one piece."""
    if type(message) is CameraFrame:
        return _camera_chunks(message)
    return (encode(message),)


def canonical_and_chunks(message: Any) -> tuple[Any, tuple[bytes, ...]]:
    """:func:`canonical` and :func:`encode_chunks` of ``message`` at once, for a message that goes
    both to stages of this process and over the wire: one whose wire form rounds is turned into
    its protobuf object once for both."""
    if type(message) in LOSSY:
        codec = CODECS[type(message)]
        proto = codec.to_proto(message)
        return codec.from_proto(proto), (proto.SerializeToString(deterministic=True),)
    return message, encode_chunks(message)


def decode(schema_name: str, data: bytes | bytearray | memoryview) -> Any:
    """One of our messages from its protobuf bytes and the full name of their type (:func:`schema`);
    :class:`MessageError` for bytes that are not one, or a type that is not ours."""
    from google.protobuf.message import DecodeError

    codec = _BY_NAME.get(schema_name)
    if codec is None:
        raise MessageError(f"{schema_name!r} is not one of our messages' protobuf types")
    proto = codec.proto()
    try:
        proto.ParseFromString(bytes(data) if isinstance(data, memoryview) else data)
        return codec.from_proto(proto)
    except DecodeError as exc:
        raise MessageError(f"not a {codec.proto.DESCRIPTOR.full_name}: {exc}") from None
    except (ValueError, TypeError, KeyError) as exc:  # a required field missing, a value out of range
        raise MessageError(f"bad {codec.proto.DESCRIPTOR.full_name}: {exc}") from None


def parse(proto_type: Any, data: bytes) -> Any:
    """``data`` parsed as a ``proto_type`` (a generated message class); :class:`MessageError` naming
    the league's message for bytes that are not one (garbage, cut short, a required field missing)."""
    from google.protobuf.message import DecodeError

    m = proto_type()
    name = proto_type.DESCRIPTOR.name
    try:
        m.ParseFromString(data)
    except DecodeError as exc:
        raise MessageError(f"not a {name}: {exc}") from None
    if not m.IsInitialized():
        raise MessageError(f"{name} with required fields missing: " + ", ".join(m.FindInitializationErrors()))
    return m


def canonical(message: Any) -> Any:
    """``message`` as a stage on another process would receive it (through its wire form when that
    rounds, else itself)."""
    if type(message) in LOSSY:
        codec = CODECS[type(message)]
        return codec.from_proto(codec.to_proto(message))
    return message
