"""``cmdragons sim --serve``'s table in one process, a client on plain sockets beside it: the
client's teleports place the ball and robots where it asked (seen in the served SSL-Vision packets),
its RobotControl moves its robot (local and global velocities, either team), a team that sends
nothing stands, each packet is answered (the ball at a robot's dribbler in its feedback), every
camera of the division is served with the division's geometry, and every socket is on loopback."""

from __future__ import annotations

import dataclasses
import math
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import pytest

from cmdragons import messages as msg
from cmdragons.runtime.bus import Bus
from cmdragons.runtime.match import CLOCK, build, served_wiring
from cmdragons.runtime.proto import ssl_simulation_control_pb2 as ctl_pb
from cmdragons.runtime.proto import ssl_simulator_pb2 as sim_pb
from cmdragons.runtime.proto import ssl_tracked_pb2 as trk_pb
from cmdragons.runtime.settings import Settings, load_settings
from cmdragons.runtime.ssl.stages import (
    CommandsOutStage,
    RefereeOutStage,
    RobotCountStage,
    SimulationInStage,
    VisionOutStage,
    close_sockets,
)
from cmdragons.runtime.ssl.udp import MulticastReceiver, UdpEndpoint
from cmdragons.runtime.ssl.vision import VisionGeometry, decode_wrapper
from cmdragons.runtime.stages import Tap
from cmdragons.runtime.topics import topic_matches
from sim.simulator import Simulator
from sim.substitution import RobotCount, RobotCountParams
from tests.runtime.conftest import free_udp_ports

MM = 1e-3  # the wire's millimetres: positions within a millimetre of the truth without noise


def _settings(division: str = "B", *extra: str) -> Settings:
    """Served on ports of their own (tests that run at once never hear each other), no vision noise,
    the basic rules (the referee leaves the client's placements alone)."""
    vision, referee, control, blue, yellow = free_udp_ports(5)
    return load_settings(None, [f"field.division={division}", f"protocols.simulation.vision_port={vision}",
                                f"protocols.referee.port={referee}", f"protocols.simulation.control_port={control}",
                                f"protocols.simulation.blue_port={blue}",
                                f"protocols.simulation.yellow_port={yellow}", "protocols.serve.vision_noise=false",
                                "sim.referee.rules=basic", *extra])


@dataclass
class Served:
    """The served simulator's bus, its truth as it goes, and a client's sockets."""

    settings: Settings
    bus: Bus
    stages: list
    truth: list[msg.GroundTruth]
    vision: MulticastReceiver
    client: UdpEndpoint
    frame: int = 0

    def tick(self, n: int = 1) -> None:
        for _ in range(n):
            self.bus.tick(self.frame)
            self.frame += 1

    def robot(self, team: str, rid: int) -> msg.RobotTruth:
        return next(r for r in self.truth[-1].robots if (r.team, r.id) == (team, rid))

    def seen(self) -> tuple[dict[int, msg.DetectionFrame], VisionGeometry | None]:
        """The newest detection packet of each camera and the newest geometry that came."""
        frames: dict[int, msg.DetectionFrame] = {}
        geometry = None
        for data in self.vision.drain():
            det, geo = decode_wrapper(data)
            geometry = geo or geometry
            if det is not None:
                frames[det.camera_id] = det
        return frames, geometry

    def send(self, data: bytes, port: int) -> bytes:
        """``data`` to the served port, the frame that takes it, and its answer."""
        self.client.send_to(data, ("127.0.0.1", port))
        self.tick()
        got = self.client.receive(1.0)
        assert got is not None, f"no answer from port {port}"
        return got[0]


@contextmanager
def served(settings: Settings) -> Iterator[Served]:
    sim = Simulator(settings.field, settings.camera_models(), settings.sim, seed=1, render=False, referee=False)
    p = settings.protocols
    vision = MulticastReceiver(p.vision.group, p.simulation.vision_port, p.interface, p.receive_buffer_bytes)
    truth: list[msg.GroundTruth] = []
    stages = build(served_wiring(settings, sim, 1), [Tap("truth", ("truth",), lambda _t, m: truth.append(m))])
    bus = Bus()
    for stage in stages:
        bus.add(stage)
    client = UdpEndpoint("127.0.0.1")
    try:
        bus.start()
        yield Served(settings, bus, stages, truth, vision, client)
    finally:
        close_sockets(stages)
        vision.close()
        client.close()


Pose = tuple[int, int, float, float, float]  # team code, id, x m, y m, theta rad


