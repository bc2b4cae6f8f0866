"""Tracker packets out, commands to grSim and to a simulation-protocol simulator, and our own
simulator taking the simulation protocol: every message round trips, its bytes decode with protoc,
the multicast stays on loopback with TTL 0, a team outside moves its robots in our simulator over
loopback UDP and teleports the ball, and bad packets are counted and dropped with a line."""

from __future__ import annotations

import dataclasses
import io
import math
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from typing import Any

import pytest

from cmdragons import messages as msg
from cmdragons.runtime import wire
from cmdragons.runtime.match import Match
from cmdragons.runtime.proto import grsim_pb2 as grsim_pb
from cmdragons.runtime.proto import ssl_simulation_control_pb2 as ctl_pb
from cmdragons.runtime.proto import ssl_simulator_pb2 as sim_pb
from cmdragons.runtime.proto import ssl_tracked_pb2 as trk_pb
from cmdragons.runtime.proto.generate import PROTO_DIR, ROOT
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.commands import (
    UNSUPPORTED,
    Feedback,
    SimError,
    grsim_packet,
    local_velocity,
    read_robot_control,
    read_robot_control_response,
    read_simulator_command,
    robot_control_packet,
    robot_control_response,
    simulator_command_packet,
    simulator_response,
    to_field,
)
from cmdragons.runtime.ssl.stages import SimulationInStage, TrackerOutStage, close_sockets
from cmdragons.runtime.ssl.tracker import decode_tracker, tracker_packet
from cmdragons.runtime.ssl.udp import MulticastReceiver, UdpEndpoint
from cmdragons.runtime.stages import Tap
from tests.runtime.conftest import free_udp_ports

NO_PROTOC = "Debian's protoc (apt-get install protobuf-compiler) is the independent decoder"
F32 = 1e-6  # the wire's 32-bit floats, relative

WORLD = msg.WorldState(
    1.25, msg.BallState(0.5, -0.25, 1.5, -0.5, True),
    (msg.RobotState("blue", 3, 1.0, 2.0, 0.5, 0.1, -0.2, 0.3, True),
     msg.RobotState("yellow", 15, -1.0, -2.0, -3.0, 0.0, 0.0, 0.0, False)), 77)
COMMANDS = msg.TeamCommands("blue", 77, 1.25, (
    msg.RobotCommand("blue", 3, 1.0, -0.5, 0.25, 4.0, False, 0.0),
    msg.RobotCommand("blue", 4, -0.3, 0.7, -1.0, 3.0, True, 0.5)))
HEADINGS = {3: 0.5, 4: -2.0}
CHIP = math.radians(45.0)


def _protoc(schema: str, message: str, data: bytes) -> str:
    path = str((PROTO_DIR / schema).relative_to(ROOT))
    return subprocess.run(["protoc", f"-I{ROOT}", f"--decode=cmdragons.league.{message}", path], input=data,
                          capture_output=True, check=True).stdout.decode()


@pytest.mark.parametrize("theta", [0.0, 0.5, -2.0, math.pi])
def test_local_velocity_is_the_field_velocity_in_the_robots_frame(theta: float) -> None:
    forward, left = local_velocity(math.cos(theta), math.sin(theta), theta)  # along the heading
    assert (forward, left) == pytest.approx((1.0, 0.0), abs=1e-12)
    forward, left = local_velocity(-math.sin(theta), math.cos(theta), theta)  # to the robot's left
    assert (forward, left) == pytest.approx((0.0, 1.0), abs=1e-12)
    assert to_field(*local_velocity(0.3, -0.7, theta), theta) == pytest.approx((0.3, -0.7), abs=1e-12)


def test_tracker_packets_round_trip() -> None:
    uuid, source, world = decode_tracker(tracker_packet(WORLD, "abc-1", "cmdragons"))
    assert (uuid, source) == ("abc-1", "cmdragons")
    assert world == wire.canonical(WORLD)
    assert world is not None and world.robots[0].theta == pytest.approx(0.5, rel=F32)


