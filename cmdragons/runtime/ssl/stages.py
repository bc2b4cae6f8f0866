"""The protocol adapters: stages on the bus like any other, each between topics and UDP packets.

    ssl/vision_out             detections/<id> -> SSL_WrapperPacket multicast; ssl/vision/sent (Tick) per frame
    ssl/vision_in              SSL_WrapperPacket multicast -> ssl/vision/<id> (DetectionFrame)
    ssl/referee_out            referee (GameState) -> Referee multicast
    ssl/referee_in             Referee multicast -> referee/gc (GameState); world/<team>: the ball taken into play
    ssl/tracker_out/<team>     world/<team> -> TrackerWrapperPacket multicast
    ssl/commands_out/<team>    commands/<team> (headings from world/<team>) -> grSim_Packet or RobotControl
                               unicast; teleport -> SimulatorCommand
    ssl/simulation_in/<team>   RobotControl and SimulatorCommand unicast, on each truth -> commands/<team>, teleport

``ssl/vision_in`` runs free (on every ``clock`` tick it publishes what came since) when the packets
come from outside; fed by our own ``ssl/vision_out`` in the same match it runs in lock-step: on each
``ssl/vision/sent`` it waits (up to ``vision.wait_s``) until that frame's packet from every camera
came, so the match plays the same as on the in-process path. Every camera id is taken (published
on ``ssl/vision/<id>``, whoever reads it: grSim sends four cameras, a Division A field may have
eight); garbage, a packet cut short and a packet already seen are counted and dropped with a line
on stderr (by every receiving stage: garbage and cut packets for the simulation protocol and the
referee too); robot detections without id or orientation are left out and counted. Times on the
wire are Unix time, match time here (:mod:`cmdragons.runtime.ssl.clock`).
"""

from __future__ import annotations

import math
import time
import uuid
from collections.abc import Mapping, Sequence
from typing import Any, Protocol, TextIO

from cmdragons.geometry import Field, LeagueParams, Team
from cmdragons.messages import (
    DetectionFrame,
    GameState,
    GroundTruth,
    MessageError,
    RobotCommand,
    StageSummary,
    TeamCommands,
    Teleport,
    Tick,
    WorldState,
)
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.ssl.clock import UnixEpoch, run_epoch
from cmdragons.runtime.ssl.commands import (
    UNSUPPORTED,
    Feedback,
    SimError,
    grsim_packet,
    off_field_packet,
    read_robot_control,
    read_robot_control_response,
    read_simulator_command,
    robot_control_packet,
    robot_control_response,
    simulator_command_packet,
    simulator_response,
)
from cmdragons.runtime.ssl.params import ProtocolParams
from cmdragons.runtime.ssl.referee import RefereeReader, referee_packet
from cmdragons.runtime.ssl.tracker import tracker_packet
from cmdragons.runtime.ssl.udp import DropLog, MulticastReceiver, MulticastSender, UdpEndpoint
from cmdragons.runtime.ssl.vision import VisionGeometry, detection_packet, read_wrapper
from cmdragons.runtime.topics import Contract, Port, summary_port
from sim.substitution import RobotCount
from sim.world import ball_at_front

__all__ = ["CommandsOutStage", "RefereeInStage", "RefereeOutStage", "RobotCountStage", "SimulationInStage",
           "SocketStage", "TrackerOutStage", "VisionInStage", "VisionOutStage", "close_sockets"]


class Receiver(Protocol):
    """Where a receiving stage reads its datagrams: a socket, or a replay's queue."""

    def receive(self, timeout_s: float = 0.0) -> bytes | None: ...

    def drain(self) -> list[bytes]: ...

    def close(self) -> None: ...


class SocketStage(BaseStage):
    """A stage that holds sockets: :meth:`close` them when the run ends."""

    def close(self) -> None:
        return None


def close_sockets(stages: Sequence[Any]) -> None:
    """Close the sockets of every :class:`SocketStage` among ``stages``."""
    for stage in stages:
        if isinstance(stage, SocketStage):
            stage.close()


