"""A match in an outside simulator (``play --simulator grsim|sim-protocol``): the frame gate keeps
each camera's newest frame, the cameras and the field are learnt from the simulator's packets,
the set-up is a checked table, grSim's commands go again each vision frame, and our team plays
yellow in a simulator it reaches only through the league's protocols (our own embedded match
served by ``cmdragons sim --serve`` in another process): its tracked robots where the served
truth has them. Every socket on 127.0.0.1, TTL 0, on ports free at the time."""

from __future__ import annotations

import itertools
import json
import math
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cmdragons import messages as msg
from cmdragons.bench.league import PEERS, peer_script
from cmdragons.geometry import Field
from cmdragons.runtime.log import read_log
from cmdragons.runtime.match import CLOCK, Match
from cmdragons.runtime.outside import (
    FrameGate,
    OutsideError,
    SimulatorKind,
    field_settings,
    listen,
    outside_settings,
    outside_wiring,
    vision_params,
)
from cmdragons.runtime.proto import grsim_pb2 as grsim_pb
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.stages import CommandsOutStage
from cmdragons.runtime.ssl.udp import DatagramQueue, UdpEndpoint
from cmdragons.runtime.ssl.vision import decode_wrapper, geometry_packet
from cmdragons.runtime.ssl.vision import detection_packet as packet
from cmdragons.runtime.stages import Tap
from cmdragons.runtime.topics import check_wiring
from tests.runtime.conftest import free_udp_ports

FROM_ZERO = UnixEpoch(0)  # a sender whose clock counts from 0 (grSim's simulation time)


def _det(camera: int, frame: int, epoch: UnixEpoch | None = FROM_ZERO) -> bytes:
    """A camera's empty frame, its times on a clock from 0 (grSim's) or (``epoch`` None) Unix time."""
    return packet(msg.DetectionFrame(camera, frame, 10.0 + frame / 60, 10.0 + frame / 60, (), ()), epoch)


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
    assert heard.robots == ()
    assert heard.cameras == (3, 7)
    assert heard.geometry.field_length_m == pytest.approx(9.0)
    assert heard.packets == 4
    assert heard.uncalibrated == (3, 7)


@pytest.mark.parametrize("epoch", [FROM_ZERO, None], ids=["grsim_clock", "unix_time"])
def test_match_time_starts_at_the_first_frame_the_match_plays_on(epoch: UnixEpoch | None) -> None:
    """grSim's clock counts from its own start, SSL-Vision's is Unix time: either way the first frame
    the match plays on (those that came while the team listened and was built passed over, as
    :meth:`OutsideMatch.skip_stale` does) is at match time 0 within its whole second, as the
    referee's first kickoff is (it was 7.6 s in, of the kickoff's 10, on an idle machine)."""
    gate = FrameGate(DatagramQueue())
    table = outside_wiring(load_settings(), SimulatorKind.GRSIM, ["blue"], [0], gate, [("blue", 0)])
    vision = next(e for e in table if e.contract.name == "ssl/vision_in").build()
    for frame in (1, 60, 120):  # the simulator's clock at 10 s to 12 s while the team is built
        gate.receiver.push(_det(0, frame, epoch))
    gate.drain()  # passed over, as skip_stale does
    gate.receiver.push(_det(0, 2430, epoch))  # its clock at 50.5 s: the match's first frame
    got: list[Any] = []
    vision.on_message("clock", msg.Tick(0), lambda _topic, m: got.append(m))
    assert [d.frame_number for d in got] == [2430] and 0.0 <= got[0].t_capture < 1.0
    assert got[0].t_capture == pytest.approx(0.5, abs=1e-6)


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


def test_an_outside_simulators_robots_brake_as_configured_for_it_until_measured() -> None:
    """field.yaml's robot is our own simulator's (braking 6 m/s²); in an outside simulator the team
    assumes protocols.outside's braking (grSim's robots brake at about 3.7) in motion control, the safety
    search and as the tracker's configured value, until it measured the robots; a --set of
    field.yaml's braking stays as given, and 0 keeps field.yaml's."""
    own = load_settings()
    assert own.field.robot.max_brake_m_s2 == 6.0
    s = outside_settings(None, [])
    brake = own.protocols.outside.robot_max_brake_m_s2
    assert 0.0 < brake < 6.0 and s.field.robot.max_brake_m_s2 == brake
    assert s.control.motion.max_brake_m_s2 == brake and s.tracker.physics.max_brake_m_s2 == brake
    assert s.field.robot.max_accel_m_s2 == own.field.robot.max_accel_m_s2  # nothing else of the robot changes
    assert outside_settings(None, ["field.robot.max_brake_m_s2=5.0"]).control.motion.max_brake_m_s2 == 5.0
    assert outside_settings(None, ["protocols.outside.robot_max_brake_m_s2=0"]).control.motion.max_brake_m_s2 == 6.0