def _teleport(ball: tuple[float, float] | None = None, robots: tuple[Pose, ...] = (), present: bool = True) -> bytes:
    """A SimulatorCommand written field by field from the league's definition (team codes: 1 yellow, 2 blue)."""
    m = sim_pb.SimulatorCommand()
    for team, rid, x, y, theta in robots:
        m.control.teleport_robot.add(id=trk_pb.RobotId(id=rid, team=team), x=x, y=y, orientation=theta,
                                     present=present)
    if ball is not None:
        m.control.teleport_ball.x, m.control.teleport_ball.y = ball
    return m.SerializeToString()  # type: ignore[no-any-return]


def _control(rid: int, forward: float = 0.0, left: float = 0.0, angular: float = 0.0,
             field_v: tuple[float, float] | None = None, dribbler_rpm: float = 0.0) -> bytes:
    m = ctl_pb.RobotControl()
    r = m.robot_commands.add(id=rid, dribbler_speed=dribbler_rpm)
    if field_v is None:
        v = r.move_command.local_velocity
        v.forward, v.left, v.angular = forward, left, angular
    else:
        g = r.move_command.global_velocity
        g.vel_x, g.vel_y, g.vel_angular = field_v[0], field_v[1], angular
    return m.SerializeToString()  # type: ignore[no-any-return]


BLUE, YELLOW = trk_pb.BLUE, trk_pb.YELLOW


def test_teleports_place_the_ball_and_robots_in_the_served_vision() -> None:
    s = _settings()
    sim = s.protocols.simulation
    with served(s) as srv:
        srv.tick(3)
        answer = sim_pb.SimulatorResponse()
        answer.ParseFromString(srv.send(_teleport((1.2, -0.7), ((BLUE, 2, -0.5, 2.5, 1.0),
                                                                (YELLOW, 4, 2.0, -2.5, -2.5))), sim.control_port))
        assert list(answer.errors) == []
        srv.tick(2)
        assert (srv.truth[-1].ball.x, srv.truth[-1].ball.y) == pytest.approx((1.2, -0.7), abs=1e-6)
        frames, _ = srv.seen()
        balls = [b for f in frames.values() for b in f.balls]
        assert balls and all((b.x, b.y) == pytest.approx((1.2, -0.7), abs=MM) for b in balls)
        for team, rid, x, y, theta in (("blue", 2, -0.5, 2.5, 1.0), ("yellow", 4, 2.0, -2.5, -2.5)):
            seen = [r for f in frames.values() for r in f.robots if (r.team, r.id) == (team, rid)]
            assert seen and all((r.x, r.y) == pytest.approx((x, y), abs=MM) for r in seen)
            assert all(abs(math.remainder(r.theta - theta, 2 * math.pi)) < 1e-3 for r in seen)
        # present: false takes a robot off the field (out of every camera's view), present: true brings it back
        answer.ParseFromString(srv.send(_teleport(None, ((BLUE, 2, 0.0, 0.0, 0.0),), present=False), sim.control_port))
        assert list(answer.errors) == []
        srv.tick(2)
        off = srv.robot("blue", 2)
        assert abs(off.y) > s.field_geometry().boundary_half_width
        frames, _ = srv.seen()
        assert not [r for f in frames.values() for r in f.robots if (r.team, r.id) == ("blue", 2)]
        srv.send(_teleport(None, ((BLUE, 2, 0.5, 2.5, 0.0),)), sim.control_port)
        srv.tick(2)
        frames, _ = srv.seen()
        assert [(r.x, r.y) for f in frames.values() for r in f.robots if (r.team, r.id) == ("blue", 2)] and all(
            (r.x, r.y) == pytest.approx((0.5, 2.5), abs=MM) for f in frames.values() for r in f.robots
            if (r.team, r.id) == ("blue", 2))


