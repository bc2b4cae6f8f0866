"""configs/protocols.yaml: the league's protocols over UDP (SSL-Vision, tracker and referee packets,
grSim, the simulation protocol). The defaults keep every packet on this machine: multicast sent and
joined on the loopback interface with a TTL of 0."""

from __future__ import annotations

import ipaddress
from dataclasses import dataclass
from typing import Literal

from cmdragons.config import Validated, setting
from sim.substitution import RobotCountParams

__all__ = ["GrsimParams", "MulticastParams", "OutsideParams", "ProtocolParams", "ServeParams",
           "SimulationParams"]

CommandsTo = Literal["none", "grsim", "simulation"]

_LOOPBACK = "127.0.0.1"


def _check_group(group: str, port: int) -> None:
    try:
        address = ipaddress.IPv4Address(group)
    except ValueError:
        raise ValueError(f"group must be an IPv4 multicast address, got {group!r}") from None
    if not address.is_multicast:
        raise ValueError(f"group {group} is not a multicast address (224.0.0.0 to 239.255.255.255)")
    if not 1 <= port <= 65535:
        raise ValueError(f"port must be 1 to 65535, got {port}")


@dataclass(frozen=True)
class MulticastParams(Validated):
    """One multicast stream: its group and port, and whether we send it."""

    group: str = "224.5.23.2"
    port: int = setting(10006, lo=1, hi=65535)
    send: bool = False  # our stage multicasts this stream

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_group(self.group, self.port)


@dataclass(frozen=True)
class VisionStreamParams(MulticastParams):
    geometry_interval_s: float = setting(1.0, lo=0.01, hi=3600.0)  # geometry packets this often (camera time)
    wait_s: float = setting(1.0, lo=0.001, hi=60.0)  # lock-step: the receiver waits this long for a frame's packets


@dataclass(frozen=True)
class TrackerStreamParams(MulticastParams):
    group: str = "224.5.23.2"
    port: int = setting(10010, lo=1, hi=65535)
    source_name: str = "cmdragons"  # the packets' source_name


@dataclass(frozen=True)
class RefereeStreamParams(MulticastParams):
    group: str = "224.5.23.1"
    port: int = setting(10003, lo=1, hi=65535)
    source: Literal["simulator", "game_controller"] = "simulator"  # whose word our teams play to
    source_identifier: str = "cmdragons"  # the packets' source_identifier when we send


@dataclass(frozen=True)
class GrsimParams(Validated):
    """grSim's command port (it sends its own vision on 224.5.23.2:10020 by default, not 10006)."""

    address: str = _LOOPBACK
    port: int = setting(20011, lo=1, hi=65535)
    vision_port: int = setting(10020, lo=1, hi=65535)
    # grSim kicks as a command arrives, and only a ball touching the kicker then: a one-touch ball
    # bounces off between two commands. With this the dribbler turns on while the kicker is armed,
    # and grSim holds a ball that touches until the next command fires the kick.
    hold_armed: bool = setting(True)


@dataclass(frozen=True)
class SimulationParams(Validated):
    """The simulation protocol's ports: SimulatorCommand to control_port, each team's RobotControl to
    its own port."""

    address: str = _LOOPBACK
    control_port: int = setting(10300, lo=1, hi=65535)
    blue_port: int = setting(10301, lo=1, hi=65535)
    yellow_port: int = setting(10302, lo=1, hi=65535)
    dribbler_full_rpm: float = setting(10000.0, lo=1.0, hi=1e6)  # dribbler_speed (rpm) that is our full power (1)
    wait_s: float = setting(0.05, lo=0.0, hi=60.0)  # our simulator: a frame without a new RobotControl waits this long
    vision_port: int = setting(10020, lo=1, hi=65535)  # play --simulator sim-protocol: the simulator's SSL-Vision
    robot_count: RobotCountParams = RobotCountParams()  # an outside simulator: the robots kept at the allowed count

    def port(self, team: str) -> int:
        """The RobotControl port of ``team``."""
        return self.blue_port if team == "blue" else self.yellow_port


@dataclass(frozen=True)
class OutsideParams(Validated):
    """A match in an outside simulator (``play --simulator grsim|sim-protocol``)."""

    geometry_timeout_s: float = setting(10.0, lo=0.1, hi=600.0)  # before the match: its geometry must come by then
    learn_s: float = setting(0.5, lo=0.0, hi=60.0)  # its cameras: those heard this long from the first detection on
    frame_wait_s: float = setting(2.0, lo=0.01, hi=600.0)  # no vision for this long ends the match
    # the simulator's robots brake this hard (m/s²) as far as our team knows until our tracker measured it
    # (field.yaml's robot is our own simulator's); 0: field.yaml's
    robot_max_brake_m_s2: float = setting(3.5, lo=0.0, hi=50.0)


@dataclass(frozen=True)
class ServeParams(Validated):
    """``cmdragons sim --serve``: our simulator alone as a league simulator."""

    vision_noise: bool = True  # its SSL-Vision detections carry the tracker's measurement noise (false: exact)
    # lock-step: a frame waits up to this long (s) for the RobotControl of each team that has sent one
    # (0: the wall clock alone, as the league's simulators run)
    wait_s: float = setting(0.0, lo=0.0, hi=60.0)


@dataclass(frozen=True)
class ProtocolParams(Validated):
    interface: str = _LOOPBACK  # every multicast socket sends and joins on this interface's address
    network: bool = False  # allow an interface and unicast peers off loopback (a real field's network)
    ttl: int = setting(0, lo=0, hi=255)  # multicast hops: 0 never leaves this host
    receive_buffer_bytes: int = setting(4 * 1024 * 1024, lo=65536, hi=2**30)
    max_datagram_bytes: int = setting(65507, lo=1024, hi=65507)
    drop_report_interval_s: float = setting(1.0, lo=0.0, hi=3600.0)  # a dropped packet's log line at most this often
    perception: Literal["simulator", "ssl_vision"] = "simulator"  # ssl_vision: our tracker reads SSL-Vision packets
    commands_to: CommandsTo = "none"  # our team's commands also go to grSim or a simulation-protocol simulator
    vision: VisionStreamParams = VisionStreamParams()
    tracker: TrackerStreamParams = TrackerStreamParams()
    referee: RefereeStreamParams = RefereeStreamParams()
    grsim: GrsimParams = GrsimParams()
    simulation: SimulationParams = SimulationParams()
    outside: OutsideParams = OutsideParams()
    serve: ServeParams = ServeParams()

    def __post_init__(self) -> None:
        super().__post_init__()
        for name, address in (("interface", self.interface), ("grsim.address", self.grsim.address),
                              ("simulation.address", self.simulation.address)):
            try:
                ip = ipaddress.IPv4Address(address)
            except ValueError:
                raise ValueError(f"{name} must be an IPv4 address, got {address!r}") from None
            if not self.network and not ip.is_loopback:
                raise ValueError(f"{name} {address} is off this machine: set network: true to allow it")
