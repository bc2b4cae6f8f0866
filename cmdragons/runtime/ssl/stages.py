"""The protocol adapters: stages on the bus like any other, each between topics and UDP packets.

    ssl/vision_out   detections/<id> -> SSL_WrapperPacket multicast; ssl/vision/sent (Tick) per frame
    ssl/vision_in    SSL_WrapperPacket multicast -> ssl/vision/<id> (DetectionFrame)
    ssl/referee_out  referee (GameState) -> Referee multicast
    ssl/referee_in   Referee multicast -> referee/gc (GameState); world/<team>: the ball taken into play

``ssl/vision_in`` runs free (on every ``clock`` tick it publishes what came since) when the packets
come from outside; fed by our own ``ssl/vision_out`` in the same match it runs in lock-step: on each
``ssl/vision/sent`` it waits (up to ``vision.wait_s``) until that frame's packet from every camera
came, so the match plays the same as on the in-process path. Garbage, a packet cut short, a camera
not in the config and a packet already seen are counted and dropped with a line on stderr.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Any, TextIO

from cmdragons.messages import DetectionFrame, MessageError, StageSummary, Tick
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.ssl.params import ProtocolParams
from cmdragons.runtime.ssl.referee import RefereeReader, referee_packet
from cmdragons.runtime.ssl.udp import DropLog, MulticastReceiver, MulticastSender
from cmdragons.runtime.ssl.vision import VisionGeometry, decode_wrapper, detection_packet

__all__ = ["RefereeInStage", "RefereeOutStage", "SocketStage", "VisionInStage", "VisionOutStage", "close_sockets"]


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

    name = "ssl/vision_out"

    def __init__(self, params: ProtocolParams, camera_ids: Sequence[int], geometry: bytes) -> None:
        v = params.vision
        self.inputs = tuple(f"detections/{c}" for c in camera_ids)
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
        self.sender.send(detection_packet(det))
        self._sent.add(det.camera_id)
        if self._sent >= set(self.camera_ids):
            publish("ssl/vision/sent", Tick(det.frame_number))
            self._sent = set()

    def summarize(self, publish: Publish) -> None:
        wall = time.perf_counter() - self._wall0 if self._wall0 is not None else 0.0
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "packets": self.sender.sent, "geometry_packets": self.geometry_packets, "bytes": self.sender.bytes,
            "packets_per_s": round(self.sender.sent / wall, 1) if wall > 0 else None}))  # fmt: skip

    def close(self) -> None:
        self.sender.close()


class VisionInStage(SocketStage):
    """SSL-Vision packets from multicast -> ``ssl/vision/<camera id>`` detections (metres), the
    latest geometry kept. ``lockstep``: fed by our own sender in this match (see the module)."""

    name = "ssl/vision_in"

    def __init__(self, params: ProtocolParams, camera_ids: Sequence[int], lockstep: bool,
                 err: TextIO | None = None) -> None:  # fmt: skip
        v = params.vision
        self.receiver = MulticastReceiver(v.group, v.port, params.interface, params.receive_buffer_bytes,
                                          params.max_datagram_bytes)  # fmt: skip
        self.camera_ids = frozenset(camera_ids)
        self.lockstep = lockstep
        self.wait_s = v.wait_s
        self.inputs = ("ssl/vision/sent",) if lockstep else ("clock",)
        self.drops = DropLog(f"ssl-vision {v.group}:{v.port}", params.drop_report_interval_s, err)
        self.geometry: VisionGeometry | None = None
        self.received = self.detections = self.geometry_packets = self.late = 0
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
            det, geo = decode_wrapper(data)
        except MessageError as exc:
            self.drops.drop("undecodable", f"{len(data)} bytes, {exc}")
            return
        if geo is not None:
            self.geometry = geo
            self.geometry_packets += 1
        if det is None:
            return
        if det.camera_id not in self.camera_ids:
            self.drops.drop("unknown camera", f"camera {det.camera_id} is not in the config "
                            f"({', '.join(map(str, sorted(self.camera_ids)))})")  # fmt: skip
            return
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
            "field_m": None if g is None else [g.field_length_m, g.field_width_m]}))  # fmt: skip

    def close(self) -> None:
        self.receiver.close()


class RefereeOutStage(SocketStage):
    """Our referee's game state as the league's Referee message, multicast."""

    name = "ssl/referee_out"
    inputs = ("referee",)

    def __init__(self, params: ProtocolParams) -> None:
        r = params.referee
        self.sender = MulticastSender(r.group, r.port, params.interface, params.ttl)
        self.source = r.source_identifier

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        self.sender.send(referee_packet(message, self.source))

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {"packets": self.sender.sent}))

    def close(self) -> None:
        self.sender.close()


class RefereeInStage(SocketStage):
    """A game controller's Referee packets from multicast -> ``referee/gc`` game states, on every
    clock tick each packet that came since. On
    ``world_topic`` it watches the ball: once a kickoff's or penalty's restart is taken (the ball
    ``moved_m`` from the designated position), play is normal."""

    name = "ssl/referee_in"

    def __init__(self, params: ProtocolParams, world_topic: str, moved_m: float,
                 err: TextIO | None = None) -> None:  # fmt: skip
        r = params.referee
        self.receiver = MulticastReceiver(r.group, r.port, params.interface, params.receive_buffer_bytes,
                                          params.max_datagram_bytes)  # fmt: skip
        self.inputs = ("clock", world_topic)
        self.moved_m = moved_m
        self.reader = RefereeReader()
        self.drops = DropLog(f"referee {r.group}:{r.port}", params.drop_report_interval_s, err)
        self.received = 0
        self._last: bytes | None = None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == "clock":
            for data in self.receiver.drain():
                self._take(data, publish)
            return
        g, b = self.reader.last, message.ball
        taking = g is not None and g.command in ("kickoff", "penalty") and g.ready and g.placement is not None
        if taking and b is not None and self._last is not None and g is not None and g.placement is not None \
                and math.hypot(b.x - g.placement[0], b.y - g.placement[1]) > self.moved_m:  # fmt: skip
            self.reader.ball_moved()
            publish("referee/gc", self.reader.read(self._last))

    def _take(self, data: bytes, publish: Publish) -> None:
        self.received += 1
        try:
            game = self.reader.read(data)
        except MessageError as exc:
            self.drops.drop("undecodable", f"{len(data)} bytes, {exc}")
            return
        self._last = data
        publish("referee/gc", game)

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "packets": self.received, "dropped": dict(sorted(self.drops.counts.items()))}))  # fmt: skip

    def close(self) -> None:
        self.receiver.close()