def test_grsim_commands_round_trip_in_the_robots_frame() -> None:
    p = grsim_pb.grSim_Packet()
    p.ParseFromString(grsim_packet(COMMANDS, HEADINGS, CHIP))
    assert p.commands.isteamyellow is False and p.commands.timestamp == 1.25
    for c, g in zip(COMMANDS.commands, p.commands.robot_commands, strict=True):
        assert g.id == c.id and not g.wheelsspeed and g.spinner == (c.dribbler > 0)
        assert to_field(g.veltangent, g.velnormal, HEADINGS[c.id]) == pytest.approx((c.vx, c.vy), abs=1e-6)
        assert g.velangular == pytest.approx(c.omega, rel=F32)
        angle = CHIP if c.chip else 0.0
        assert (g.kickspeedx, g.kickspeedz) == pytest.approx((c.kick_speed * math.cos(angle),
                                                              c.kick_speed * math.sin(angle)), rel=F32)


def test_grsim_holds_the_ball_for_an_armed_kicker_when_asked() -> None:
    """grSim kicks only a ball touching as the packet arrives: with ``hold_armed`` an armed kicker's
    robot has its spinner on (grSim then holds a touching ball until the next packet kicks it), a
    robot not kicking keeps its own dribbler."""
    commands = msg.TeamCommands("blue", 1, 0.0, (msg.RobotCommand("blue", 0, kick_speed=3.0),
                                                 msg.RobotCommand("blue", 1, 1.0, dribbler=0.0),
                                                 msg.RobotCommand("blue", 2, dribbler=0.5)))
    for hold, spinners in ((False, [False, False, True]), (True, [True, False, True])):
        p = grsim_pb.grSim_Packet()
        p.ParseFromString(grsim_packet(commands, {}, CHIP, hold))
        assert [g.spinner for g in p.commands.robot_commands] == spinners


def test_robot_control_round_trips_through_our_reader() -> None:
    data = robot_control_packet(COMMANDS, HEADINGS, CHIP, 10000.0)
    m = ctl_pb.RobotControl()
    m.ParseFromString(data)
    assert not m.HasField("team") and all(r.move_command.WhichOneof("command") == "local_velocity"
                                          for r in m.robot_commands)
    back = read_robot_control(data, "blue", HEADINGS, 10000.0)
    assert back.errors == ()
    for c, b in zip(COMMANDS.commands, back.commands, strict=True):
        assert (b.team, b.id, b.chip) == (c.team, c.id, c.chip)
        assert (b.vx, b.vy, b.omega, b.kick_speed, b.dribbler) == pytest.approx(
            (c.vx, c.vy, c.omega, c.kick_speed, c.dribbler), abs=1e-6)


def test_robot_control_with_wheel_velocities_is_refused_per_robot() -> None:
    m = ctl_pb.RobotControl()
    m.robot_commands.add(id=1).move_command.wheel_velocity.CopyFrom(
        ctl_pb.MoveWheelVelocity(front_right=1, back_right=1, back_left=1, front_left=1))
    g = m.robot_commands.add(id=2).move_command.global_velocity
    g.vel_x, g.vel_y, g.vel_angular = 0.5, 0.25, 1.0
    read = read_robot_control(m.SerializeToString(), "yellow", {}, 10000.0)
    assert [c.id for c in read.commands] == [2] and (read.commands[0].vx, read.commands[0].vy) == (0.5, 0.25)
    assert [i for i, _ in read.errors] == [1] and "wheel_velocity" in read.errors[0][1]