class VisionOutStage(SocketStage):
    """Our vision as SSL-Vision: each camera frame's detections as an SSL_WrapperPacket, the
    geometry (field and calibrations) every ``vision.geometry_interval_s`` of camera time."""

    @staticmethod
    def declare(params: ProtocolParams, camera_ids: Sequence[int], geometry: bytes = b"",
                topics: Sequence[str] | None = None) -> Contract:
        read = tuple(topics) if topics is not None else tuple(f"detections/{c}" for c in camera_ids)
        return Contract("ssl/vision_out", tuple(Port(t, DetectionFrame) for t in read),
                        (Port("ssl/vision/sent", Tick), summary_port("ssl/vision_out")))

    def __init__(self, params: ProtocolParams, camera_ids: Sequence[int], geometry: bytes,
                 topics: Sequence[str] | None = None, epoch: UnixEpoch | None = None) -> None:
        v = params.vision
        self.epoch = run_epoch() if epoch is None else epoch
        self.contract = self.declare(params, camera_ids, geometry, topics)
        self.camera_ids = tuple(camera_ids)
        self.sender = MulticastSender(v.group, v.port, params.interface, params.ttl)
        self.geometry = geometry
        self.interval_s = v.geometry_interval_s
        self._next_geometry = -float("inf")
        self._frame = -1
        self._sent: set[int] = set()
        self.geometry_packets = 0
        self._wall0: float | None = None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        det: DetectionFrame = message
        if self._wall0 is None:
            self._wall0 = time.perf_counter()
        if det.frame_number != self._frame:
            if self._sent:  # a newer frame: the one before is as complete as it gets
                publish("ssl/vision/sent", Tick(self._frame))
            self._frame, self._sent = det.frame_number, set()
        if det.t_capture >= self._next_geometry:
            self.sender.send(self.geometry)
            self.geometry_packets += 1
            self._next_geometry = det.t_capture + self.interval_s
        self.sender.send(detection_packet(det, self.epoch))
        self._sent.add(det.camera_id)
        if self._sent >= set(self.camera_ids):
            publish("ssl/vision/sent", Tick(det.frame_number))
            self._sent = set()

    def summarize(self, publish: Publish) -> None:
        wall = time.perf_counter() - self._wall0 if self._wall0 is not None else 0.0
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "packets": self.sender.sent, "geometry_packets": self.geometry_packets, "bytes": self.sender.bytes,
            "packets_per_s": round(self.sender.sent / wall, 1) if wall > 0 else None}))

    def close(self) -> None:
        self.sender.close()