@pytest.mark.parametrize("team", ["blue", "yellow"])
def test_robot_control_moves_a_robot_and_the_silent_team_stands(team: str) -> None:
    s = _settings()
    sim = s.protocols.simulation
    code, port, other = (BLUE, sim.blue_port, "yellow") if team == "blue" else (YELLOW, sim.yellow_port, "blue")
    with served(s) as srv:
        srv.tick(2)
        srv.send(_teleport((0.0, -2.5), ((code, 1, 0.0, 0.0, math.pi / 2),)), sim.control_port)
        srv.tick(2)
        others = {(r.team, r.id): (r.x, r.y) for r in srv.truth[-1].robots if r.team == other}
        start = srv.robot(team, 1)
        for _ in range(60):  # a second at 1 m/s forward: the robot faces +y
            response = sim_pb.RobotControlResponse()
            response.ParseFromString(srv.send(_control(1, forward=1.0), port))
            assert [f.id for f in response.feedback] == [1] and list(response.errors) == []
        moved = srv.robot(team, 1)
        assert moved.y - start.y > 0.6 and abs(moved.x - start.x) < 0.05
        assert (moved.vx, moved.vy) == pytest.approx((0.0, 1.0), abs=0.05)
        for _ in range(60):  # then along -x in the field frame, whatever the heading
            srv.send(_control(1, field_v=(-1.0, 0.0)), port)
        back = srv.robot(team, 1)
        assert back.x - moved.x < -0.6 and (back.vx, back.vy) == pytest.approx((-1.0, 0.0), abs=0.05)
        still = {(r.team, r.id): math.dist((r.x, r.y), others[(r.team, r.id)]) for r in srv.truth[-1].robots
                 if r.team == other}
        assert len(still) == len(others) and max(still.values()) < 1e-6
        frames, _ = srv.seen()
        seen = [r for f in frames.values() for r in f.robots if (r.team, r.id) == (team, 1)]
        assert seen and all((r.x, r.y) == pytest.approx((back.x, back.y), abs=MM) for r in seen)


def test_the_feedback_says_which_robot_has_the_ball_at_its_dribbler() -> None:
    s = _settings()
    sim = s.protocols.simulation
    front = s.field.robot.front_distance_m + s.field.ball.radius_m
    with served(s) as srv:
        srv.tick(2)
        srv.send(_teleport((1.0 + front, 1.0), ((BLUE, 0, 1.0, 1.0, 0.0), (BLUE, 3, -1.0, -1.0, 0.0))),
                 sim.control_port)
        response = sim_pb.RobotControlResponse()
        m = ctl_pb.RobotControl()
        for rid in (0, 3):
            v = m.robot_commands.add(id=rid, dribbler_speed=5000.0).move_command.local_velocity
            v.forward = v.left = v.angular = 0.0
        response.ParseFromString(srv.send(m.SerializeToString(), sim.blue_port))
        contact = {f.id: f.dribbler_ball_contact for f in response.feedback}
        assert contact == {0: True, 3: False}


@pytest.mark.parametrize("division", ["A", "B"])
def test_every_camera_of_the_division_is_served_with_its_geometry(division: str) -> None:
    s = _settings(division)
    models = s.camera_models()
    with served(s) as srv:
        srv.tick(3)
        frames, geometry = srv.seen()
    assert sorted(frames) == [m.id for m in models] == list(range(4 if division == "A" else 2))
    assert geometry is not None
    dims = s.field.divisions[division]
    assert (geometry.field_length_m, geometry.field_width_m, geometry.goal_width_m, geometry.goal_depth_m,
            geometry.penalty_area_depth_m, geometry.penalty_area_width_m, geometry.boundary_width_m) == pytest.approx(
        (dims.length_m, dims.width_m, dims.goal_width_m, dims.goal_depth_m, dims.defense_depth_m,
         dims.defense_width_m, dims.boundary_width_m), abs=MM)
    assert sorted(c.camera_id for c in geometry.cameras) == [m.id for m in models]
    # every robot on the field is seen by some camera
    seen = {(r.team, r.id) for f in frames.values() for r in f.robots}
    assert seen == {(r.team, r.id) for r in srv.truth[-1].robots}


def test_the_served_stages_publish_what_they_declare() -> None:
    """Every topic published on the served bus is declared by a row of the table with its message
    type, and every topic the rows declare for each frame is published (with a client sending)."""
    s = _settings()
    sim = s.protocols.simulation
    seen: list[tuple[str, object]] = []
    with served(s) as srv:
        srv.bus.add(Tap("every", ("*",), lambda t, m: seen.append((t, m))))
        srv.send(_teleport((1.0, 1.0)), sim.control_port)
        for _ in range(5):
            srv.send(_control(1, forward=0.5), sim.yellow_port)
        srv.bus.summarize()
        declared = [p for st in srv.stages for p in st.contract.writes] + list(CLOCK)
    for topic, m in seen:
        ports = [p for p in declared if topic_matches(p.topic, topic)]
        assert ports and type(m) is ports[0].type, topic
    published = {t for t, _ in seen}
    for p in declared:
        if not p.sometimes:
            assert any(topic_matches(p.topic, t) for t in published), p.topic


