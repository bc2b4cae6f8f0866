"""Robot commands and teleports as the league's simulators take them, and back.

grSim takes a ``grSim_Packet`` whose commands move each robot in its own frame (``veltangent``
forward, ``velnormal`` to the left, m/s; ``velangular`` rad/s) and kick with a speed along the
ground (``kickspeedx``) and up (``kickspeedz``); ``spinner`` turns the dribbler on. The simulation
protocol takes a ``RobotControl`` per team (``move_command.local_velocity``: ``forward``, ``left``,
``angular``; ``kick_speed`` m/s, ``kick_angle`` degrees, ``dribbler_speed`` rpm) and a
``SimulatorCommand`` with teleports. Our commands are field-frame velocities: each goes into the
robot's frame by its heading (the tracked one when we send, the true one in our simulator).
A chip is our robots' own chip elevation (``sim.kicker.chip_angle_rad``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from google.protobuf.message import DecodeError

from cmdragons.geometry import Team
from cmdragons.messages import MessageError, RobotCommand, TeamCommands, Teleport
from cmdragons.runtime import wire
from cmdragons.runtime.proto import grsim_pb2 as grsim_pb
from cmdragons.runtime.proto import ssl_simulation_control_pb2 as ctl_pb
from cmdragons.runtime.proto import ssl_simulator_pb2 as sim_pb
from cmdragons.runtime.proto import ssl_tracked_pb2 as trk_pb

__all__ = ["UNSUPPORTED", "ControlAnswer", "Feedback", "ReadCommands", "SimError", "grsim_packet", "local_velocity",
           "read_robot_control", "read_robot_control_response", "read_simulator_command", "read_simulator_response",
           "robot_control_packet", "robot_control_response", "simulator_command_packet", "simulator_response",
           "to_field"]

_TEAM_PB = {"blue": trk_pb.BLUE, "yellow": trk_pb.YELLOW}
_PB_TEAM: dict[int, Team] = {trk_pb.BLUE: "blue", trk_pb.YELLOW: "yellow"}
_CHIP_MIN_DEG = 1.0  # a kick angle above this is a chip


def local_velocity(vx: float, vy: float, theta: float) -> tuple[float, float]:
    """Field-frame velocity (m/s) -> (forward, left) in the frame of a robot heading ``theta`` (rad)."""
    c, s = math.cos(theta), math.sin(theta)
    return c * vx + s * vy, -s * vx + c * vy


def to_field(forward: float, left: float, theta: float) -> tuple[float, float]:
    """(forward, left) in a robot's frame (m/s) -> field-frame velocity; :func:`local_velocity`'s inverse."""
    c, s = math.cos(theta), math.sin(theta)
    return c * forward - s * left, s * forward + c * left


def _heading(headings: Mapping[int, float], rid: int) -> float:
    """A robot's heading (rad); 0 for one not seen yet (its velocity then goes as if it faced +x)."""
    return headings.get(rid, 0.0)


def grsim_packet(tc: TeamCommands, headings: Mapping[int, float], chip_angle_rad: float,
                 hold_armed: bool = False) -> bytes:
    """A ``grSim_Packet`` with ``tc``'s commands; ``headings``: robot id -> heading (rad). With
    ``hold_armed`` the spinner turns on while the kicker is armed (grSim kicks only a ball touching
    as the packet arrives; it holds a ball the spinner touches until then)."""
    p = grsim_pb.grSim_Packet()
    cmds = p.commands
    cmds.timestamp, cmds.isteamyellow = tc.t, tc.team == "yellow"
    for c in tc.commands:
        forward, left = local_velocity(c.vx, c.vy, _heading(headings, c.id))
        angle = chip_angle_rad if c.chip else 0.0
        cmds.robot_commands.add(id=c.id, kickspeedx=c.kick_speed * math.cos(angle),
                                kickspeedz=c.kick_speed * math.sin(angle), veltangent=forward, velnormal=left,
                                velangular=c.omega, spinner=c.dribbler > 0.0 or (hold_armed and c.kick_speed > 0.0),
                                wheelsspeed=False)
    return p.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def robot_control_packet(tc: TeamCommands, headings: Mapping[int, float], chip_angle_rad: float,
                         dribbler_full_rpm: float) -> bytes:
    """A ``RobotControl`` with ``tc``'s commands as local velocities, the league's fields only (a
    simulator is told the team by the port)."""
    m = ctl_pb.RobotControl()
    for c in tc.commands:
        r = m.robot_commands.add(id=c.id)
        forward, left = local_velocity(c.vx, c.vy, _heading(headings, c.id))
        v = r.move_command.local_velocity
        v.forward, v.left, v.angular = forward, left, c.omega
        r.kick_speed = c.kick_speed
        r.kick_angle = math.degrees(chip_angle_rad) if c.chip else 0.0
        r.dribbler_speed = c.dribbler * dribbler_full_rpm
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