class VisionInStage(SocketStage):
    """SSL-Vision packets from multicast -> ``ssl/vision/<camera id>`` detections (metres), the
    latest geometry kept. ``lockstep``: fed by our own sender in this match (see the module).
    Times: the packets' less ``epoch``; by default our sender's in lock-step, else the first
    packet's whole second (Unix time, or a clock from the sender's start: grSim's)."""

    @staticmethod
    def declare(params: ProtocolParams, camera_ids: Sequence[int], lockstep: bool) -> Contract:
        any_camera = () if lockstep else (Port("ssl/vision/*", DetectionFrame),)  # from outside: any camera id
        return Contract("ssl/vision_in", (Port("ssl/vision/sent" if lockstep else "clock", Tick),),
                        (*(Port(f"ssl/vision/{c}", DetectionFrame) for c in sorted(camera_ids)), *any_camera,
                         summary_port("ssl/vision_in")))

    def __init__(self, params: ProtocolParams, camera_ids: Sequence[int], lockstep: bool,
                 err: TextIO | None = None, receiver: Receiver | None = None, epoch: UnixEpoch | None = None,
                 camera_clock: bool | None = None) -> None:
        v = params.vision
        # lock-step: our own sender's epoch; from outside: given, or the first packet's (the sender's time,
        # Unix or grSim's from its start, becomes match time from that packet's second)
        self.epoch: UnixEpoch | None = run_epoch() if epoch is None and lockstep else epoch
        self.camera_clock = lockstep if camera_clock is None else camera_clock  # our own packets: exact times
        self.receiver: Receiver = receiver if receiver is not None else MulticastReceiver(
            v.group, v.port, params.interface, params.receive_buffer_bytes, params.max_datagram_bytes)
        self.camera_ids = frozenset(camera_ids)
        self.lockstep = lockstep
        self.wait_s = v.wait_s
        self.contract = self.declare(params, camera_ids, lockstep)
        self.drops = DropLog(f"ssl-vision {v.group}:{v.port}", params.drop_report_interval_s, err)
        self.geometry: VisionGeometry | None = None
        self.received = self.detections = self.geometry_packets = self.late = 0
        self.robots_left_out: dict[str, int] = {}  # robot detections without id or orientation, by reason
        self.cameras_seen: set[int] = set()  # any camera id is taken (grSim sends four, a big field eight)
        self._last: dict[int, int] = {}  # camera -> the last frame number published

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if not self.lockstep:
            for datagram in self.receiver.drain():
                self._take(datagram, publish)
            return
        frame = message.frame_number
        deadline = time.monotonic() + self.wait_s
        while not all(self._last.get(c, -1) >= frame for c in self.camera_ids):
            data = self.receiver.receive(max(0.0, deadline - time.monotonic()))
            if data is None:
                self.late += 1
                return
            self._take(data, publish)

    def _take(self, data: bytes, publish: Publish) -> None:
        self.received += 1
        try:
            if self.epoch is None:
                first = read_wrapper(data, UnixEpoch(0)).detection
                self.epoch = None if first is None else UnixEpoch.of_first(first.t_capture)
            got = read_wrapper(data, self.epoch or UnixEpoch(0), camera_clock=self.camera_clock)
        except MessageError as exc:
            self.drops.drop("undecodable", f"{len(data)} bytes, {exc}")
            return
        det, geo = got.detection, got.geometry
        for why, n in got.robots_left_out.items():
            self.robots_left_out[why] = self.robots_left_out.get(why, 0) + n
        if geo is not None:
            self.geometry = geo
            self.geometry_packets += 1
        if det is None:
            return
        self.cameras_seen.add(det.camera_id)
        last = self._last.get(det.camera_id, -1)
        if det.frame_number <= last:
            self.drops.drop("duplicate", f"camera {det.camera_id} frame {det.frame_number} after frame {last}")
            return
        self._last[det.camera_id] = det.frame_number
        self.detections += 1
        publish(f"ssl/vision/{det.camera_id}", det)

    def summarize(self, publish: Publish) -> None:
        g = self.geometry
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "packets": self.received, "detections": self.detections, "geometry_packets": self.geometry_packets,
            "dropped": dict(sorted(self.drops.counts.items())), "frames_late": self.late,
            "robots_left_out": dict(sorted(self.robots_left_out.items())),
            "cameras_seen": sorted(self.cameras_seen),
            "field_m": None if g is None else [g.field_length_m, g.field_width_m]}))

    def close(self) -> None:
        self.receiver.close()


class RefereeOutStage(SocketStage):
    """Our referee's game state as the league's Referee message, multicast."""

    contract = Contract("ssl/referee_out", (Port("referee", GameState),), (summary_port("ssl/referee_out"),))

    def __init__(self, params: ProtocolParams, epoch: UnixEpoch | None = None) -> None:
        r = params.referee
        self.sender = MulticastSender(r.group, r.port, params.interface, params.ttl)
        self.source = r.source_identifier
        self.epoch = run_epoch() if epoch is None else epoch

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        self.sender.send(referee_packet(message, self.source, epoch=self.epoch))

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {"packets": self.sender.sent}))

    def close(self) -> None:
        self.sender.close()