def test_the_served_sockets_stay_on_this_machine() -> None:
    """The defaults (only the ports moved, so tests that run at once keep apart): multicast sent on
    127.0.0.1 with TTL 0, the simulation protocol's ports bound on 127.0.0.1."""
    s = _settings()
    with served(s) as srv:
        stages = {type(st): st for st in srv.stages}
        for stage in (stages[VisionOutStage], stages[RefereeOutStage]):
            sock = stage.sender.sock
            assert socket.inet_ntoa(sock.getsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, 4)) == "127.0.0.1"
            assert sock.getsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL) == 0
        sim_in = stages[SimulationInStage]
        for endpoint in (sim_in.control, *sim_in.robots.values()):
            assert endpoint.sock.getsockname()[0] == "127.0.0.1"
        assert stages[VisionOutStage].sender.address == ("224.5.23.2", s.protocols.simulation.vision_port)
    p = load_settings().protocols
    assert (p.interface, p.ttl, p.network, p.simulation.address) == ("127.0.0.1", 0, False, "127.0.0.1")
    # where grSim and the ER-Force simulator speak: vision on 10020, commands and teleports on 10301/10302/10300
    assert (p.simulation.vision_port, p.simulation.control_port, p.simulation.blue_port,
            p.simulation.yellow_port, p.referee.port) == (10020, 10300, 10301, 10302, 10003)


def _seen_robots(srv: Served) -> dict[tuple[str, int], tuple[float, float]]:
    frames, _ = srv.seen()
    return {(r.team, r.id): (r.x, r.y) for f in frames.values() for r in f.robots}


def test_the_robot_count_takes_a_robot_too_many_out_of_the_served_simulator_and_puts_it_back() -> None:
    """Our side of the league's simulation controller against our served simulator, over its control
    port: with five of blue's six allowed, the one nearest the halfway line at a touch line leaves the
    served field (present: false: no camera sees it); allowed six again, it comes back by blue's touch
    line near the halfway line, where the served cameras see it."""
    s = _settings()
    sim = s.protocols.simulation
    pitch = s.field_geometry()
    with served(s) as srv:
        srv.tick(3)
        srv.send(_teleport((3.0, 0.0), ((BLUE, 3, 0.4, -2.7, 0.0),)), sim.control_port)  # the ball 2 m and more
        srv.tick(3)  # from the halfway line (a substitution may be made), blue 3 nearest a crossing with a touch line
        stage = RobotCountStage(s.protocols, RobotCount(pitch, RobotCountParams(settle_s=0.0)), "world/blue",
                                "referee")
        try:
            def judge(allowed: int) -> None:
                truth = srv.truth[-1]
                world = msg.WorldState(truth.t, msg.BallState(truth.ball.x, truth.ball.y, 0.0, 0.0), tuple(
                    msg.RobotState(r.team, r.id, r.x, r.y, r.theta) for r in truth.robots
                    if pitch.in_field(r.x, r.y, -pitch.dims.boundary_width_m)))
                info = dataclasses.replace(msg.TeamInfo(), max_robots=allowed)
                stage.on_message("referee", msg.GameState(truth.t, blue_team=info), lambda *_: None)
                stage.on_message("world/blue", world, lambda *_: None)
                srv.tick(3)

            assert ("blue", 3) in _seen_robots(srv)
            judge(5)
            seen = _seen_robots(srv)
            assert ("blue", 3) not in seen
            assert sorted(rid for team, rid in seen if team == "blue") == [0, 1, 2, 4, 5]
            judge(6)
            seen = _seen_robots(srv)
            x, y = seen[("blue", 3)]
            r = pitch.league.robot.radius_m
            assert 0.0 < -x <= 1.0 and y == pytest.approx(-(pitch.half_width - 2 * r), abs=MM)
            assert stage.count.taken_off == 1 and stage.count.put_back == 1
        finally:
            stage.close()


def test_a_robot_our_referee_parks_beyond_the_field_leaves_the_served_simulator() -> None:
    """Our referee's teleport of a robot it sends off, to its spot beyond the field's margin, goes out
    as ``present: false`` (as the league's simulation controller takes a robot out) and one back on
    the field as ``present: true``: the served cameras lose it and see it again."""
    s = _settings()
    pitch = s.field_geometry()
    with served(s) as srv:
        srv.tick(3)
        stage = CommandsOutStage(dataclasses.replace(s.protocols, commands_to="simulation"),
                                 "blue", 0.0, pitch=pitch)
        try:
            parked = (-pitch.half_length, -(pitch.boundary_half_width + 3.0))
            stage.on_message("teleport", msg.Teleport(0.0, (("blue", 2, *parked, 0.0),)), lambda *_: None)
            srv.tick(3)
            assert ("blue", 2) not in _seen_robots(srv)
            stage.on_message("teleport", msg.Teleport(0.0, (("blue", 2, 0.5, 2.5, 0.0),)), lambda *_: None)
            srv.tick(3)
            assert _seen_robots(srv)[("blue", 2)] == pytest.approx((0.5, 2.5), abs=MM)
        finally:
            stage.close()