def test_simulator_command_round_trips() -> None:
    tp = msg.Teleport(2.0, (("blue", 1, 0.5, -0.5, 1.0), ("yellow", 2, -1.0, 1.0, -2.0)), (0.25, 0.75))
    where = {("blue", 1): (0.0, 0.0, 0.0), ("yellow", 2): (0.0, 0.0, 0.0)}
    back, refused = read_simulator_command(simulator_command_packet(tp), 2.0, where, (0.0, 0.0))
    assert refused == [] and back is not None and back.t == 2.0
    assert [r[:2] for r in back.robots] == [("blue", 1), ("yellow", 2)]
    for got, want in zip(back.robots, tp.robots, strict=True):
        assert got[2:] == pytest.approx(want[2:], rel=F32)
    assert back.ball == pytest.approx(tp.ball, rel=F32)
    # a coordinate left out keeps the object's own; an unknown robot is refused
    m = sim_pb.SimulatorCommand()
    m.control.teleport_robot.add(id=trk_pb.RobotId(id=1, team=trk_pb.BLUE), x=2.0)
    m.control.teleport_robot.add(id=trk_pb.RobotId(id=9, team=trk_pb.BLUE), x=2.0)
    back, refused = read_simulator_command(m.SerializeToString(), 0.0, {("blue", 1): (0.1, 0.2, 0.3)}, (0.0, 0.0))
    assert back is not None and back.robots == (("blue", 1, 2.0, pytest.approx(0.2), pytest.approx(0.3)),)
    assert len(refused) == 1 and "no such robot" in refused[0] and back.ball is None


@pytest.mark.skipif(shutil.which("protoc") is None, reason=NO_PROTOC)
def test_every_message_sent_decodes_with_protoc() -> None:
    data = tracker_packet(WORLD, "u-1", "cmdragons", UnixEpoch(1_764_000_000))
    out = _protoc("ssl_tracker_wrapper.proto", "TrackerWrapperPacket", data)
    for line in ("uuid: \"u-1\"", "frame_number: 77", "timestamp: 1764000001.25", "team: YELLOW", "id: 15"):
        assert line in out, (line, out)
    out = _protoc("grsim.proto", "grSim_Packet", grsim_packet(COMMANDS, HEADINGS, CHIP))
    assert "isteamyellow: false" in out and "veltangent:" in out and "spinner: true" in out and "id: 4" in out
    out = _protoc("ssl_simulation_control.proto", "RobotControl", robot_control_packet(COMMANDS, HEADINGS, CHIP, 1e4))
    assert "local_velocity" in out and "kick_angle: 45" in out and "dribbler_speed: 5000" in out
    tp = msg.Teleport(0.0, (("yellow", 2, -1.0, 1.0, -2.0),), (0.25, 0.75))
    out = _protoc("ssl_simulator.proto", "SimulatorCommand", simulator_command_packet(tp))
    assert "teleport_ball" in out and "x: 0.25" in out and "team: YELLOW" in out and "present: true" in out
    out = _protoc("ssl_simulator.proto", "RobotControlResponse",
                  robot_control_response([Feedback(3)], [SimError(UNSUPPORTED, "robot 4: no")]))
    assert "message: \"robot 4: no\"" in out and "feedback {\n  id: 3\n}" in out
    out = _protoc("ssl_simulator.proto", "SimulatorResponse",
                  simulator_response([SimError(UNSUPPORTED, "config: not here")]))
    assert "message: \"config: not here\"" in out