class RefereeInStage(SocketStage):
    """A game controller's Referee packets from multicast -> ``referee/gc`` game states, on every
    clock tick each packet that came since. On ``world_topic`` it watches the ball: once a
    kickoff's or penalty's restart is taken (the ball moved ``moved_m``, the rules' ball-in-play
    distance, from its spot), play is normal. The spot is the designated position of the packet
    that started it, or (a game controller clears the designated position at NORMAL_START) of the
    prepare command before it, or else where the ball was first seen after the normal start. Times:
    the packets' Unix times less ``epoch``, by default their first packet's second."""

    @staticmethod
    def declare(params: ProtocolParams, world_topic: str, moved_m: float = 0.0) -> Contract:
        return Contract("ssl/referee_in", (Port("clock", Tick), Port(world_topic, WorldState)),
                        (Port("referee/gc", GameState), summary_port("ssl/referee_in")))

    def __init__(self, params: ProtocolParams, world_topic: str, moved_m: float, err: TextIO | None = None,
                 receiver: Receiver | None = None, epoch: UnixEpoch | None = None) -> None:
        r = params.referee
        self.receiver: Receiver = receiver if receiver is not None else MulticastReceiver(
            r.group, r.port, params.interface, params.receive_buffer_bytes, params.max_datagram_bytes)
        self.contract = self.declare(params, world_topic)
        self.moved_m = moved_m
        self.reader = RefereeReader(epoch) if epoch is not None else None  # None: the first packet's epoch
        self.drops = DropLog(f"referee {r.group}:{r.port}", params.drop_report_interval_s, err)
        self.received = self.restarts_taken = 0
        self._last: bytes | None = None
        self._spot: tuple[float, float] | None = None  # where the restart under way was set (field, m)

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == "clock":
            for data in self.receiver.drain():
                self._take(data, publish)
            return
        g, b = (None if self.reader is None else self.reader.last), message.ball
        if self.reader is None or g is None or not (g.command.prepared and g.ready) or b is None or self._last is None:
            return
        if self._spot is None:
            self._spot = (b.x, b.y)
        elif math.hypot(b.x - self._spot[0], b.y - self._spot[1]) > self.moved_m:
            self.reader.ball_moved()
            self.restarts_taken += 1
            self._spot = None
            publish("referee/gc", self.reader.read(self._last))

    def _take(self, data: bytes, publish: Publish) -> None:
        self.received += 1
        try:
            if self.reader is None:
                first = RefereeReader(UnixEpoch(0)).read(data)
                self.reader = RefereeReader(UnixEpoch.of_first(first.t))
            game = self.reader.read(data)
        except MessageError as exc:
            self.drops.drop("undecodable", f"{len(data)} bytes, {exc}")
            return
        self._last = data
        if not game.command.prepared:
            self._spot = None
        elif game.placement is not None:  # the prepare's spot, or the start's when it says one
            self._spot = game.placement
        publish("referee/gc", game)

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "packets": self.received, "restarts_taken": self.restarts_taken,
            "dropped": dict(sorted(self.drops.counts.items()))}))

    def close(self) -> None:
        self.receiver.close()


class TrackerOutStage(SocketStage):
    """Our tracker's world state as the league's TrackerWrapperPacket (metres), multicast; one
    ``uuid`` for the run."""

    @staticmethod
    def declare(params: ProtocolParams, team: Team) -> Contract:
        name = f"ssl/tracker_out/{team}"
        return Contract(name, (Port(f"world/{team}", WorldState),), (summary_port(name),))

    def __init__(self, params: ProtocolParams, team: Team, epoch: UnixEpoch | None = None) -> None:
        t = params.tracker
        self.epoch = run_epoch() if epoch is None else epoch
        self.contract = self.declare(params, team)
        self.sender = MulticastSender(t.group, t.port, params.interface, params.ttl)
        self.uuid = str(uuid.uuid4())
        self.source = t.source_name

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        self.sender.send(tracker_packet(message, self.uuid, self.source, self.epoch))

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {"packets": self.sender.sent,
                                                                 "bytes": self.sender.bytes}))

    def close(self) -> None:
        self.sender.close()


