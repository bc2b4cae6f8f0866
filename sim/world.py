"""Field physics in pymunk: robots with a motor model, the two-phase ball, kicker, dribbler,
walls and goals, and the events a referee needs (goals, ball out, robot-robot contacts).

Field frame, SI units. One call of :meth:`World.step_frame` advances one camera frame
(``1 / physics.frame_rate_hz`` seconds) in ``physics.substeps`` fixed physics steps.

Motor model: each robot is driven through a kinematic "motor" body joined to it by a pivot joint
(velocity only, ``max_bias = 0``) and a gear joint. The motor body moves at the commanded
velocity; the joints' force limits (mass x acceleration limit, inertia x angular acceleration
limit) make the robot track the command within its acceleration and braking limits while contacts
still push it around.

Ball model: two phases along a straight line, after the CMDragons ball model: after a kick or a
bounce the ball slides and decelerates at ``acc_slide``; once its speed falls to
``slide_to_roll_fraction`` of the speed it started sliding with, it rolls and decelerates at
``acc_roll``. The deceleration is a velocity joint to the static body whose force limit is
mass x deceleration, so the ball stops exactly rather than oscillating around zero speed.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import pymunk

from cmdragons.config import Validated, derived, setting
from cmdragons.geometry import TEAMS, Field, LeagueParams, Team, wrap_angle
from cmdragons.messages import BallOut, BallTruth, Contact, Goal, GroundTruth, Kick, RobotCommand, RobotTruth, Teleport
from sim.snapshot import Snapshot

__all__ = [
    "BallParams",
    "BallOut",
    "CommandFaults",
    "Contact",
    "DribblerParams",
    "Goal",
    "KickerParams",
    "Kick",
    "PhysicsParams",
    "RobotParams",
    "World",
    "ball_at_front",
]

# collision types
_WALL, _ROBOT, _BALL = 1, 2, 3
# shape filter categories
_CAT_WALL, _CAT_ROBOT, _CAT_BALL = 0b001, 0b010, 0b100
_GRAVITY = 9.81


@dataclass(frozen=True)
class PhysicsParams(Validated):
    frame_rate_hz: float = setting(60.0, lo=1.0, hi=1000.0)  # camera frames per second
    substeps: int = setting(6, lo=1, hi=100)  # physics steps per camera frame
    collision_slop_m: float = setting(0.0005, lo=0.0, hi=0.01)  # allowed overlap before correction
    wall_elasticity: float = setting(0.6, lo=0.0, hi=1.0)  # boundary and goal walls


@dataclass(frozen=True)
class RobotParams(Validated):
    mass_kg: float = setting(2.5, lo=0.1, hi=50.0)
    # the robot's limits and latency: configured once, in field.yaml robot
    max_speed_m_s: float = derived("field.robot.max_speed_m_s", 3.0, lo=0.0, hi=10.0)
    max_accel_m_s2: float = derived("field.robot.max_accel_m_s2", 3.0, lo=0.0, hi=50.0)
    max_brake_m_s2: float = derived("field.robot.max_brake_m_s2", 6.0, lo=0.0, hi=50.0)
    max_omega_rad_s: float = derived("field.robot.max_omega_rad_s", 20.0, lo=0.0, hi=100.0)
    max_alpha_rad_s2: float = derived("field.robot.max_alpha_rad_s2", 60.0, lo=0.0, hi=1000.0)
    command_latency_s: float = derived("field.robot.command_latency_s", 0.03, lo=0.0, hi=1.0)
    command_timeout_s: float = setting(0.25, lo=0.0, hi=10.0)  # no new command for this long: brake
    elasticity: float = setting(0.1, lo=0.0, hi=1.0)
    friction: float = setting(0.3, lo=0.0, hi=2.0)  # robot-robot and robot-wall contact friction


@dataclass(frozen=True)
class BallParams(Validated):
    mass_kg: float = setting(0.046, lo=0.001, hi=1.0)
    # the two-phase model: configured once, in field.yaml ball
    acc_slide_m_s2: float = derived("field.ball.acc_slide_m_s2", 3.0, lo=0.0, hi=50.0)
    acc_roll_m_s2: float = derived("field.ball.acc_roll_m_s2", 0.26, lo=0.0, hi=10.0)
    slide_to_roll_fraction: float = derived("field.ball.slide_to_roll_fraction", 0.64, lo=0.0, hi=1.0)
    robot_elasticity: float = setting(0.5, lo=0.0, hi=1.0)  # ball against a robot's body
    wall_elasticity: float = setting(0.6, lo=0.0, hi=1.0)
    chip_restitution: float = setting(0.5, lo=0.0, hi=1.0)  # vertical bounce of a chipped ball
    chip_damping: float = setting(0.75, lo=0.0, hi=1.0)  # horizontal speed kept at each bounce


@dataclass(frozen=True)
class KickerParams(Validated):
    max_speed_m_s: float = setting(6.5, lo=0.0, hi=20.0)
    recharge_s: float = setting(0.3, lo=0.0, hi=10.0)  # time between two kicks of one robot
    touch_tolerance_m: float = setting(0.006, lo=0.0, hi=0.05)  # ball surface to the front face
    chip_angle_rad: float = setting(0.7854, lo=0.05, hi=1.5)  # elevation of a chip kick
    # fraction of the ball's velocity across the robot's heading that survives a kick: the kicker
    # pushes along the heading only, so a one-touch redirection must aim off the target to compensate
    tangential_retention: float = setting(0.3, lo=0.0, hi=1.0)
    # the ball leaves at this share of the kick speed a command asks (a weaker or stronger kicker
    # than the team believes, field.yaml robot.kick_gain, which its tracker measures)
    gain: float = setting(1.0, lo=0.1, hi=3.0)


@dataclass(frozen=True)
class DribblerParams(Validated):
    grip_force_n: float = setting(1.0, lo=0.0, hi=50.0)  # at full dribbler power
    pull_speed_m_s: float = setting(0.5, lo=0.0, hi=5.0)  # how fast the grip re-centres the ball
    release_distance_m: float = setting(0.03, lo=0.001, hi=0.5)  # ball torn this far away: released


@dataclass
class CommandFaults:
    """Commands the physics never saw as given: counted for the run summary."""

    non_finite: int = 0  # NaN or infinite values -> replaced by braking
    clamped: int = 0  # out-of-limit values -> clamped to the limits
    unknown_robot: int = 0  # a team/id the simulator does not have -> dropped
    timed_out: int = 0  # robot got no command for command_timeout_s -> braking

    def as_dict(self) -> dict[str, int]:
        return {"non_finite": self.non_finite, "clamped": self.clamped, "unknown_robot": self.unknown_robot,
                "timed_out": self.timed_out}


@dataclass
class _Robot:
    team: Team
    id: int
    body: pymunk.Body
    motor: pymunk.Body
    shape: pymunk.Poly
    pivot: pymunk.PivotJoint
    gear: pymunk.GearJoint
    command: RobotCommand
    command_t: float = -math.inf  # when the command in force took effect
    kick_ready_t: float = 0.0
    hold: pymunk.PivotJoint | None = None
    stale: bool = False


@dataclass
class _ContactTrack:
    t_start: float
    relative_speed: float
    max_depth: float = 0.0
    pushed_by: int | None = None  # two robots of one team: the first of the other team touching either


@dataclass
class _BallState:
    sliding: bool = False
    slide_start_speed: float = 0.0
    z: float = 0.0  # height of the ball's bottom above the ground (chips)
    vz: float = 0.0
    last_touch: Team | None = None
    touches: set[int] = field(default_factory=set)  # robots in contact this substep


def _contact_order(event: Goal | BallOut | Kick | Contact) -> tuple[tuple[str, int], tuple[str, int]]:
    """The order of the contacts that end in one physics step: by the pair of robots."""
    return (event.a, event.b) if isinstance(event, Contact) else (("", -1), ("", -1))


def ball_at_front(league: LeagueParams, dx: float, dy: float, theta: float,
                  slack_m: float) -> tuple[bool, float, float]:
    """Is a ball ``(dx, dy)`` m from a robot's centre (field frame) against the flat front of the
    robot heading ``theta`` (rad), within ``slack_m`` of touching it? Returns (touching, x, y), the
    ball in the robot's frame: what the kicker's light barrier and the dribbler feel."""
    c, s = math.cos(theta), math.sin(theta)
    x, y = c * dx + s * dy, -s * dx + c * dy
    shape = league.robot
    front = shape.front_distance_m + league.ball.radius_m
    touching = front - 0.01 <= x <= front + slack_m and abs(y) <= shape.mouth_half_width_m
    return touching, x, y


class World:
    """The pymunk field. Robots of both teams, one ball, boundary walls, goals."""

    def __init__(
        self,
        league: LeagueParams,
        physics: PhysicsParams,
        robot: RobotParams,
        ball: BallParams,
        kicker: KickerParams,
        dribbler: DribblerParams,
        robots_per_team: Mapping[Team, int] | None = None,
    ) -> None:
        self.league = league
        self.field = Field(league)
        self.p_physics, self.p_robot, self.p_ball = physics, robot, ball
        self.p_kicker, self.p_dribbler = kicker, dribbler
        self.frame_dt = 1.0 / physics.frame_rate_hz
        self.dt = self.frame_dt / physics.substeps
        self.t = 0.0
        self.frame_number = 0
        self.faults = CommandFaults()
        self.events: list[Goal | BallOut | Kick | Contact] = []

        self.space = pymunk.Space()
        self.space.collision_slop = physics.collision_slop_m
        self.space.iterations = 12
        self._add_walls()
        counts = robots_per_team or {t: league.dims.robots_per_team for t in TEAMS}
        self.robots: list[_Robot] = []
        self._shape_index: dict[pymunk.Shape, int] = {}
        self._index: dict[tuple[Team, int], int] = {}
        for team in TEAMS:
            for rid in range(counts.get(team, 0)):
                self._add_robot(team, rid)
        self._add_ball()
        self._pending: deque[tuple[float, RobotCommand]] = deque()
        self._contacts: dict[tuple[int, int], _ContactTrack] = {}
        self.space.on_collision(_ROBOT, _ROBOT, begin=self._robot_contact_begin,
                                post_solve=self._robot_contact_post, separate=self._robot_contact_end)
        self.space.on_collision(_ROBOT, _BALL, pre_solve=self._ball_touch, separate=self._ball_separate)
        self.space.on_collision(_WALL, _BALL, pre_solve=self._ball_wall, separate=self._ball_separate)
        self._goal_pending = False
        self._out_pending = False
        # the sign of x of the goal blue defends: the simulator follows the referee's game state
        self.blue_defends: Literal[-1, 1] = -1

    # --- construction -----------------------------------------------------------------------
    def _add_walls(self) -> None:
        f = self.field
        static = self.space.static_body
        bx, by = f.boundary_half_length, f.boundary_half_width
        corners = [(-bx, -by), (bx, -by), (bx, by), (-bx, by)]
        shapes: list[pymunk.Shape] = []
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
            shapes.append(pymunk.Segment(static, a, b, 0.02))
        for side in (-1.0, 1.0):
            for x0, y0, x1, y1 in f.goal_walls(side):
                shapes.append(pymunk.Poly(static, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]))
        for s in shapes:
            s.elasticity = self.p_physics.wall_elasticity
            s.friction = self.p_robot.friction
            s.collision_type = _WALL
            s.filter = pymunk.ShapeFilter(categories=_CAT_WALL)
        self.space.add(*shapes)

    def _add_robot(self, team: Team, rid: int) -> None:
        shape_p = self.league.robot
        mass = self.p_robot.mass_kg
        outline = [tuple(p) for p in shape_p.outline(24)]
        moment = pymunk.moment_for_poly(mass, outline)
        body = pymunk.Body(mass, moment)
        shape = pymunk.Poly(body, outline)
        shape.elasticity = self.p_robot.elasticity
        shape.friction = self.p_robot.friction
        shape.collision_type = _ROBOT
        shape.filter = pymunk.ShapeFilter(categories=_CAT_ROBOT)
        motor = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        pivot = pymunk.PivotJoint(motor, body, (0, 0), (0, 0))
        pivot.max_bias = 0.0
        pivot.max_force = mass * self.p_robot.max_brake_m_s2
        gear = pymunk.GearJoint(motor, body, 0.0, 1.0)
        gear.max_bias = 0.0
        gear.max_force = moment * self.p_robot.max_alpha_rad_s2
        # start far from everything until placed
        body.position = (0.0, 0.0)
        self.space.add(body, shape, motor, pivot, gear)
        self._index[(team, rid)] = len(self.robots)
        self._shape_index[shape] = len(self.robots)
        self.robots.append(_Robot(team, rid, body, motor, shape, pivot, gear, RobotCommand(team, rid)))

    def _add_ball(self) -> None:
        r = self.league.ball.radius_m
        self.ball_body = pymunk.Body(self.p_ball.mass_kg, math.inf)
        self.ball_shape = pymunk.Circle(self.ball_body, r)
        self.ball_shape.elasticity = self.p_ball.robot_elasticity
        self.ball_shape.friction = 0.0
        self.ball_shape.collision_type = _BALL
        self.ball_shape.filter = pymunk.ShapeFilter(categories=_CAT_BALL)
        self.ball_friction = pymunk.PivotJoint(self.space.static_body, self.ball_body, (0, 0), (0, 0))
        self.ball_friction.max_bias = 0.0
        self.ball_friction.max_force = self.p_ball.mass_kg * self.p_ball.acc_roll_m_s2
        self.space.add(self.ball_body, self.ball_shape, self.ball_friction)
        self._ball = _BallState()

    # --- placement ----------------------------------------------------------------------------
    def robot_keys(self) -> list[tuple[Team, int]]:
        return [(r.team, r.id) for r in self.robots]

    def place_robot(self, team: Team, rid: int, x: float, y: float, theta: float) -> None:
        """Teleport a robot to rest at (x, y, theta)."""
        r = self.robots[self._index[(team, rid)]]
        self._release(r)
        r.body.position = (x, y)
        r.body.angle = theta
        r.body.velocity = (0.0, 0.0)
        r.body.angular_velocity = 0.0
        r.motor.position = (x, y)
        r.motor.angle = theta
        r.motor.velocity = (0.0, 0.0)
        r.motor.angular_velocity = 0.0
        r.command = RobotCommand(team, rid)
        self.space.reindex_shapes_for_body(r.body)

    def place_ball(self, x: float, y: float, vx: float = 0.0, vy: float = 0.0, z: float = 0.0) -> None:
        """Teleport the ball; a moving ball starts sliding."""
        for r in self.robots:
            self._release(r)
        self.ball_body.position = (x, y)
        self.ball_body.velocity = (vx, vy)
        self._ball.z, self._ball.vz = z, 0.0
        self._start_slide(math.hypot(vx, vy))
        self.space.reindex_shapes_for_body(self.ball_body)

    def apply(self, teleport: Teleport) -> None:
        """Carry out a teleport: its robots in the order given, then its ball, each at rest."""
        for team, rid, x, y, theta in teleport.robots:
            self.place_robot(team, rid, x, y, theta)
        if teleport.ball is not None:
            self.place_ball(*teleport.ball)

    # --- commands -----------------------------------------------------------------------------
    def sanitize(self, cmd: RobotCommand) -> RobotCommand | None:
        """A command within the robot's limits, or None for an unknown robot. Faults are counted."""
        if (cmd.team, cmd.id) not in self._index:
            self.faults.unknown_robot += 1
            return None
        values = (cmd.vx, cmd.vy, cmd.omega, cmd.kick_speed, cmd.dribbler)
        if not all(isinstance(v, int | float) and math.isfinite(v) for v in values):
            self.faults.non_finite += 1
            return RobotCommand(cmd.team, cmd.id)  # brake
        p = self.p_robot
        vx, vy, omega, kick, drib = cmd.vx, cmd.vy, cmd.omega, cmd.kick_speed, cmd.dribbler
        clamped = False
        speed = math.hypot(vx, vy)
        if speed > p.max_speed_m_s:
            vx, vy = vx * p.max_speed_m_s / speed, vy * p.max_speed_m_s / speed
            clamped = True
        if abs(omega) > p.max_omega_rad_s:
            omega = math.copysign(p.max_omega_rad_s, omega)
            clamped = True
        if not 0.0 <= kick <= self.p_kicker.max_speed_m_s:
            kick = min(max(kick, 0.0), self.p_kicker.max_speed_m_s)
            clamped = True
        if not 0.0 <= drib <= 1.0:
            drib = min(max(drib, 0.0), 1.0)
            clamped = True
        if clamped:
            self.faults.clamped += 1
            return RobotCommand(cmd.team, cmd.id, vx, vy, omega, kick, bool(cmd.chip), drib)
        return cmd

    def submit(self, commands: Iterable[RobotCommand]) -> None:
        """Queue commands sent now; each takes effect after the configured latency."""
        due = self.t + self.p_robot.command_latency_s - 1e-9
        for cmd in commands:
            safe = self.sanitize(cmd)
            if safe is not None:
                self._pending.append((due, safe))

    def _apply_due_commands(self) -> None:
        while self._pending and self._pending[0][0] <= self.t:
            _, cmd = self._pending.popleft()
            r = self.robots[self._index[(cmd.team, cmd.id)]]
            r.command, r.command_t, r.stale = cmd, self.t, False
        timeout = self.p_robot.command_timeout_s
        for r in self.robots:
            if not r.stale and self.t - r.command_t > timeout and r.command_t > -math.inf:
                r.stale = True
                self.faults.timed_out += 1
                r.command = RobotCommand(r.team, r.id)

    def _drive_motors(self) -> None:
        p = self.p_robot
        for r in self.robots:
            c = r.command
            v = r.body.velocity
            dvx, dvy = c.vx - v.x, c.vy - v.y
            # braking when the change points against the current motion and the speed drops
            braking = dvx * v.x + dvy * v.y < 0.0 and c.vx * c.vx + c.vy * c.vy < v.x * v.x + v.y * v.y
            acc = p.max_brake_m_s2 if braking else p.max_accel_m_s2
            r.pivot.max_force = p.mass_kg * acc
            r.motor.velocity = (c.vx, c.vy)
            r.motor.angular_velocity = c.omega

    # --- stepping -------------------------------------------------------------------------------
    def step_frame(self, commands: Iterable[RobotCommand] = ()) -> list[Goal | BallOut | Kick | Contact]:
        """Queue ``commands`` (sent at the current time) and advance one camera frame.

        Returns the events of this frame (also appended to :attr:`events`)."""
        self.submit(commands)
        n_before = len(self.events)
        for _ in range(self.p_physics.substeps):
            self._apply_due_commands()
            self._drive_motors()
            self._ball_phase()
            self._dribble()
            self._ball.touches.clear()
            ended = len(self.events)
            self.space.step(self.dt)
            # pymunk reports the contacts that end in one step in the order of its arbiter hash (the
            # shapes' addresses in memory): ordered by the pair, the same match logs the same bytes
            self.events[ended:] = sorted(self.events[ended:], key=_contact_order)
            self.t += self.dt
            self._kick()
            self._chip_flight()
        self.frame_number += 1
        self._check_ball_events()
        return self.events[n_before:]

    # --- ball ---------------------------------------------------------------------------------
    def _start_slide(self, speed: float) -> None:
        self._ball.sliding = speed > 1e-3
        self._ball.slide_start_speed = speed
        acc = self.p_ball.acc_slide_m_s2 if self._ball.sliding else self.p_ball.acc_roll_m_s2
        self.ball_friction.max_force = self.p_ball.mass_kg * acc

    def _ball_phase(self) -> None:
        b = self._ball
        if b.z > 0.0:
            self.ball_friction.max_force = 0.0  # in the air
            return
        if b.sliding:
            speed = self.ball_body.velocity.length
            if speed <= self.p_ball.slide_to_roll_fraction * b.slide_start_speed:
                b.sliding = False
            acc = self.p_ball.acc_slide_m_s2 if b.sliding else self.p_ball.acc_roll_m_s2
            self.ball_friction.max_force = self.p_ball.mass_kg * acc
        else:
            self.ball_friction.max_force = self.p_ball.mass_kg * self.p_ball.acc_roll_m_s2

    def _ball_touch(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        # pymunk would multiply the two shapes' elasticities; the ball model names the pair's own
        arbiter.restitution = self.p_ball.robot_elasticity
        i = self._shape_index[arbiter.shapes[0]]
        self._ball.touches.add(i)
        self._ball.last_touch = self.robots[i].team

    def _ball_wall(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        arbiter.restitution = self.p_ball.wall_elasticity

    def _ball_separate(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        # a bounce off a robot or a wall makes the ball slide again
        if self._ball.z <= 0.0:
            self._start_slide(self.ball_body.velocity.length)

    def _in_mouth(self, r: _Robot, slack: float) -> tuple[bool, float, float]:
        """Is the ball against robot r's flat front? Returns (touching, x, y) in the robot frame."""
        rel = self.ball_body.position - r.body.position
        return ball_at_front(self.league, rel.x, rel.y, r.body.angle, slack)

    def _kick(self) -> None:
        """An armed kicker fires when the ball is at the front face (within the tolerance, as the
        kicker's light barrier sees it), whether or not pymunk reports a contact."""
        if self._ball.z > 0.0:
            return
        for r in self.robots:
            speed = r.command.kick_speed * self.p_kicker.gain
            if speed <= 0.0 or self.t < r.kick_ready_t:
                continue
            touching, _, _ = self._in_mouth(r, self.p_kicker.touch_tolerance_m)
            if not touching:
                continue
            self._release(r)
            hx, hy = math.cos(r.body.angle), math.sin(r.body.angle)
            # the kick is relative to the robot (its velocity carries over to the ball); the ball's
            # velocity relative to the robot, across the heading, partly survives it
            rel = self.ball_body.velocity - r.body.velocity
            across = (-hy * rel.x + hx * rel.y) * self.p_kicker.tangential_retention
            tx, ty = -hy * across + r.body.velocity.x, hx * across + r.body.velocity.y
            if r.command.chip:
                a = self.p_kicker.chip_angle_rad
                self.ball_body.velocity = (hx * speed * math.cos(a) + tx, hy * speed * math.cos(a) + ty)
                self._ball.vz = speed * math.sin(a)
                self._ball.z = 1e-6
                self.ball_shape.filter = pymunk.ShapeFilter(categories=_CAT_BALL, mask=_CAT_WALL)
            else:
                self.ball_body.velocity = (hx * speed + tx, hy * speed + ty)
                self._start_slide(self.ball_body.velocity.length)
            r.kick_ready_t = self.t + self.p_kicker.recharge_s
            self._ball.last_touch = r.team
            self.events.append(Kick(self.t, r.team, r.id, speed, bool(r.command.chip)))
            break

    def _chip_flight(self) -> None:
        b = self._ball
        if b.z <= 0.0:
            return
        b.vz -= _GRAVITY * self.dt
        b.z += b.vz * self.dt
        if b.z <= 0.0:
            b.z = 0.0
            bounce = -b.vz * self.p_ball.chip_restitution
            self.ball_body.velocity = self.ball_body.velocity * self.p_ball.chip_damping
            if bounce > 0.3:
                b.vz, b.z = bounce, 1e-6
            else:
                b.vz = 0.0
                self._start_slide(self.ball_body.velocity.length)
        # over the robots' heads the ball passes them; below, it hits them
        airborne = b.z > self.league.robot.height_m
        mask = _CAT_WALL if airborne else pymunk.ShapeFilter.ALL_MASKS()
        if self.ball_shape.filter.mask != mask:
            self.ball_shape.filter = pymunk.ShapeFilter(categories=_CAT_BALL, mask=mask)

    def _dribble(self) -> None:
        p = self.p_dribbler
        for r in self.robots:
            power = r.command.dribbler
            if r.hold is not None:
                touching, x, _ = self._in_mouth(r, p.release_distance_m)
                if power <= 0.0 or not touching:
                    self._release(r)
                else:
                    r.hold.max_force = p.grip_force_n * power
                continue
            if power <= 0.0 or self._ball.z > 0.0:
                continue
            touching, _, _ = self._in_mouth(r, self.p_kicker.touch_tolerance_m)
            if touching:
                anchor = (self.league.robot.front_distance_m + self.league.ball.radius_m, 0.0)
                hold = pymunk.PivotJoint(r.body, self.ball_body, anchor, (0, 0))
                hold.max_force = p.grip_force_n * power
                hold.max_bias = p.pull_speed_m_s
                hold.collide_bodies = True
                self.space.add(hold)
                r.hold = hold
                self._ball.last_touch = r.team

    def _release(self, r: _Robot) -> None:
        if r.hold is not None:
            self.space.remove(r.hold)
            r.hold = None

    def holding(self, team: Team, rid: int) -> bool:
        """Does this robot's dribbler hold the ball?"""
        return self.robots[self._index[(team, rid)]].hold is not None

    # --- referee facts ------------------------------------------------------------------------
    def _check_ball_events(self) -> None:
        f, r = self.field, self.league.ball.radius_m
        x, y = self.ball_body.position
        past_goal_line = abs(x) > f.half_length + r
        if past_goal_line and abs(y) < f.goal_half_width:
            if self._goal_pending:
                return
            # the team attacking the goal at +x scores there; which team that is, the referee knows
            self._goal_pending = True
            self.events.append(Goal(self.t, self._attacker_of(1 if x > 0 else -1), x, y))
        elif past_goal_line or abs(y) > f.half_width + r:
            if self._out_pending:
                return
            self._out_pending = True
            cx = min(max(x, -f.half_length), f.half_length)
            cy = min(max(y, -f.half_width), f.half_width)
            self.events.append(BallOut(self.t, cx, cy, self._ball.last_touch))
        else:
            self._goal_pending = self._out_pending = False

    def _attacker_of(self, goal_side: int) -> Team:
        return "yellow" if goal_side == self.blue_defends else "blue"

    # --- robot-robot contacts -------------------------------------------------------------------
    def _pair(self, arbiter: pymunk.Arbiter) -> tuple[int, int]:
        ia, ib = (self._shape_index[s] for s in arbiter.shapes)
        return (ia, ib) if ia < ib else (ib, ia)

    def _robot_contact_begin(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        ba, bb = arbiter.bodies
        n = arbiter.normal
        rel = (ba.velocity - bb.velocity).dot(n)
        self._contacts[self._pair(arbiter)] = _ContactTrack(self.t, abs(rel))

    def _robot_contact_post(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        key = self._pair(arbiter)
        track = self._contacts.get(key)
        if track is not None:
            for pt in arbiter.contact_point_set.points:
                track.max_depth = max(track.max_depth, -pt.distance)
            if track.pushed_by is None and self.robots[key[0]].team == self.robots[key[1]].team:
                track.pushed_by = self._pusher(key)

    def _pusher(self, key: tuple[int, int]) -> int | None:
        """A robot of the other team in contact with either robot of the pair ``key`` (one team's), or None."""
        team = self.robots[key[0]].team
        for pair in sorted(self._contacts):
            if pair != key and (key[0] in pair or key[1] in pair):
                other = pair[0] if pair[1] in key else pair[1]
                if self.robots[other].team != team:
                    return other
        return None

    def _robot_contact_end(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        key = self._pair(arbiter)
        track = self._contacts.pop(key, None)
        if track is not None:
            self.events.append(self._contact_event(key, track))

    def _contact_event(self, key: tuple[int, int], track: _ContactTrack) -> Contact:
        ra, rb = self.robots[key[0]], self.robots[key[1]]
        pusher = None if track.pushed_by is None else self.robots[track.pushed_by]
        return Contact(track.t_start, self.t - track.t_start, (ra.team, ra.id), (rb.team, rb.id), track.max_depth,
                       track.relative_speed, None if pusher is None else (pusher.team, pusher.id))

    def open_contacts(self) -> list[Contact]:
        """Contacts still going on now, as if they ended now (for a run's summary)."""
        return [self._contact_event(k, self._contacts[k]) for k in sorted(self._contacts)]

    # --- state out --------------------------------------------------------------------------------
    def snapshot(self) -> Snapshot:
        rows = np.empty((len(self.robots), 8), dtype=np.float64)
        for i, r in enumerate(self.robots):
            b = r.body
            p, v = b.position, b.velocity
            rows[i] = (0.0 if r.team == "blue" else 1.0, r.id, p.x, p.y, b.angle, v.x, v.y, b.angular_velocity)
        rows[:, 4] = wrap_angle(rows[:, 4])
        bp, bv = self.ball_body.position, self.ball_body.velocity
        ball = np.array([bp.x, bp.y, self._ball.z + self.league.ball.radius_m, bv.x, bv.y, self._ball.vz])
        return Snapshot(self.t, self.frame_number, ball, rows)

    def ground_truth(
        self,
        snapshot: Snapshot | None = None,
        ball_pixels: Mapping[int, tuple[float, float, float]] | None = None,
        robot_pixels: Mapping[tuple[Team, int], Mapping[int, tuple[float, float]]] | None = None,
    ) -> GroundTruth:
        s = snapshot or self.snapshot()
        b = s.ball
        pixels = robot_pixels or {}
        robots = []
        for row in s.robots:
            team, rid = TEAMS[int(row[0])], int(row[1])
            x, y, theta, vx, vy, omega = (float(v) for v in row[2:8])
            robots.append(RobotTruth(team, rid, x, y, theta, vx, vy, omega, dict(pixels.get((team, rid), {}))))
        bx, by, bz, bvx, bvy, bvz = (float(v) for v in b)
        ball = BallTruth(bx, by, bz, bvx, bvy, bvz, dict(ball_pixels or {}))
        return GroundTruth(s.frame_number, s.t, ball, tuple(robots))