def _own_contacts(settings: Any, seconds: float) -> list[tuple[Any, Any]]:
    events: list[msg.SimEvents] = []
    Match(settings, "self", "truth", seed=1, extra=[Tap("events", ("events",), lambda _t, e: events.append(e))]).run(
        seconds)
    return [(c.a, c.b) for e in events for c in e.events if isinstance(c, msg.Contact) and c.a[0] == c.b[0]]


def test_in_grsims_world_the_braking_assumed_keeps_our_robots_apart() -> None:
    """grSim's first kickoff played in our own simulator made grSim's world (its robots braking at
    3.6 m/s² as our tracker measured grSim's, sim.world_robot_max_brake_m_s2): from the teleported
    formation blue's defenders 1 and 2 run at each other toward their places 0.32 m apart.
    Believing field.yaml's 6 m/s² they brake too late and meet (as in grSim, 1 s in); with the
    braking an outside simulator's robots are assumed to have (:func:`outside_settings`) they stop
    apart, and nobody else meets either."""
    grsim_world = ["sim.world_robot_max_brake_m_s2=3.6"]
    assert (("blue", 1), ("blue", 2)) in _own_contacts(load_settings(None, grsim_world), 3.0)
    assert _own_contacts(outside_settings(None, grsim_world), 3.0) == []


@pytest.mark.parametrize("kind", [SimulatorKind.GRSIM, SimulatorKind.SIM_PROTOCOL])
@pytest.mark.parametrize("teams", [["blue"], ["yellow"], ["blue", "yellow"]])
def test_the_set_up_is_a_checked_table_without_our_simulator(kind: SimulatorKind, teams: list[Any]) -> None:
    settings = load_settings()
    robots = [(t, i) for t in ("blue", "yellow") for i in range(6)]
    table = outside_wiring(settings, kind, teams, [0, 1, 2, 3], DatagramQueue(), robots)
    check_wiring([e.contract for e in table], CLOCK)
    names = {e.contract.name for e in table}
    assert "sim" not in names and not any(n.startswith(("vision/", "perception/")) for n in names)
    # refereed by our referee on its own tracked world of every camera, its teleports sent by one team's stage
    assert {"tracker/autoref", "autoref"} <= names
    takes = [e.contract.name for e in table if "teleport" in e.contract.inputs]
    assert takes == [f"ssl/commands_out/{teams[0]}"]
    for team in teams:
        assert {f"tracker/{team}", f"team/{team}", f"ssl/commands_out/{team}"} <= names
    tracker = next(e.contract for e in table if e.contract.name == f"tracker/{teams[0]}")
    assert [p.topic for p in tracker.reads][:4] == [f"ssl/vision/{c}" for c in range(4)]
    p = vision_params(settings.protocols, kind)
    assert p.vision.port == 10020 and p.commands_to == ("grsim" if kind is SimulatorKind.GRSIM else "simulation")


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


def _cmdragons(*args: str | Path) -> list[str]:
    return [sys.executable, "-m", "cmdragons.cli", *map(str, args)]