class CommandsOutStage(SocketStage):
    """Our team's commands to a league simulator: grSim (``grSim_Packet`` to ``grsim.address:port``)
    or the simulation protocol (``RobotControl`` to the team's port); our referee's teleports as
    ``SimulatorCommand`` to the simulation protocol's control port (grSim takes them there too;
    ``teleports``: this team's stage sends them, one of a match's does; a robot placed beyond the
    field's margin of ``pitch``, where our referee parks a robot it sends off, is taken out of the
    simulator instead, ``present: false``, and one placed on it again is put back, ``present: true``, as
    the league's simulation controller does). Velocities go in each
    robot's frame by its heading in our tracker's latest world state. grSim stops a robot whose last
    packet is older than one of its frames: on each world state (a vision frame) the last packet
    goes again, with the new headings, before the frame's own commands come. The simulators'
    answers are read and counted."""

    @staticmethod
    def declare(params: ProtocolParams, team: Team, chip_angle_rad: float = 0.0, teleports: bool = True) -> Contract:
        name = f"ssl/commands_out/{team}"
        takes = params.commands_to != "none" and teleports  # (grSim takes them on the simulation protocol's port too)
        return Contract(name, (Port(f"world/{team}", WorldState), Port(f"commands/{team}", TeamCommands),
                               *((Port("teleport", Teleport),) if takes else ())),
                        (summary_port(name),))

    def __init__(self, params: ProtocolParams, team: Team, chip_angle_rad: float, err: TextIO | None = None,
                 teleports: bool = True, pitch: Field | None = None) -> None:
        self.contract = self.declare(params, team, chip_angle_rad, teleports)
        self.team = team
        self.pitch = pitch
        self.to = params.commands_to
        sim = params.simulation
        self.endpoint = UdpEndpoint(sim.address if self.to == "simulation" else params.grsim.address)
        self.peer = (params.grsim.address, params.grsim.port) if self.to == "grsim" else (sim.address,
                                                                                           sim.port(team))
        self.control = (sim.address, sim.control_port)
        self.chip_angle_rad = chip_angle_rad
        self.hold_armed = params.grsim.hold_armed
        self.full_rpm = sim.dribbler_full_rpm
        self.headings: dict[int, float] = {}
        self.sent = self.teleports = self.answers = self.answer_errors = self.answers_earlier_layout = 0
        self.resent = 0
        self._last: TeamCommands | None = None  # grSim: the latest commands, resent each vision frame
        self.drops = DropLog(f"{self.to} answers", params.drop_report_interval_s, err)

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == "teleport":
            tp: Teleport = message
            off = [(team, rid) for team, rid, x, y, _ in tp.robots if self.beyond(x, y)]
            if off:  # sent off: out of the simulator, as the league's simulation controller takes a robot out
                self.endpoint.send_to(off_field_packet(off), self.control)
                tp = Teleport(tp.t, tuple(r for r in tp.robots if not self.beyond(r[2], r[3])), tp.ball)
            if tp.robots or tp.ball is not None:
                self.endpoint.send_to(simulator_command_packet(tp), self.control)
            self.teleports += 1
        elif isinstance(message, TeamCommands):
            if self.to == "grsim":
                data = grsim_packet(message, self.headings, self.chip_angle_rad, self.hold_armed)
                self._last = message
            else:
                data = robot_control_packet(message, self.headings, self.chip_angle_rad, self.full_rpm)
            self.endpoint.send_to(data, self.peer)
            self.sent += 1
        else:
            self.headings = {r.id: r.theta for r in message.robots if r.team == self.team}
            if self._last is not None:
                self.endpoint.send_to(grsim_packet(self._last, self.headings, self.chip_angle_rad, self.hold_armed),
                                      self.peer)
                self.resent += 1
        self._read_answers()

    def beyond(self, x: float, y: float) -> bool:
        """Is (``x``, ``y``) beyond the field's margin (where our referee parks a robot it sends off;
        never, without ``pitch``)?"""
        return self.pitch is not None and not self.pitch.in_field(x, y, -self.pitch.dims.boundary_width_m)

    def _read_answers(self) -> None:
        """The simulation protocol answers each packet (grSim does not): count them and their errors."""
        while (got := self.endpoint.receive()) is not None:
            data, _peer = got
            try:
                answer = read_robot_control_response(data)
            except MessageError as exc:
                self.drops.drop("undecodable", f"{len(data)} bytes, {exc}")
                continue
            self.answers += 1
            self.answer_errors += len(answer.errors)
            self.answers_earlier_layout += answer.earlier_layout

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "to": self.to, "packets": self.sent, "resent": self.resent, "teleports": self.teleports,
            "answers": self.answers, "answer_errors": self.answer_errors,
            "answers_earlier_layout": self.answers_earlier_layout,
            "dropped": dict(sorted(self.drops.counts.items()))}))

    def close(self) -> None:
        self.endpoint.close()