def test_a_match_multicasts_its_world_states_as_tracker_packets(udp_port: int) -> None:
    settings = load_settings(None, ["protocols.tracker.send=true", f"protocols.tracker.port={udp_port}"])
    rx = MulticastReceiver("224.5.23.2", udp_port, "127.0.0.1", 1 << 22)
    worlds: list[msg.WorldState] = []
    tap = Tap("w", ("world/blue",), lambda _t, w: worlds.append(w))
    match = Match(settings, "simple", "truth", seed=1, extra=[tap])
    try:
        sender = next(s for s in match.bus.stages if isinstance(s, TrackerOutStage))
        sock = sender.sender.sock
        assert socket.inet_ntoa(sock.getsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, 4)) == "127.0.0.1"
        assert sock.getsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL) == 0
        for _ in range(12):
            match.step()
        got = [decode_tracker(d) for d in rx.drain()]
        summary = match.summary()
    finally:
        match.close()
        rx.close()
    assert len(got) == len(worlds) == 12 and len({u for u, _, _ in got}) == 1
    back = [w for _, _, w in got]  # world states on the bus are already in their wire form; times via Unix time
    assert [dataclasses.replace(w, t=want.t) for w, want in zip(back, worlds, strict=True)] == worlds
    assert [w.t for w in back] == pytest.approx([w.t for w in worlds], abs=1e-6)
    assert summary["protocols"]["ssl/tracker_out/blue"]["packets"] == 12


@pytest.mark.parametrize("to", ["grsim", "simulation"])
def test_a_match_sends_our_commands_to_a_league_simulator(to: str) -> None:
    peer = UdpEndpoint("127.0.0.1")
    port_key = "grsim.port" if to == "grsim" else "simulation.blue_port"
    control = UdpEndpoint("127.0.0.1")
    settings = load_settings(None, [f"protocols.commands_to={to}", f"protocols.{port_key}={peer.port}",
                                    f"protocols.simulation.control_port={control.port}"])
    worlds: list[msg.WorldState] = []
    sent: list[msg.TeamCommands] = []
    extra = [Tap("w", ("world/blue", "commands/blue"),
                 lambda t, m: (worlds if t.startswith("world") else sent).append(m))]
    match = Match(settings, "simple", "truth", seed=1, extra=extra)
    try:
        packets: list[bytes] = []
        for _ in range(10):
            match.step()
            while (got := peer.receive(0.5 if len(packets) < len(sent) else 0.0)) is not None:
                packets.append(got[0])
        teleports = [d for d, _ in iter(lambda: control.receive(0.2), None)]
        summary = match.summary()
    finally:
        match.close()
        peer.close()
        control.close()
    if to == "grsim":  # grSim hears the last commands again on each vision frame, before the frame's own
        chip = settings.sim.kicker.chip_angle_rad
        hold = settings.protocols.grsim.hold_armed
        assert packets[1::2] == [grsim_packet(tc, {r.id: r.theta for r in w.robots if r.team == "blue"}, chip, hold)
                                 for tc, w in zip(sent[:-1], worlds[1:], strict=True)]  # (in the robots' new headings)
        packets = packets[0::2]
    assert len(packets) == len(sent) == 10
    for data, tc, world in zip(packets, sent, worlds, strict=True):
        headings = {r.id: r.theta for r in world.robots if r.team == "blue"}
        if to == "grsim":
            p = grsim_pb.grSim_Packet()
            p.ParseFromString(data)
            rows = [(g.id, *to_field(g.veltangent, g.velnormal, headings[g.id]), g.velangular)
                    for g in p.commands.robot_commands]
        else:
            back = read_robot_control(data, "blue", headings, settings.protocols.simulation.dribbler_full_rpm)
            rows = [(c.id, c.vx, c.vy, c.omega) for c in back.commands]
        assert [r[0] for r in rows] == [c.id for c in tc.commands]
        for r, c in zip(rows, tc.commands, strict=True):
            assert r[1:] == pytest.approx((c.vx, c.vy, c.omega), abs=1e-5)
    figures = summary["protocols"]["ssl/commands_out/blue"]
    assert figures["packets"] == 10 and figures["to"] == to
    # the simulator also gets our referee's kickoff formation as a SimulatorCommand (grSim takes it
    # on the simulation protocol's control port too)
    assert len(teleports) >= 1
    cmd = sim_pb.SimulatorCommand()
    cmd.ParseFromString(teleports[0])
    assert len(cmd.control.teleport_robot) > 0