@pytest.mark.slow
def test_two_processes_play_our_team_in_the_served_simulator_as_in_any_league_simulator(tmp_path: Path) -> None:
    """``sim --serve`` in one process, ``play --simulator sim-protocol`` in another: our team (blue,
    on the served referee's word) sees the served field where the served truth has it and plays
    the ball. The served simulator runs in lock-step with our team (each frame waits for blue's
    commands, ``protocols.serve.wait_s``), so that what our team does in its 12 s of the served
    clock does not hang on how fast a busy machine lets it answer (the served robots brake when
    their commands are late)."""
    vision, referee, control, blue, yellow = free_udp_ports(5)
    sets = [f"protocols.simulation.vision_port={vision}", f"protocols.referee.port={referee}",
            f"protocols.simulation.control_port={control}", f"protocols.simulation.blue_port={blue}",
            f"protocols.simulation.yellow_port={yellow}", "protocols.referee.source=game_controller",
            "protocols.serve.wait_s=2.0"]
    flags = [x for k in sets for x in ("--set", k)]
    served = subprocess.Popen(_cmdragons("sim", "--serve", "--seconds", 120, "--no-progress", "--seed", 3,
                                         "--out", tmp_path / "served", *flags),
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        ours = subprocess.run(_cmdragons("play", "--simulator", "sim-protocol", "--seconds", 12, "--no-progress",
                                         "--out", tmp_path / "ours", *flags),
                              capture_output=True, text=True, timeout=240)
    finally:
        served.send_signal(signal.SIGINT)
        served_out, _ = served.communicate(timeout=60)
    assert ours.returncode == 0, ours.stderr + ours.stdout
    assert served.returncode == 130, served_out  # (stopped by SIGINT, its output written)
    summary = json.loads((tmp_path / "ours" / "summary.json").read_text())
    assert summary["seconds"] >= 12.0 and summary["cameras"] == [0, 1] and summary["simulator"] == "sim-protocol"
    assert summary["protocols"]["ssl/commands_out/blue"]["answers"] > 100
    assert summary["protocols"]["ssl/referee_in"]["packets"] > 100  # the served referee's word, followed
    # our tracker against the served truth, frame by frame (its state is predicted to when the
    # commands act: compared with the truth that many frames on)
    truth = {m.frame_number: m for _topic, _t, m in read_log(tmp_path / "served" / "run.mcap", {"/truth"})}
    ahead = round(load_settings().tracker.latency_s * load_settings().sim.physics.frame_rate_hz)
    err: list[float] = []
    for _topic, _t, w in read_log(tmp_path / "ours" / "run.mcap", {"/world/blue"}):
        g = truth.get(w.frame_number + ahead)
        if g is None:
            continue
        true = {(r.team, r.id): (r.x, r.y) for r in g.robots}
        err += [math.hypot(r.x - true[r.team, r.id][0], r.y - true[r.team, r.id][1]) for r in w.robots
                if r.visible and (r.team, r.id) in true]
    assert len(err) > 1000 and float(np.percentile(err, 95)) < 0.08
    # blue went for the ball and played it
    frames = sorted(truth)
    first = truth[frames[0]]
    ball_path = sum(math.hypot(truth[b].ball.x - truth[a].ball.x, truth[b].ball.y - truth[a].ball.y)
                    for a, b in itertools.pairwise(frames))
    start = {r.id: (r.x, r.y) for r in first.robots if r.team == "blue"}
    # the farthest a blue robot got from where it stood (at the end they may stand in a kickoff's formation again)
    moved = max(math.hypot(r.x - start[r.id][0], r.y - start[r.id][1]) for f in frames for r in truth[f].robots
                if r.team == "blue" and r.id in start)
    assert ball_path > 1.0 and moved > 0.5


def _grsim_netns() -> str | None:
    """The script that runs grSim and a command beside it in a network namespace of its own (grSim
    multicasts with no pinned interface: never run it outside one), found as the league bench finds
    it; None when there is none or no grSim for it."""
    return peer_script(next(p for p in PEERS if p.name == "grsim"))[0]


@pytest.mark.slow
@pytest.mark.skipif(_grsim_netns() is None, reason="no grSim: set GRSIM_NETNS to a script that runs grSim in a "
                    "network namespace of its own with a command beside it (and GRSIM to its binary)")
def test_our_team_plays_in_grsim(tmp_path: Path) -> None:
    """grSim's Division B: four cameras learnt, its field played on, our team refereed by our
    autoref on the tracked world moves the ball."""
    script = _grsim_netns()
    assert script is not None
    done = subprocess.run([script, "--division", "B", *_cmdragons("play", "--simulator", "grsim", "--seconds", 20,
                                                                   "--no-progress", "--out", tmp_path / "ours")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr + done.stdout
    summary = json.loads((tmp_path / "ours" / "summary.json").read_text())
    assert summary["cameras"] == [0, 1, 2, 3] and summary["field_m"] == [9.0, 6.0] and summary["division"] == "B"
    assert summary["seconds"] >= 20.0 and summary["frames"] > 300
    balls = [(w.ball.x, w.ball.y) for _topic, _t, w in read_log(tmp_path / "ours" / "run.mcap", {"/world/blue"})
             if w.ball is not None]
    assert sum(math.dist(a, b) for a, b in itertools.pairwise(balls)) > 1.0