@dataclass(frozen=True)
class ReadCommands:
    """What a ``RobotControl`` said: the commands understood, and one line per command that was not."""

    commands: tuple[RobotCommand, ...]
    errors: tuple[tuple[int, str], ...]  # (robot id, why)


def read_robot_control(data: bytes, team: Team, headings: Mapping[int, float],
                       dribbler_full_rpm: float) -> ReadCommands:
    """A ``RobotControl``'s bytes -> field-frame commands of ``team`` (local velocities turned by
    ``headings``, rad); :class:`MessageError` for bytes that are not one. Wheel velocities are not
    understood (the robot is left out, with the reason)."""
    m = wire.parse(ctl_pb.RobotControl, data)
    out: list[RobotCommand] = []
    errors: list[tuple[int, str]] = []
    for r in m.robot_commands:
        kind = r.move_command.WhichOneof("command")
        if kind == "local_velocity":
            v = r.move_command.local_velocity
            vx, vy = to_field(v.forward, v.left, _heading(headings, r.id))
            omega = v.angular
        elif kind == "global_velocity":
            g = r.move_command.global_velocity
            vx, vy, omega = g.vel_x, g.vel_y, g.vel_angular
        elif kind is None:
            vx = vy = omega = 0.0
        else:
            errors.append((r.id, f"robot {r.id}: {kind} is not simulated here; send local_velocity or global_velocity"))
            continue
        chip = r.kick_angle > _CHIP_MIN_DEG or r.chip
        dribbler = r.dribbler_power if r.HasField("dribbler_power") else min(1.0, r.dribbler_speed / dribbler_full_rpm)
        out.append(RobotCommand(team, r.id, vx, vy, omega, r.kick_speed, chip, max(0.0, dribbler)))
    return ReadCommands(tuple(out), tuple(errors))


@dataclass(frozen=True)
class Feedback:
    """One robot's feedback in a ``RobotControlResponse``: its id (the team is the port's) and
    whether its dribbler touches the ball (None: the simulator did not say)."""

    id: int
    ball_contact: bool | None = None


@dataclass(frozen=True)
class SimError:
    """One ``SimulatorError``: the simulator's code for it and a text for a person."""

    code: str
    message: str


@dataclass(frozen=True)
class ControlAnswer:
    """What a ``RobotControlResponse`` said. ``earlier_layout``: some entry came in the layout
    before 2021-01-27 (a RobotId as the feedback's id, the error's text in field 3); ``unnamed``:
    feedback entries that named no robot in either layout (left out)."""

    feedback: tuple[Feedback, ...]
    errors: tuple[SimError, ...]
    earlier_layout: bool = False
    unnamed: int = 0


UNSUPPORTED = "UNSUPPORTED"  # our code for a request this simulator does not carry out


def robot_control_response(feedback: Sequence[Feedback], errors: Sequence[SimError] = ()) -> bytes:
    """The ``RobotControlResponse`` a simulator answers a ``RobotControl`` with, in the league's
    current layout: each robot's ``RobotFeedback`` by its plain id, each error's text in field 2."""
    m = sim_pb.RobotControlResponse()
    for e in errors:
        m.errors.add(code=e.code, message=e.message)
    for f in feedback:
        r = m.feedback.add(id=f.id)
        if f.ball_contact is not None:
            r.dribbler_ball_contact = f.ball_contact
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def _parse_partial(proto_type: Any, data: bytes) -> Any:
    """``data`` as a ``proto_type`` with its required fields not checked (an entry of the other
    layout lacks them: its fields of the other wire type are kept aside as unknown ones)."""
    m = proto_type()
    try:
        m.ParseFromString(data)
    except DecodeError as exc:
        raise MessageError(f"not a {proto_type.DESCRIPTOR.name}: {exc}") from None
    return m


def _error_of(e: Any) -> tuple[SimError, bool]:
    """A ``SimulatorError`` of either layout, and whether it was the earlier one."""
    if e.HasField("message"):
        return SimError(e.code, e.message), False
    earlier = _parse_partial(sim_pb.EarlierSimulatorError, e.SerializePartialToString())
    if not (earlier.HasField("message") or earlier.HasField("unsupported_capability")):
        return SimError(e.code, ""), False
    text = earlier.message
    if earlier.HasField("unsupported_capability"):
        capability = sim_pb.SimulatorCapability.Name(earlier.unsupported_capability)
        text = f"{text} ({capability})" if text else capability
    return SimError(earlier.code, text), True