def _outside_match(**extra: Any) -> tuple[Match, list[msg.GroundTruth], dict[str, int]]:
    control, yellow = free_udp_ports(2)
    settings = load_settings(None, [f"protocols.simulation.control_port={control}",
                                    f"protocols.simulation.yellow_port={yellow}", "protocols.simulation.wait_s=0",
                                    *(f"protocols.{k}={v}" for k, v in extra.items())])
    truths: list[msg.GroundTruth] = []
    match = Match(settings, "simulation", "truth", seed=1, extra=[Tap("t", ("truth",), lambda _t, g: truths.append(g))])
    return match, truths, {"control": control, "yellow": yellow}


def _robot(gt: msg.GroundTruth, team: str, rid: int) -> msg.RobotTruth:
    return next(r for r in gt.robots if r.team == team and r.id == rid)


@pytest.mark.parametrize("kind", ["global", "local"])
def test_a_team_outside_drives_its_robot_in_our_simulator_over_udp(kind: str) -> None:
    match, truths, ports = _outside_match()
    client = UdpEndpoint("127.0.0.1")
    answers = 0
    try:
        match.step()
        start = _robot(truths[-1], "yellow", 1)
        want = (0.0, 1.0) if kind == "global" else (math.cos(start.theta + 0.0), math.sin(start.theta))
        for _ in range(45):  # 0.75 s, a command every frame as a team sends them
            m = ctl_pb.RobotControl()
            r = m.robot_commands.add(id=1)
            if kind == "global":
                g = r.move_command.global_velocity
                g.vel_x, g.vel_y, g.vel_angular = *want, 0.0
            else:
                v = r.move_command.local_velocity
                v.forward, v.left, v.angular = 1.0, 0.0, 0.0
            client.send_to(m.SerializeToString(), ("127.0.0.1", ports["yellow"]))
            match.step()
            while (got := client.receive()) is not None:
                resp = read_robot_control_response(got[0])
                assert [f.id for f in resp.feedback] == [1] and not resp.errors and not resp.earlier_layout
                answers += 1
        summary = match.summary()
    finally:
        match.close()
        client.close()
    end = _robot(truths[-1], "yellow", 1)
    # ground truth: the robot runs at the commanded 1 m/s in the commanded direction
    assert (end.vx, end.vy) == pytest.approx(want, abs=0.08)
    moved = (end.x - start.x, end.y - start.y)
    assert math.hypot(*moved) > 0.4 and (moved[0] * want[0] + moved[1] * want[1]) / math.hypot(*moved) > 0.97
    assert answers >= 40 and summary["protocols"]["ssl/simulation_in/yellow"]["packets"] == 45


def test_a_teleport_over_the_control_port_puts_the_ball_where_asked() -> None:
    match, truths, ports = _outside_match()
    client = UdpEndpoint("127.0.0.1")
    try:
        match.step()
        cmd = sim_pb.SimulatorCommand()
        cmd.control.teleport_ball.x, cmd.control.teleport_ball.y = 1.0, -0.5
        cmd.control.teleport_robot.add(id=trk_pb.RobotId(id=2, team=trk_pb.YELLOW), x=-2.0, y=1.5, orientation=1.0)
        client.send_to(cmd.SerializeToString(), ("127.0.0.1", ports["control"]))
        match.step()
        match.step()
        answer = client.receive(1.0)
    finally:
        match.close()
        client.close()
    ball = truths[-1].ball
    assert (ball.x, ball.y) == pytest.approx((1.0, -0.5), abs=1e-3)
    r = _robot(truths[-1], "yellow", 2)
    assert (r.x, r.y, r.theta) == pytest.approx((-2.0, 1.5, 1.0), abs=2e-3)
    assert answer is not None
    resp = sim_pb.SimulatorResponse()
    resp.ParseFromString(answer[0])
    assert not resp.errors


