"""SSL-Vision packets: our sender -> our receiver on loopback reproduces the detections and the
geometry; the bytes decode with protoc as the league's SSL_WrapperPacket; bad packets are counted and
dropped; a match whose tracker reads SSL-Vision packets from our own sender plays as the in-process
one (the wire loses nothing that matters). Every socket is pinned to 127.0.0.1 with TTL 0."""

from __future__ import annotations

import dataclasses
import io
import math
import shutil
import socket
import subprocess
import time
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cmdragons import messages as msg
from cmdragons.config import ConfigError
from cmdragons.runtime import wire
from cmdragons.runtime.match import Match
from cmdragons.runtime.proto.generate import PROTO_DIR, ROOT
from cmdragons.runtime.proto.ssl_wrapper_pb2 import SSL_WrapperPacket
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.params import ProtocolParams
from cmdragons.runtime.ssl.stages import VisionInStage, close_sockets
from cmdragons.runtime.ssl.udp import MulticastReceiver, MulticastSender
from cmdragons.runtime.ssl.vision import decode_wrapper, detection_packet, geometry_packet
from cmdragons.runtime.stages import Tap

DET = msg.DetectionFrame(
    1, 42, 0.7, 0.702,
    (msg.BallDetection(0.5, -0.25, 0.9, (100.5, 200.25), 0.004),),
    (msg.RobotDetection("blue", 3, 1.0, 2.0, 0.5, 0.99, (10.0, 20.0)),
     msg.RobotDetection("yellow", 15, -1.0, -2.0, -3.0, 0.5, (30.0, 40.0))),
)


EPOCH = UnixEpoch(1_764_000_000)  # a Unix time of 2025, in whole seconds


def _same(a: msg.DetectionFrame, b: msg.DetectionFrame) -> bool:
    """The same detections, times to the microsecond (they crossed the wire as Unix time)."""
    return dataclasses.replace(a, t_capture=b.t_capture, t_sent=b.t_sent) == b and \
        abs(a.t_capture - b.t_capture) < 1e-6 and abs(a.t_sent - b.t_sent) < 1e-6


def _params(port: int, **extra: Any) -> ProtocolParams:
    s = load_settings(None, [f"protocols.vision.port={port}", *(f"protocols.{k}={v}" for k, v in extra.items())])
    return s.protocols


def test_the_defaults_are_the_leagues_and_stay_on_this_machine() -> None:
    for p in (ProtocolParams(), load_settings().protocols):
        assert (p.vision.group, p.vision.port) == ("224.5.23.2", 10006)
        assert (p.tracker.group, p.tracker.port) == ("224.5.23.2", 10010)
        assert (p.referee.group, p.referee.port) == ("224.5.23.1", 10003)
        assert (p.simulation.control_port, p.simulation.blue_port, p.simulation.yellow_port) == (10300, 10301, 10302)
        assert p.grsim.vision_port == 10020
        assert p.interface == "127.0.0.1" and p.ttl == 0 and not p.network
        assert p.perception == "simulator" and not p.vision.send


@pytest.mark.parametrize("override", ["protocols.interface=10.1.2.3", "protocols.vision.group=10.0.0.1",
                                      "protocols.grsim.address=192.168.1.5", "protocols.ttl=-1"])
def test_an_address_off_this_machine_or_a_bad_group_is_a_config_error(override: str) -> None:
    with pytest.raises(ConfigError):
        load_settings(None, [override])


def test_the_sender_is_pinned_to_loopback_with_ttl_0(udp_port: int) -> None:
    s = MulticastSender("224.5.23.2", udp_port, "127.0.0.1", 0)
    try:
        assert socket.inet_ntoa(s.sock.getsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, 4)) == "127.0.0.1"
        assert s.sock.getsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL) == 0
    finally:
        s.close()


def test_detections_and_geometry_cross_loopback_unchanged(udp_port: int) -> None:
    settings = load_settings()
    rx = MulticastReceiver("224.5.23.2", udp_port, "127.0.0.1", 1 << 20)
    tx = MulticastSender("224.5.23.2", udp_port, "127.0.0.1", 0)
    try:
        cams = settings.camera_models()
        tx.send(geometry_packet(settings.field_geometry(), cams))
        tx.send(detection_packet(DET, EPOCH))
        geo_data, det_data = rx.receive(2.0), rx.receive(2.0)
    finally:
        tx.close()
        rx.close()
    assert geo_data is not None and det_data is not None
    det, none = decode_wrapper(det_data, EPOCH, camera_clock=True)  # our own packet: the camera clock's time
    assert none is None and det == dataclasses.replace(wire.canonical(DET), t_sent=det.t_sent)  # to the bit
    assert det.t_sent == pytest.approx(DET.t_sent, abs=1e-6)  # through Unix time: to the microsecond
    sent = SSL_WrapperPacket.FromString(det_data).detection  # Unix time on the wire, the match's in the camera's
    assert (sent.t_capture, sent.t_sent, sent.t_capture_camera) == (EPOCH.epoch_s + 0.7, EPOCH.epoch_s + 0.702, 0.7)
    # SSL-Vision counts pixels from the centre of the top-left pixel, we from its corner
    assert (sent.balls[0].pixel_x, sent.balls[0].pixel_y, sent.robots_blue[0].pixel_x) == (100.0, 199.75, 9.5)
    other, _ = decode_wrapper(det_data, EPOCH)  # anyone's packet: Unix time less the epoch
    assert (other.t_capture, other.t_sent) == pytest.approx((0.7, 0.702), abs=1e-6)
    assert det.robots[1].x == pytest.approx(-1.0, abs=1e-6) and det.balls[0].sigma_m == pytest.approx(0.004)
    _, geo = decode_wrapper(geo_data)
    assert geo is not None
    d = settings.field.dims
    assert (geo.field_length_m, geo.field_width_m, geo.goal_width_m) == (d.length_m, d.width_m, d.goal_width_m)
    assert geo.penalty_area_depth_m == d.defense_depth_m and geo.center_circle_radius_m == d.center_circle_radius_m
    assert len(geo.lines) == 12 and [a.name for a in geo.arcs] == ["CenterCircle"]
    assert geo.acc_roll_m_s2 == pytest.approx(settings.field.ball.acc_roll_m_s2)
    assert [c.camera_id for c in geo.cameras] == [c.id for c in cams]
    for c, cam in zip(geo.cameras, cams, strict=True):
        assert c.position_m == pytest.approx(tuple(cam.center), abs=1e-4)
        assert c.focal_px == pytest.approx(cam.f, rel=1e-6) and c.resolution_px == (cam.width, cam.height)
        # the rotation and translation put the camera's own centre at the camera frame's origin
        r = Rotation.from_quat(c.quaternion).as_matrix()
        assert r @ cam.center + c.translation_m == pytest.approx([0.0, 0.0, 0.0], abs=1e-4)
        assert np.allclose(r @ cam.R_cam_to_field, np.eye(3), atol=1e-6)