class RobotCountStage(SocketStage):
    """The league's simulation controller's part we need in an outside simulator: each team's robots
    on the field kept at the count the referee allows (:class:`sim.substitution.RobotCount` on our
    tracked ``world`` and the ``referee_topic``'s game state), robots taken out (``present: false``)
    and put back (``present: true``) through the simulation protocol's control port."""

    @staticmethod
    def declare(world: str, referee_topic: str) -> Contract:
        return Contract("ssl/robot_count", (Port(referee_topic, GameState), Port(world, WorldState)),
                        (summary_port("ssl/robot_count"),))

    def __init__(self, params: ProtocolParams, count: RobotCount, world: str, referee_topic: str) -> None:
        self.contract = self.declare(world, referee_topic)
        self.count = count
        self.referee_topic = referee_topic
        sim = params.simulation
        self.endpoint = UdpEndpoint(sim.address)
        self.control = (sim.address, sim.control_port)
        self.game: GameState | None = None
        self.changes: list[dict[str, Any]] = []

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == self.referee_topic:
            self.game = message
            return
        if self.game is None:
            return
        change = self.count.step(message, self.game)
        if change.off:
            self.endpoint.send_to(off_field_packet(change.off), self.control)
        if change.on:
            self.endpoint.send_to(simulator_command_packet(Teleport(message.t, change.on)), self.control)
        if change:
            self.changes.append({"t": round(message.t, 3), "off": [list(k) for k in change.off],
                                 "on": [[team, rid] for team, rid, *_ in change.on]})

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "taken_off": self.count.taken_off, "put_back": self.count.put_back, "each": self.changes}))

    def close(self) -> None:
        self.endpoint.close()


