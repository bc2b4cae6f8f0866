"""A match in an outside simulator (``play --simulator grsim|sim-protocol``): the frame gate keeps
each camera's newest frame, the cameras and the field are learnt from the simulator's packets,
the set-up is a checked table, grSim's commands go again each vision frame, and our team plays
yellow in a simulator it reaches only through the league's protocols (our own embedded match
serving the simulation protocol, in a thread): its tracked robots where the simulator's truth has
them. Every socket on 127.0.0.1, TTL 0, on ports free at the time."""

from __future__ import annotations

import itertools
import math
import socket
import threading
from typing import Any

import numpy as np
import pytest

from cmdragons import messages as msg
from cmdragons.geometry import Field
from cmdragons.runtime.match import Match
from cmdragons.runtime.outside import (
    NO_REFEREE,
    FrameGate,
    OutsideError,
    OutsideMatch,
    SimulatorKind,
    field_settings,
    listen,
    outside_wiring,
    vision_params,
)
from cmdragons.runtime.proto import grsim_pb2 as grsim_pb
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.stages import CommandsOutStage
from cmdragons.runtime.ssl.udp import DatagramQueue, MulticastReceiver, UdpEndpoint
from cmdragons.runtime.ssl.vision import decode_wrapper, geometry_packet
from cmdragons.runtime.ssl.vision import detection_packet as packet
from cmdragons.runtime.stages import Tap
from cmdragons.runtime.topics import check_wiring


def _det(camera: int, frame: int) -> bytes:
    return packet(msg.DetectionFrame(camera, frame, frame / 60, frame / 60, (), ()))


def _queue(*items: bytes) -> DatagramQueue:
    q = DatagramQueue()
    for item in items:
        q.push(item)
    return q


def _frames(datagrams: list[bytes]) -> list[tuple[int, int] | None]:
    out = []
    for d in datagrams:
        try:
            det, _ = decode_wrapper(d)
        except msg.MessageError:
            out.append(None)
            continue
        out.append(None if det is None else (det.camera_id, det.frame_number))
    return out


def test_the_gate_keeps_each_cameras_newest_frame_and_counts_those_passed_over() -> None:
    settings = load_settings()
    geometry = geometry_packet(settings.field_geometry(), settings.camera_models())
    gate = FrameGate(_queue(_det(0, 1), _det(1, 1), geometry, _det(0, 2), b"\x01garbage", _det(1, 2), _det(3, 7)))
    assert gate.wait(0.0)
    got = gate.drain()
    # frame 1 of cameras 0 and 1 passed over (one frame), the geometry and the garbage kept for the stage
    assert _frames(got) == [None, (0, 2), None, (1, 2), (3, 7)]
    assert got[0] == geometry and got[2] == b"\x01garbage"
    assert gate.skipped == 1
    assert not gate.wait(0.0) and gate.drain() == []


def _clock(step_s: float) -> Any:
    ticks = itertools.count()
    return lambda: next(ticks) * step_s


def test_listening_learns_the_cameras_that_send_and_the_geometry() -> None:
    settings = load_settings()
    geometry = geometry_packet(settings.field_geometry(), settings.camera_models())  # calibrates cameras 0 and 1
    heard = listen(_queue(_det(3, 1), _det(7, 1), geometry, _det(3, 2)), 5.0, 0.1, "here", _clock(0.01))
    assert heard.cameras == (3, 7)
    assert heard.geometry.field_length_m == pytest.approx(9.0)
    assert heard.packets == 4
    assert heard.uncalibrated == (3, 7)


def test_no_geometry_or_detections_in_time_is_an_error_naming_where_it_listened() -> None:
    with pytest.raises(OutsideError, match=r"224\.5\.23\.2:10020 in 1 s \(2 packets heard.*none with a geometry\)"):
        listen(_queue(_det(0, 1), _det(0, 2)), 1.0, 0.1, "224.5.23.2:10020", _clock(0.01))
    settings = load_settings()
    geometry = geometry_packet(settings.field_geometry(), settings.camera_models())
    with pytest.raises(OutsideError, match=r"none with a detection\)"):
        listen(_queue(geometry), 1.0, 0.1, "here", _clock(0.01))
    with pytest.raises(OutsideError, match=r"\(nothing heard\)"):
        listen(_queue(), 1.0, 0.1, "here", _clock(0.01))


