"""Two processes play a match as with grSim: ``cmdragons sim --serve`` as the simulator, and a client
team in the test on plain sockets, written from the league's definitions. The client reads the
served geometry and vision, takes the kickoff (a teleport of its kicker behind the ball, then
RobotControl: forward with the kicker armed) past the other team's standing robots into the goal;
the served referee's Referee packets give the goal and then the restart, and the served vision
shows the ball back on the centre spot."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from cmdragons.messages import GameState, RefereeCommand
from cmdragons.runtime.proto import ssl_simulation_control_pb2 as ctl_pb
from cmdragons.runtime.proto import ssl_simulator_pb2 as sim_pb
from cmdragons.runtime.proto import ssl_tracked_pb2 as trk_pb
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.referee import RefereeReader
from cmdragons.runtime.ssl.udp import MulticastReceiver, UdpEndpoint
from cmdragons.runtime.ssl.vision import VisionGeometry, decode_wrapper
from tests.runtime.conftest import free_udp_ports

KICKER = 3  # blue's robot nearest the centre in the kickoff formation
KICK_M_S = 5.0
AIM_Y_M = 0.42  # into the goal beside the keeper standing on its centre


@pytest.mark.slow
def test_a_two_process_match_scores_and_restarts(tmp_path: Path) -> None:
    vision_port, referee_port, control, blue, yellow = free_udp_ports(5)
    sets = [f"protocols.simulation.vision_port={vision_port}", f"protocols.referee.port={referee_port}",
            f"protocols.simulation.control_port={control}", f"protocols.simulation.blue_port={blue}",
            f"protocols.simulation.yellow_port={yellow}"]
    p = load_settings(None, sets).protocols
    vision = MulticastReceiver(p.vision.group, vision_port, p.interface, p.receive_buffer_bytes)
    referee = MulticastReceiver(p.referee.group, referee_port, p.interface, p.receive_buffer_bytes)
    client = UdpEndpoint("127.0.0.1")
    out = tmp_path / "served"
    # --seconds bounds the match: the test stops it once the restart came
    server = subprocess.Popen([sys.executable, "-m", "cmdragons.cli", "sim", "--serve", "--seconds", "60",
                               "--no-progress", "--out", str(out), *(f"--set={s}" for s in sets)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    reader = RefereeReader()
    states: list[GameState] = []
    geometry: VisionGeometry | None = None
    ball: tuple[float, float] | None = None
    ball_after_restart: tuple[float, float] | None = None
    teleported = False
    seen_since_restart = 0  # detection packets since the restart's Referee packet
    try:
        while server.poll() is None:
            first = referee.receive(0.01)
            states += [reader.read(d) for d in ([first] if first is not None else []) + referee.drain()]
            for data in vision.drain():
                det, geo = decode_wrapper(data)
                geometry = geo or geometry
                if det is not None and det.balls:
                    ball = (det.balls[0].x, det.balls[0].y)
                    seen_since_restart += 1
            if not states or geometry is None or ball is None:
                continue
            game = states[-1]
            if game.score_blue == 0 and game.command == RefereeCommand.KICKOFF and game.for_team == "blue":
                if not teleported:  # the kicker behind the ball, aimed beside the keeper
                    aim = math.atan2(AIM_Y_M - ball[1], geometry.field_length_m / 2 - ball[0])
                    back = 0.13
                    m = sim_pb.SimulatorCommand()
                    m.control.teleport_robot.add(id=trk_pb.RobotId(id=KICKER, team=trk_pb.BLUE),
                                                 x=ball[0] - back * math.cos(aim), y=ball[1] - back * math.sin(aim),
                                                 orientation=aim, present=True)
                    client.send_to(m.SerializeToString(), ("127.0.0.1", control))
                    teleported = True
                elif game.ready:  # the normal start: forward, the kicker armed
                    _drive(client, blue, forward=0.5, kick=KICK_M_S)
            elif game.score_blue == 1 and game.command == RefereeCommand.KICKOFF and game.for_team == "yellow":
                if ball_after_restart is None:
                    ball_after_restart, seen_since_restart = ball, 0
                elif seen_since_restart >= 10:  # the frames after the restart's teleport
                    ball_after_restart = ball
                    break
            elif game.score_blue == 0:  # the kick is under way
                _drive(client, blue, forward=0.0, kick=0.0)
            while client.receive() is not None:  # the answers (their content: tests/runtime/test_serve.py)
                pass
        if server.poll() is None:
            server.send_signal(signal.SIGINT)
        stdout, stderr = server.communicate(timeout=60)
    finally:
        if server.poll() is None:
            server.kill()
        for sock in (vision, referee, client):
            sock.close()
    assert server.returncode in (0, 128 + signal.SIGINT), stderr
    assert ball_after_restart is not None, f"no goal and restart seen; the server said: {stdout} {stderr}"
    # the referee's word: a kickoff for blue, the goal (a stop with the score), then the kickoff for yellow
    scored = next(i for i, g in enumerate(states) if g.score_blue == 1)
    assert states[scored].score_yellow == 0
    assert states[scored].command in (RefereeCommand.STOP, RefereeCommand.KICKOFF)
    assert any(g.command == RefereeCommand.KICKOFF and g.for_team == "blue" for g in states[:scored])
    assert math.dist(ball_after_restart, (0.0, 0.0)) < 0.05  # back on the centre spot (vision noise)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["score"] == {"blue": 1, "yellow": 0}
    assert summary["protocols"]["ssl/simulation_in"]["teleports"] == 1
    assert "score blue 1:0 yellow" in stdout.splitlines()[-1]


def _drive(client: UdpEndpoint, port: int, forward: float, kick: float) -> None:
    """The kicker's RobotControl: ``forward`` m/s in its own frame, the kicker armed at ``kick`` m/s."""
    m = ctl_pb.RobotControl()
    r = m.robot_commands.add(id=KICKER, kick_speed=kick)
    v = r.move_command.local_velocity
    v.forward, v.left, v.angular = forward, 0.0, 0.0
    client.send_to(m.SerializeToString(), ("127.0.0.1", port))