class SimulationInStage(SocketStage):
    """Our simulator as a simulation-protocol simulator for ``teams`` (one, or both when it is
    served alone): ``RobotControl`` on each team's port (loopback) becomes that team's commands,
    ``SimulatorCommand`` teleports on the control port become teleports. On each captured frame
    (``truth``) it takes what came since; a frame with no new RobotControl waits up to ``wait_s``
    (default ``simulation.wait_s``; 0 for a simulator running on its own clock) for one (the match
    keeps pace with a team that answers every frame; ``heard_only``: only for a team that has sent one
    before, so that a served simulator runs on before a client joins and beside a colour nobody plays).
    A team that sent nothing this frame has no
    commands for it (its robots stop by their own command timeout). Local velocities turn into the
    field frame by the robot's true heading. Each packet is answered (RobotControlResponse, with each
    robot's ball contact when ``league`` is given, within ``touch_m`` of its front; SimulatorResponse).
    A robot taken off the field (``present: false``) goes to its spot in ``parked``, out of the
    cameras' view (refused without). Garbage and a packet cut short are counted and dropped with a
    line on stderr."""

    @staticmethod
    def declare(params: ProtocolParams, teams: Team | Sequence[Team]) -> Contract:
        ts = _teams(teams)
        name = f"ssl/simulation_in/{ts[0]}" if len(ts) == 1 else "ssl/simulation_in"
        return Contract(name, (Port("truth", GroundTruth),), (*(Port(f"commands/{t}", TeamCommands) for t in ts),
                        Port("teleport", Teleport), summary_port(name)))

    def __init__(self, params: ProtocolParams, teams: Team | Sequence[Team], wait_s: float | None = None,
                 league: LeagueParams | None = None, touch_m: float = 0.0,
                 parked: Mapping[tuple[Team, int], tuple[float, float]] | None = None,
                 err: TextIO | None = None, heard_only: bool = False) -> None:
        sim = params.simulation
        self.contract = self.declare(params, teams)
        self.teams = _teams(teams)
        self.robots: dict[Team, UdpEndpoint] = {}
        try:  # a port another program holds: what was opened is closed again
            for t in self.teams:
                self.robots[t] = UdpEndpoint(sim.address, sim.port(t), params.max_datagram_bytes)
            self.control = UdpEndpoint(sim.address, sim.control_port, params.max_datagram_bytes)
        except OSError:
            for endpoint in self.robots.values():
                endpoint.close()
            raise
        self.wait_s = sim.wait_s if wait_s is None else wait_s
        self.heard_only = heard_only
        self.heard: set[Team] = set()  # the teams that have sent a RobotControl
        self.league, self.touch_m, self.parked = league, touch_m, parked
        self.full_rpm = sim.dribbler_full_rpm
        ports = "/".join(str(sim.port(t)) for t in self.teams)
        self.drops = DropLog(f"simulation protocol {sim.address}:{ports}/{sim.control_port}",
                             params.drop_report_interval_s, err)
        self.packets = self.teleports = self.frames_waited_out = 0
        self.refused: dict[str, int] = {}

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        gt: GroundTruth = message
        where = {(r.team, r.id): (r.x, r.y, r.theta) for r in gt.robots}
        while (got := self.control.receive()) is not None:
            self._teleport(got, gt, where, publish)
        for team in self.teams:
            commands = self._team_commands(team, gt)
            publish(f"commands/{team}", TeamCommands(team, gt.frame_number, gt.t, commands))

    def _team_commands(self, team: Team, gt: GroundTruth) -> tuple[RobotCommand, ...]:
        """The newest command of each of ``team``'s robots that came since the last frame."""
        endpoint = self.robots[team]
        headings = {r.id: r.theta for r in gt.robots if r.team == team}
        contact = self._contact(team, gt)
        latest: dict[int, RobotCommand] = {}
        got = endpoint.receive()
        if got is None and self.wait_s > 0 and (team in self.heard or not self.heard_only):
            got = endpoint.receive(self.wait_s)
            self.frames_waited_out += got is None
        if got is not None:
            self.heard.add(team)
        while got is not None:
            for c in self._commands(team, got, headings, contact):
                latest[c.id] = c
            got = endpoint.receive()
        return tuple(latest[i] for i in sorted(latest))

    def _contact(self, team: Team, gt: GroundTruth) -> dict[int, bool]:
        """Each of ``team``'s robots: is the ball at its dribbler (none known without ``league``)?"""
        if self.league is None:
            return {}
        b = gt.ball
        on_ground = b.z <= self.league.ball.radius_m + 1e-6
        return {r.id: on_ground and ball_at_front(self.league, b.x - r.x, b.y - r.y, r.theta, self.touch_m)[0]
                for r in gt.robots if r.team == team}

    def _commands(self, team: Team, got: tuple[bytes, tuple[str, int]], headings: dict[int, float],
                  contact: dict[int, bool]) -> tuple[RobotCommand, ...]:
        data, peer = got
        try:
            read = read_robot_control(data, team, headings, self.full_rpm)
        except MessageError as exc:
            self.drops.drop("undecodable", f"{len(data)} bytes from {peer[0]}:{peer[1]}, {exc}")
            return ()
        self.packets += 1
        for _, why in read.errors:
            self._refuse(why)
        feedback = [Feedback(c.id, contact.get(c.id)) for c in read.commands]
        self.robots[team].send_to(robot_control_response(feedback, [SimError(UNSUPPORTED, why)
                                                                    for _, why in read.errors]), peer)
        return read.commands

    def _teleport(self, got: tuple[bytes, tuple[str, int]], gt: GroundTruth,
                  where: dict[tuple[Team, int], tuple[float, float, float]], publish: Publish) -> None:
        data, peer = got
        try:
            tp, refused = read_simulator_command(data, gt.t, where, (gt.ball.x, gt.ball.y), self.parked)
        except MessageError as exc:
            self.drops.drop("undecodable", f"{len(data)} bytes from {peer[0]}:{peer[1]}, {exc}")
            return
        for why in refused:
            self._refuse(why)
        if tp is not None:
            self.teleports += 1
            publish("teleport", tp)
        self.control.send_to(simulator_response([SimError(UNSUPPORTED, why) for why in refused]), peer)

    def _refuse(self, why: str) -> None:
        key = why.split(":")[0]
        self.refused[key] = self.refused.get(key, 0) + 1

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "packets": self.packets, "teleports": self.teleports, "frames_waited_out": self.frames_waited_out,
            "refused": dict(sorted(self.refused.items())),
            "dropped": dict(sorted(self.drops.counts.items()))}))

    def close(self) -> None:
        for endpoint in self.robots.values():
            endpoint.close()
        self.control.close()


def _teams(teams: Team | Sequence[Team]) -> tuple[Team, ...]:
    """One team or several, as a tuple in the order given."""
    return (teams,) if isinstance(teams, str) else tuple(teams)