def test_the_field_is_the_simulators_and_a_difference_is_one_line() -> None:
    b = load_settings()
    a_field = Field(load_settings(None, ["field.division=A"]).field)
    geometry = decode_wrapper(geometry_packet(a_field, []))[1]
    assert geometry is not None
    played, line = field_settings(b, geometry)
    dims = played.field.dims
    assert played.field.division == "A"
    assert (dims.length_m, dims.width_m, dims.goal_width_m) == pytest.approx((12.0, 9.0, 1.8))
    assert (dims.defense_depth_m, dims.defense_width_m) == pytest.approx((1.8, 3.6))
    assert line is not None and "\n" not in line
    assert "division A (field.yaml B)" in line and "length 12.000 m (field.yaml 9.000)" in line
    # the same field as field.yaml's: nothing said, nothing changed
    same = decode_wrapper(geometry_packet(b.field_geometry(), []))[1]
    assert same is not None
    played, line = field_settings(b, same)
    assert line is None and played.field.dims == b.field.dims
    # a lab's field: the nearest division, with the lab's numbers
    lab_settings = load_settings(None, ["field.divisions.B.length_m=5.54", "field.divisions.B.width_m=4.0"])
    lab = decode_wrapper(geometry_packet(Field(lab_settings.field), []))[1]
    assert lab is not None
    played, line = field_settings(b, lab)
    assert played.field.division == "B" and (played.field.dims.length_m, played.field.dims.width_m) == (5.54, 4.0)
    assert line is not None and "(field.yaml B)" not in line and "width 4.000 m (field.yaml 6.000)" in line


@pytest.mark.parametrize("kind", [SimulatorKind.GRSIM, SimulatorKind.SIM_PROTOCOL])
@pytest.mark.parametrize("teams", [["blue"], ["yellow"], ["blue", "yellow"]])
def test_the_set_up_is_a_checked_table_without_our_simulator(kind: SimulatorKind, teams: list[Any]) -> None:
    settings = load_settings()
    table = outside_wiring(settings, kind, teams, [0, 1, 2, 3], DatagramQueue())
    check_wiring([e.contract for e in table], NO_REFEREE)
    names = {e.contract.name for e in table}
    assert not names & {"sim", "referee"} and not any(n.startswith(("vision/", "perception/")) for n in names)
    for team in teams:
        assert {f"tracker/{team}", f"team/{team}", f"ssl/commands_out/{team}"} <= names
    tracker = next(e.contract for e in table if e.contract.name == f"tracker/{teams[0]}")
    assert [p.topic for p in tracker.reads][:4] == [f"ssl/vision/{c}" for c in range(4)]
    p = vision_params(settings.protocols, kind)
    assert p.vision.port == 10020 and p.commands_to == ("grsim" if kind is SimulatorKind.GRSIM else "simulation")


def _free_ports(n: int) -> list[int]:
    socks = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(n)]
    for s in socks:
        s.bind(("127.0.0.1", 0))
    ports = [int(s.getsockname()[1]) for s in socks]
    for s in socks:
        s.close()
    return ports


def test_grsim_hears_the_last_commands_again_on_each_vision_frame(udp_port: int) -> None:
    settings = load_settings(None, [f"protocols.grsim.port={udp_port}"])
    p = vision_params(settings.protocols, SimulatorKind.GRSIM)
    grsim = UdpEndpoint("127.0.0.1", udp_port)
    stage = CommandsOutStage(p, "blue", 0.0)
    try:
        world = msg.WorldState(0.0, None, (msg.RobotState("blue", 2, 0.0, 0.0, 0.0),))
        sent = msg.TeamCommands("blue", 1, 0.0, (msg.RobotCommand("blue", 2, vx=1.0),))
        stage.on_message("world/blue", world, lambda *_: None)  # nothing sent yet: nothing to resend
        stage.on_message("commands/blue", sent, lambda *_: None)
        turned = msg.WorldState(0.02, None, (msg.RobotState("blue", 2, 0.0, 0.0, math.pi / 2),))
        stage.on_message("world/blue", turned, lambda *_: None)  # the next vision frame
        got = []
        while (d := grsim.receive(0.5)) is not None:
            packet = grsim_pb.grSim_Packet()
            packet.ParseFromString(d[0])
            c = packet.commands.robot_commands[0]
            got.append((c.id, round(c.veltangent, 6), round(c.velnormal, 6)))
        # the field-frame velocity +x: forward for a robot facing +x, to its right once it faces +y
        assert got == [(2, 1.0, 0.0), (2, 0.0, -1.0)]
        assert stage.resent == 1 and stage.sent == 1
    finally:
        stage.close()
        grsim.close()