def read_robot_control_response(data: bytes) -> ControlAnswer:
    """A ``RobotControlResponse``'s bytes in the league's current layout or the earlier one (both
    read, entry by entry: a field of the other wire type tells them apart); :class:`MessageError`
    for bytes that are not one."""
    m = _parse_partial(sim_pb.RobotControlResponse, data)
    feedback: list[Feedback] = []
    errors: list[SimError] = []
    earlier = False
    unnamed = 0
    for f in m.feedback:
        contact = f.dribbler_ball_contact if f.HasField("dribbler_ball_contact") else None
        if f.HasField("id"):
            feedback.append(Feedback(f.id, contact))
            continue
        old = _parse_partial(sim_pb.EarlierRobotFeedback, f.SerializePartialToString())
        if old.HasField("id") and old.id.HasField("id"):
            feedback.append(Feedback(old.id.id, contact))
            earlier = True
        else:
            unnamed += 1
    for e in m.errors:
        err, was_earlier = _error_of(e)
        errors.append(err)
        earlier = earlier or was_earlier
    return ControlAnswer(tuple(feedback), tuple(errors), earlier, unnamed)


def simulator_command_packet(tp: Teleport) -> bytes:
    """A ``SimulatorCommand`` teleporting ``tp``'s robots (at rest) and ball (at rest, on the ground)."""
    m = sim_pb.SimulatorCommand()
    ctl = m.control
    for team, rid, x, y, theta in tp.robots:
        ctl.teleport_robot.add(id=trk_pb.RobotId(id=rid, team=_TEAM_PB[team]), x=x, y=y, orientation=theta, v_x=0.0,
                               v_y=0.0, v_angular=0.0, present=True)
    if tp.ball is not None:
        ctl.teleport_ball.x, ctl.teleport_ball.y, ctl.teleport_ball.z = tp.ball[0], tp.ball[1], 0.0
        ctl.teleport_ball.vx = ctl.teleport_ball.vy = ctl.teleport_ball.vz = 0.0
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def off_field_packet(robots: Sequence[tuple[Team, int]]) -> bytes:
    """A ``SimulatorCommand`` taking ``robots`` (team, id) off the field (``present: false``)."""
    m = sim_pb.SimulatorCommand()
    for team, rid in robots:
        m.control.teleport_robot.add(id=trk_pb.RobotId(id=rid, team=_TEAM_PB[team]), present=False)
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def read_simulator_command(data: bytes, t: float, where: Mapping[tuple[Team, int], tuple[float, float, float]],
                           ball: tuple[float, float],
                           parked: Mapping[tuple[Team, int], tuple[float, float]] | None = None,
                           ) -> tuple[Teleport | None, list[str]]:
    """A ``SimulatorCommand``'s teleports as our :class:`Teleport` at time ``t`` (a coordinate left
    out keeps the object's own: ``where`` (team, id) -> (x, y, theta) and ``ball`` now), and one
    line per request not carried out (velocities, removing robots without ``parked``,
    configuration); :class:`MessageError` for bytes that are not one. ``parked``: (team, id) -> where
    a robot taken off the field (``present: false``) waits, out of the cameras' view."""
    m = wire.parse(sim_pb.SimulatorCommand, data)
    unsupported: list[str] = []
    if m.HasField("config"):
        unsupported.append("config: the simulator is configured by configs/, not over the protocol")
    if not m.HasField("control"):
        return None, unsupported
    c = m.control
    robots: list[tuple[Team, int, float, float, float]] = []
    for r in c.teleport_robot:
        team = _PB_TEAM.get(r.id.team)
        key = (team, r.id.id) if team is not None else None
        if key is None or key not in where:
            unsupported.append(f"teleport_robot {r.id.id} of team code {r.id.team}: no such robot here")
            continue
        if r.HasField("present") and not r.present:
            if parked is None or key not in parked:
                unsupported.append(f"teleport_robot {team} {r.id.id}: robots are not taken off the field here")
            else:
                robots.append((key[0], key[1], *parked[key], 0.0))
            continue
        x0, y0, th0 = where[key]
        robots.append((key[0], key[1], r.x if r.HasField("x") else x0, r.y if r.HasField("y") else y0,
                       r.orientation if r.HasField("orientation") else th0))
    ball_at = None
    if c.HasField("teleport_ball"):
        b = c.teleport_ball
        ball_at = (b.x if b.HasField("x") else ball[0], b.y if b.HasField("y") else ball[1])
        if b.vx or b.vy or b.vz or b.z:
            unsupported.append("teleport_ball: the ball is placed at rest on the ground here")
    if c.HasField("simulation_speed"):
        unsupported.append("simulation_speed: the match's pace is set by its runtime")
    if not robots and ball_at is None:
        return None, unsupported
    return Teleport(t, tuple(robots), ball_at), unsupported


def simulator_response(errors: Sequence[SimError]) -> bytes:
    """The ``SimulatorResponse`` a simulator answers a ``SimulatorCommand`` with (current layout)."""
    m = sim_pb.SimulatorResponse()
    for e in errors:
        m.errors.add(code=e.code, message=e.message)
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def read_simulator_response(data: bytes) -> tuple[SimError, ...]:
    """A ``SimulatorResponse``'s errors, in either layout (as :func:`read_robot_control_response`)."""
    return tuple(_error_of(e)[0] for e in _parse_partial(sim_pb.SimulatorResponse, data).errors)