NO_PROTOC = "Debian's protoc (apt-get install protobuf-compiler) is the independent decoder"


@pytest.mark.skipif(shutil.which("protoc") is None, reason=NO_PROTOC)
def test_wrapper_bytes_decode_with_protoc_as_ssl_wrapper_packet() -> None:
    settings = load_settings()
    schema = str((PROTO_DIR / "ssl_wrapper.proto").relative_to(ROOT))
    for data, expect in ((detection_packet(DET), ["frame_number: 42", "robot_id: 15", "x: -1000"]),
                         (geometry_packet(settings.field_geometry(), settings.camera_models()),
                          ["field_length: 9000", "name: \"CenterCircle\"", "camera_id: 1"])):
        out = subprocess.run(["protoc", f"-I{ROOT}", "--decode=cmdragons.league.SSL_WrapperPacket", schema],
                             input=data, capture_output=True, check=True).stdout.decode()
        for line in expect:
            assert line in out, (line, out)


def test_bad_packets_are_counted_and_dropped_with_a_line(udp_port: int) -> None:
    p = _params(udp_port)
    err = io.StringIO()
    rx = VisionInStage(p, [0, 1], lockstep=False, err=err)
    rx.drops.interval_s = 0.0  # a line for every drop here
    tx = MulticastSender(p.vision.group, udp_port, p.interface, p.ttl)
    good = detection_packet(DET)
    try:
        for data in (b"\xff\x13garbage", good[: len(good) // 2], detection_packet(msg.DetectionFrame(7, 1, 0.0, 0.0)),
                     good, good, detection_packet(msg.DetectionFrame(1, 41, 0.68, 0.68))):
            tx.send(data)
        got: list[tuple[str, Any]] = []
        for _ in range(50):
            rx.on_message("clock", msg.Tick(0), lambda topic, m: got.append((topic, m)))
            if rx.received == 6:
                break
            time.sleep(0.02)
    finally:
        close_sockets([rx])
        tx.close()
    # camera 7 is not in the config: taken all the same (a field of eight cameras, grSim's four)
    assert [t for t, _ in got] == ["ssl/vision/7", "ssl/vision/1"] and _same(got[1][1], wire.canonical(DET))
    assert rx.drops.counts == {"undecodable": 2, "duplicate": 2} and rx.cameras_seen == {1, 7}
    lines = err.getvalue().splitlines()
    assert len(lines) == 4 and "duplicate: camera 1 frame 42 after frame 42" in lines[2]


def _worlds(settings_overrides: list[str], seconds: float) -> tuple[list[msg.WorldState], dict[str, Any]]:
    worlds: list[msg.WorldState] = []
    settings = load_settings(None, settings_overrides)
    match = Match(settings, "simple", "vision", seed=3, extra=[Tap("worlds", ("world/blue",),
                                                                   lambda _t, w: worlds.append(w))])
    try:
        summary = match.run(seconds)
    finally:
        match.close()
    return worlds, summary


@pytest.mark.slow
def test_a_match_on_our_own_ssl_vision_packets_plays_as_the_in_process_one(udp_port: int) -> None:
    seconds = 1.0
    direct, s0 = _worlds([], seconds)
    wired, s1 = _worlds([f"protocols.vision.port={udp_port}", "protocols.vision.send=true",
                         "protocols.perception=ssl_vision"], seconds)
    frames = round(seconds * 60)
    assert len(direct) == frames and wired == direct  # every world state the same, to the bit
    assert s1["tracker"] == s0["tracker"] and s1["score"] == s0["score"]
    ins, out = s1["protocols"]["ssl/vision_in"], s1["protocols"]["ssl/vision_out"]
    cameras = len(load_settings().camera_models())
    assert out["packets"] == frames * cameras + out["geometry_packets"] and out["geometry_packets"] == 1
    assert ins["detections"] == frames * cameras and ins["dropped"] == {} and ins["frames_late"] == 0
    assert ins["field_m"] == [9.0, 6.0]
    seen = [w for w in wired if w.ball is not None and w.ball.visible]
    assert len(seen) > frames // 2 and all(math.isfinite(r.x) for w in wired for r in w.robots)
    assert "protocols" not in s0