@pytest.mark.slow
def test_our_team_plays_yellow_in_a_simulator_it_reaches_only_by_the_leagues_protocols() -> None:
    vision, control, blue, yellow = _free_ports(4)
    overrides = [f"protocols.vision.port={vision}", f"protocols.simulation.vision_port={vision}",
                 f"protocols.simulation.control_port={control}", f"protocols.simulation.blue_port={blue}",
                 f"protocols.simulation.yellow_port={yellow}", "protocols.outside.frame_wait_s=1.0",
                 "protocols.outside.learn_s=0.3", "protocols.simulation.wait_s=0.2"]  # fmt: skip
    settings = load_settings(None, overrides)
    # the outside simulator: our own match serving yellow over the simulation protocol, its vision
    # as SSL-Vision packets (noisy truth, one camera)
    served = Match(settings, "simulation", "truth", seed=5)
    truths: list[msg.GroundTruth] = []
    served.bus.add(Tap("truths", ("truth",), lambda _t, m: truths.append(m)))
    worlds: list[msg.WorldState] = []
    errors: list[BaseException] = []
    done = threading.Event()
    summary: dict[str, Any] = {}

    def ours() -> None:
        p = vision_params(settings.protocols, SimulatorKind.SIM_PROTOCOL)
        receiver = MulticastReceiver(p.vision.group, p.vision.port, p.interface, p.receive_buffer_bytes)
        try:
            heard = listen(receiver, 20.0, settings.protocols.outside.learn_s, "test")
            played, line = field_settings(settings, heard.geometry)
            assert line is None
            match = OutsideMatch(played, SimulatorKind.SIM_PROTOCOL, ["yellow"], heard, receiver,
                                 [Tap("worlds", ("world/yellow",), lambda _t, m: worlds.append(m))])  # fmt: skip
            try:
                match.skip_stale()
                summary.update(match.run(60.0, done.is_set))
            finally:
                match.close()
        except BaseException as exc:  # noqa: BLE001 (handed to the test's thread)
            errors.append(exc)
        finally:
            done.set()

    thread = threading.Thread(target=ours)
    thread.start()
    try:
        for _ in range(900):  # 15 s of the served match
            if done.is_set():
                break
            served.step()
    finally:
        done.set()
        thread.join(60.0)
        served.close()
    assert not errors, errors
    assert summary["frames"] > 200 and summary["cameras"] == [0]
    # our tracker saw yellow where the served simulator's truth had it (at the tracked time: the
    # tracker hands on its state predicted to the time the commands act)
    times = np.array([g.t for g in truths])
    err = []
    for w in worlds[30:]:
        g = truths[int(np.argmin(np.abs(times - w.t)))]
        true = {r.id: (r.x, r.y) for r in g.robots if r.team == "yellow"}
        err += [math.hypot(r.x - true[r.id][0], r.y - true[r.id][1]) for r in w.robots
                if r.team == "yellow" and r.id in true]  # fmt: skip
    assert len(err) > 1000 and float(np.percentile(err, 95)) < 0.08
    # and it played: yellow's robots went for the ball in the served simulator
    near = [min(math.hypot(r.x - g.ball.x, r.y - g.ball.y) for r in g.robots if r.team == "yellow") for g in truths]
    assert min(near[len(near) // 3 :]) < 0.15
    assert summary["protocols"]["ssl/commands_out/yellow"]["answers"] > 100