def test_garbage_and_cut_packets_to_our_simulator_are_counted_and_dropped() -> None:
    control, yellow = free_udp_ports(2)
    settings = load_settings(None, [f"protocols.simulation.control_port={control}",
                                    f"protocols.simulation.yellow_port={yellow}", "protocols.simulation.wait_s=0"])
    err = io.StringIO()
    stage = SimulationInStage(settings.protocols, "yellow", err=err)
    stage.drops.interval_s = 0.0
    client = UdpEndpoint("127.0.0.1")
    m = ctl_pb.RobotControl()
    g = m.robot_commands.add(id=1).move_command.global_velocity
    g.vel_x, g.vel_y, g.vel_angular = 0.5, 0.0, 0.0
    good = m.SerializeToString()
    gt = msg.GroundTruth(0, 0.0, msg.BallTruth(0.0, 0.0, 0.0, 0.0, 0.0),
                         (msg.RobotTruth("yellow", 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),))
    try:
        for data, port in ((b"\xff\x13garbage", yellow), (good[:-2], yellow), (b"\x0a\xff\xff", control),
                           (good, yellow)):
            client.send_to(data, ("127.0.0.1", port))
        out: list[tuple[str, Any]] = []
        time.sleep(0.1)  # loopback delivery
        stage.on_message("truth", gt, lambda topic, message: out.append((topic, message)))
    finally:
        close_sockets([stage])
        client.close()
    assert stage.drops.counts == {"undecodable": 3} and stage.packets == 1
    lines = err.getvalue().strip().splitlines()
    assert len(lines) == 3 and all("dropped a packet (undecodable" in ln for ln in lines)
    commands = [m for t, m in out if t == "commands/yellow"]
    assert len(commands) == 1 and [c.vx for c in commands[0].commands] == [pytest.approx(0.5)]


def test_a_served_simulator_in_lock_step_waits_only_for_a_team_it_has_heard() -> None:
    """``heard_only`` (sim --serve with protocols.serve.wait_s): a team never heard from is not waited
    for (the served match runs on before a client joins, beside a colour nobody plays); a team heard
    once is waited for on every frame, and its late packet is taken on that frame."""
    blue, yellow, control = free_udp_ports(3)
    settings = load_settings(None, [f"protocols.simulation.blue_port={blue}",
                                    f"protocols.simulation.yellow_port={yellow}",
                                    f"protocols.simulation.control_port={control}"])
    stage = SimulationInStage(settings.protocols, ("blue", "yellow"), 30.0, heard_only=True)
    client = UdpEndpoint("127.0.0.1")
    m = ctl_pb.RobotControl()
    g = m.robot_commands.add(id=1).move_command.global_velocity
    g.vel_x, g.vel_y, g.vel_angular = 0.5, 0.0, 0.0
    gt = msg.GroundTruth(0, 0.0, msg.BallTruth(0.0, 0.0, 0.0, 0.0, 0.0),
                         (msg.RobotTruth("blue", 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),))
    out: list[tuple[str, Any]] = []
    try:
        stage.on_message("truth", gt, lambda topic, message: out.append((topic, message)))  # nobody heard: no wait
        assert stage.heard == set() and stage.frames_waited_out == 0
        client.send_to(m.SerializeToString(), ("127.0.0.1", blue))
        time.sleep(0.1)  # loopback delivery
        stage.on_message("truth", gt, lambda topic, message: out.append((topic, message)))  # blue heard
        assert stage.heard == {"blue"}
        late = threading.Timer(0.2, lambda: client.send_to(m.SerializeToString(), ("127.0.0.1", blue)))
        late.start()
        stage.on_message("truth", gt, lambda topic, message: out.append((topic, message)))  # blue's next, late
        late.join()
    finally:
        close_sockets([stage])
        client.close()
    assert stage.heard == {"blue"} and stage.frames_waited_out == 0  # yellow, never heard, never waited for
    blue_commands = [m.commands for t, m in out if t == "commands/blue"]
    assert [len(c) for c in blue_commands] == [0, 1, 1] and blue_commands[2][0].vx == pytest.approx(0.5)
    assert all(m.commands == () for t, m in out if t == "commands/yellow")


