"""``cmdragons bench protocols``: the league's packets through loopback.

Per message kind, packets of a full field (every robot of both teams and the ball; one packet per
camera for detections) are encoded, sent, received and decoded (by our readers; grSim's by protobuf
alone) in one process, in batches that fit
the socket buffer: packets a second through the whole way, encoding alone (µs a packet), bytes,
and packets lost; beside each, how many a second a match needs (60 frames a second, one detection
packet per camera and frame). Multicast as the stages send it (interface 127.0.0.1, TTL 0);
commands as unicast to 127.0.0.1. Then the same seeded match on our cameras with no protocol and
with every protocol on (our vision through SSL-Vision packets into our tracker, tracker packets and
commands to a simulation-protocol port out), one after the other after a short warm-up match: the
packets each sent and received and the frame time both ways.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from cmdragons import messages as msg
from cmdragons.runtime.bus import run_frames
from cmdragons.runtime.proto import grsim_pb2 as grsim_pb
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.ssl.commands import (
    grsim_packet,
    read_robot_control,
    read_simulator_command,
    robot_control_packet,
    simulator_command_packet,
)
from cmdragons.runtime.ssl.referee import RefereeReader, referee_packet
from cmdragons.runtime.ssl.tracker import decode_tracker, tracker_packet
from cmdragons.runtime.ssl.udp import MulticastReceiver, MulticastSender, UdpEndpoint
from cmdragons.runtime.ssl.vision import decode_wrapper, detection_packet, geometry_packet

__all__ = ["run"]

_BATCH = 64  # packets sent before the receiver drains them (well inside a 4 MB buffer)
_FPS = 60.0


def _field(settings: Settings, rng: np.random.Generator) -> tuple[list[msg.DetectionFrame], msg.WorldState,
                                                                  msg.TeamCommands]:
    """One frame of a full field: each camera's detections, the world state, one team's commands."""
    n = {t: settings.sim.robots_per_team.get(t, settings.field.dims.robots_per_team) for t in ("blue", "yellow")}
    half = settings.field_geometry().half_length, settings.field_geometry().half_width
    robots = [(team, i, *(rng.uniform(-1, 1, 2) * half), rng.uniform(-math.pi, math.pi))
              for team in ("blue", "yellow") for i in range(n[team])]
    cams = settings.camera_models()
    dets = [msg.DetectionFrame(c.id, 7, 0.5, 0.501, (msg.BallDetection(0.3, -0.2, 0.9, (400.5, 300.25), 0.0005),),
                               tuple(msg.RobotDetection(t, i, x, y, th, 0.95, (100.0 + i, 200.0)) for t, i, x, y, th
                                     in robots)) for c in cams]
    world = msg.WorldState(0.5, msg.BallState(0.3, -0.2, 1.0, 0.5), tuple(
        msg.RobotState(t, i, x, y, th, 0.5, -0.5, 1.0) for t, i, x, y, th in robots), 7)
    commands = msg.TeamCommands("blue", 7, 0.5, tuple(msg.RobotCommand("blue", i, 1.0, -0.5, 0.5, 3.0, i % 2 == 0, 0.5)
                                                      for _, i, *_ in robots[: n["blue"]]))
    return dets, world, commands


def _through(send: Callable[[bytes], None], receive: Callable[[], bytes | None], decode: Callable[[bytes], Any],
             packets: list[bytes], count: int) -> tuple[float, int]:
    """Packets a second sent, received and decoded, and packets lost."""
    got = 0
    t0 = time.perf_counter()
    for start in range(0, count, _BATCH):
        batch = min(_BATCH, count - start)
        for k in range(batch):
            send(packets[(start + k) % len(packets)])
        deadline = time.perf_counter() + 1.0
        taken = 0
        while taken < batch and time.perf_counter() < deadline:
            data = receive()
            if data is None:
                continue
            decode(data)
            taken += 1
        got += taken
    wall = time.perf_counter() - t0
    return count / wall, count - got


def _unicast(decode: Callable[[bytes], Any], packets: list[bytes], count: int) -> tuple[float, int]:
    """:func:`_through` from one loopback UDP socket to another."""
    a, b = UdpEndpoint("127.0.0.1"), UdpEndpoint("127.0.0.1")

    def send(data: bytes) -> None:
        a.send_to(data, ("127.0.0.1", b.port))

    def receive() -> bytes | None:
        got = b.receive()
        return None if got is None else got[0]

    try:
        return _through(send, receive, decode, packets, count)
    finally:
        a.close()
        b.close()


def _row(name: str, packets: list[bytes], encode: Callable[[], bytes], needed_per_s: float,
         through: tuple[float, int], count: int) -> dict[str, Any]:
    t0 = time.perf_counter()
    reps = 200
    for _ in range(reps):
        encode()
    encode_us = (time.perf_counter() - t0) / reps * 1e6
    per_s, lost = through
    return {"name": name, "packets": count, "bytes": int(np.mean([len(p) for p in packets])),
            "encode_us": round(encode_us, 1), "packets_per_s": round(per_s), "lost": lost,
            "match_needs_per_s": needed_per_s, "headroom": round(per_s / needed_per_s, 1)}


def _packet_rows(settings: Settings, count: int) -> list[dict[str, Any]]:
    p = settings.protocols
    dets, world, commands = _field(settings, np.random.default_rng(1))
    cams = settings.camera_models()
    headings = {r.id: r.theta for r in world.robots if r.team == "blue"}
    chip = settings.sim.kicker.chip_angle_rad
    rpm = p.simulation.dribbler_full_rpm
    game = msg.GameState(12.5, msg.RefereeCommand.FREE_KICK, "blue", 1, 2, placement=(1.0, -0.5))
    teleport = msg.Teleport(1.0, tuple((r.team, r.id, r.x, r.y, r.theta) for r in world.robots), (0.0, 0.0))
    reader = RefereeReader()
    where = {(r.team, r.id): (r.x, r.y, r.theta) for r in world.robots}
    # (name, packets, encode one, decode, needed a second, multicast group or None for unicast)
    kinds: list[tuple[str, list[bytes], Callable[[], bytes], Callable[[bytes], Any], float, str | None]] = [
        (f"ssl_vision_detections_{len(cams)}_cameras", [detection_packet(d) for d in dets],
         lambda: detection_packet(dets[0]), decode_wrapper, _FPS * len(cams), p.vision.group),
        ("ssl_vision_geometry", [geometry_packet(settings.field_geometry(), cams)],
         lambda: geometry_packet(settings.field_geometry(), cams), decode_wrapper, 1.0 / p.vision.geometry_interval_s,
         p.vision.group),
        ("tracker_packet", [tracker_packet(world, "bench", "cmdragons")],
         lambda: tracker_packet(world, "bench", "cmdragons"), decode_tracker, _FPS, p.tracker.group),
        ("referee", [referee_packet(game)], lambda: referee_packet(game), reader.read, _FPS, p.referee.group),
        ("grsim_commands", [grsim_packet(commands, headings, chip)], lambda: grsim_packet(commands, headings, chip),
         grsim_pb.grSim_Packet.FromString, _FPS, None),
        ("robot_control", [robot_control_packet(commands, headings, chip, rpm)],
         lambda: robot_control_packet(commands, headings, chip, rpm),
         lambda d: read_robot_control(d, "blue", headings, rpm), _FPS, None),
        ("simulator_command", [simulator_command_packet(teleport)], lambda: simulator_command_packet(teleport),
         lambda d: read_simulator_command(d, 1.0, where, (0.0, 0.0)), 1.0, None),
    ]  # fmt: skip
    rows = []
    for name, packets, encode, decode, needed, group in kinds:
        if group is not None:
            rx = MulticastReceiver(group, 0, p.interface, p.receive_buffer_bytes, p.max_datagram_bytes)
            port = rx.sock.getsockname()[1]
            tx = MulticastSender(group, port, p.interface, p.ttl)
            try:
                through = _through(tx.send, rx.receive, decode, packets, count)
            finally:
                tx.close()
                rx.close()
        else:
            through = _unicast(decode, packets, count)
        rows.append(_row(name, packets, encode, needed, through, count))
    return rows


def _match_rows(settings: Settings, seconds: float) -> list[dict[str, Any]]:
    """The same match with every protocol on and with none: packets per match second, frame time."""
    from cmdragons.runtime.match import Match
    from cmdragons.runtime.settings import load_settings

    sink = UdpEndpoint("127.0.0.1")
    on = load_settings(None, ["protocols.vision.send=true", "protocols.perception=ssl_vision",
                              "protocols.tracker.send=true", "protocols.commands_to=simulation",
                              f"protocols.simulation.blue_port={sink.port}",
                              f"protocols.simulation.control_port={sink.port}"])
    rows = []
    try:
        # a short match first loads what the matches import and compile lazily (it is not reported)
        for name, s, secs in (("warm-up", on, 0.5), ("match_no_protocols", settings, seconds),
                              ("match_all_protocols", on, seconds)):
            match = Match(s, "simple", "vision", seed=1)
            try:
                def one_frame(_i: int, match: Match = match) -> None:
                    match.step()
                    sink.sock.setblocking(False)
                    while sink.receive() is not None:
                        pass

                frames = run_frames(one_frame, max(1, round(secs * _FPS)))
                summary = match.summary()
            finally:
                match.close()
            if name == "warm-up":
                continue
            pr = summary.get("protocols", {})
            frame = summary["cycle_ms"]["frame"]
            sent = sum(f.get("packets", 0) for k, f in pr.items() if k != "ssl/vision_in")
            rows.append({"name": f"{name}_{seconds:g}s", "frames": frames, "packets_sent": sent,
                         "packets_received": pr.get("ssl/vision_in", {}).get("packets", 0),
                         "sent_per_match_s": round(sent / seconds, 1), "frame_median_ms": round(frame["median"], 2),
                         "frame_p95_ms": round(frame["p95"], 2)})
    finally:
        sink.close()
    return rows


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    rows = _packet_rows(settings, 2000 if quick else 20000)
    rows += _match_rows(settings, 1.0 if quick else 4.0)
    return rows