def test_the_example_client_plays_yellow_in_our_simulator_over_the_leagues_protocols(udp_port: int) -> None:
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    control, yellow = free_udp_ports(2)
    settings = load_settings(None, [f"protocols.vision.port={udp_port}", f"protocols.simulation.control_port={control}",
                                    f"protocols.simulation.yellow_port={yellow}", "protocols.simulation.wait_s=1.0"])
    client = subprocess.Popen([sys.executable, str(root / "examples" / "simulation_team.py"), "--vision-port",
                               str(udp_port), "--port", str(yellow)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    truths: list[msg.GroundTruth] = []
    match = None
    try:
        assert "simulation team: yellow" in (client.stdout.readline() if client.stdout else "")
        tap = Tap("t", ("truth",), lambda _t, g: truths.append(g))
        match = Match(settings, "simulation", "truth", seed=3, extra=[tap])
        for _ in range(60):
            match.step()
        summary = match.summary()
    finally:
        if match is not None:
            match.close()
        client.send_signal(signal.SIGINT)
        _, err = client.communicate(timeout=20)
    assert client.returncode == 0 and "Traceback" not in err, err
    figures = summary["protocols"]["ssl/simulation_in/yellow"]
    assert figures["packets"] >= 55 and figures["frames_waited_out"] <= 2 and figures["dropped"] == {}

    def ball_distance(gt: msg.GroundTruth) -> float:
        d = [math.hypot(r.x - gt.ball.x, r.y - gt.ball.y) for r in gt.robots if r.team == "yellow"]
        return sum(d) / len(d)

    assert ball_distance(truths[-1]) < ball_distance(truths[0]) - 0.3


def test_garbage_answers_to_our_commands_are_counted_and_dropped() -> None:
    from cmdragons.runtime.ssl.stages import CommandsOutStage

    sim_port, control = free_udp_ports(2)
    settings = load_settings(None, ["protocols.commands_to=simulation", f"protocols.simulation.blue_port={sim_port}",
                                    f"protocols.simulation.control_port={control}"])
    err = io.StringIO()
    stage = CommandsOutStage(settings.protocols, "blue", CHIP, err=err)
    stage.drops.interval_s = 0.0
    peer = UdpEndpoint("127.0.0.1", sim_port)
    try:
        stage.on_message("commands/blue", COMMANDS, lambda _t, _m: None)
        got = peer.receive(1.0)
        assert got is not None
        peer.send_to(b"\xff\x13garbage", got[1])
        peer.send_to(sim_pb.RobotControlResponse(errors=[sim_pb.SimulatorError(code="x")]).SerializeToString(), got[1])
        time.sleep(0.1)  # loopback delivery
        stage.on_message("world/blue", WORLD, lambda _t, _m: None)
    finally:
        close_sockets([stage])
        peer.close()
    assert stage.drops.counts == {"undecodable": 1} and (stage.answers, stage.answer_errors) == (1, 1)
    assert len(err.getvalue().strip().splitlines()) == 1 and "dropped a packet (undecodable" in err.getvalue()


def test_the_simulation_opponent_is_for_the_embedded_match(capsys: pytest.CaptureFixture[str]) -> None:
    from cmdragons.cli import main

    assert main(["play", "--opponent", "simulation", "--distributed", "--seconds", "1"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "leave out --distributed" in err


def test_the_new_streams_default_off_and_to_the_leagues_ports() -> None:
    p = load_settings().protocols
    assert not p.tracker.send and p.commands_to == "none"
    assert (p.grsim.address, p.grsim.port, p.grsim.vision_port) == ("127.0.0.1", 20011, 10020)
    assert (p.simulation.address, p.simulation.port("blue"), p.simulation.port("yellow")) == ("127.0.0.1", 10301, 10302)
