"""Per-robot motion control: the velocity command for the next frame period (Bruce 2006 appendix B.4).

Field frame, metres, seconds, radians. The robot's translation follows the 2D trapezoidal profile
toward a target position and velocity; its heading follows a 1D profile toward a target angle. The
command is the profile's velocity at the end of the next control period, held to the robot's
limits (speed, and the acceleration model A(v) of §5.1), because the robot's motors track a
commanded velocity as fast as their limits allow.

Path following: the target is the next waypoint of a planned path; the robot arrives there with
a speed that still lets it stop at the end of the path and turn into the next leg without drifting
more than ``corner_overshoot_m`` past the corner.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, derived, setting
from cmdragons.control import _kernels as K
from cmdragons.control.acceleration import Limits, stop_accel, trajectory, trajectory_state
from cmdragons.control.trapezoid import TrapezoidParams
from cmdragons.geometry import RobotShape, path_length
from cmdragons.messages import RobotCommand, RobotState

__all__ = [
    "ControlParams",
    "MotionParams",
    "MotionTarget",
    "PathParams",
    "follow_path",
    "motion_command",
    "motion_commands",
    "predict_braking",
    "relative_kick",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class MotionParams(Validated):
    """The robot model the controller, the navigators and the safety search assume, and the
    control period. The limits are the robots' own, configured once in field.yaml ``robot``
    (defaults: the simulator's robots); the period is control's."""

    max_speed_m_s: float = derived("field.robot.max_speed_m_s", 3.0, lo=0.01, hi=10.0)
    max_accel_m_s2: float = derived("field.robot.max_accel_m_s2", 3.0, lo=0.01, hi=50.0)  # speeding up, turning
    max_brake_m_s2: float = derived("field.robot.max_brake_m_s2", 6.0, lo=0.01, hi=50.0)  # slowing down
    max_omega_rad_s: float = derived("field.robot.max_omega_rad_s", 20.0, lo=0.01, hi=100.0)
    # angular acceleration and braking
    max_alpha_rad_s2: float = derived("field.robot.max_alpha_rad_s2", 60.0, lo=0.01, hi=1000.0)
    # the ball leaves at this share of the kick asked (configured, or as the tracker measured it)
    kick_gain: float = derived("field.robot.kick_gain", 1.0, lo=0.1, hi=3.0)
    frame_rate_hz: float = setting(60.0, lo=1.0, hi=1000.0)  # one command per camera frame

    @property
    def period_s(self) -> float:
        """The control period: one command holds for this long."""
        return 1.0 / self.frame_rate_hz

    def limits(self) -> Limits:
        """The limits by name, for the kernels."""
        return Limits(self.max_speed_m_s, self.max_accel_m_s2, self.max_brake_m_s2, self.max_omega_rad_s,
                        self.max_alpha_rad_s2)


@dataclass(frozen=True)
class PathParams(Validated):
    """configs/control.yaml ``path``: following a planned path."""

    waypoint_reached_m: float = setting(0.05, lo=0.0, hi=1.0)  # a waypoint this close counts as passed
    corner_overshoot_m: float = setting(0.03, lo=0.001, hi=1.0)  # drift past a corner while turning
    # the speed at a waypoint: no more than the robot reaches on the way at this share of max_accel
    # (the 2D profile splits the acceleration between the axes and also cancels the velocity across)
    waypoint_accel_share: float = setting(0.8, lo=0.05, hi=1.0)


@dataclass(frozen=True)
class ControlParams(Validated):
    """configs/control.yaml: motion control (Bruce 2006 B.4)."""

    motion: MotionParams = MotionParams()
    trapezoid: TrapezoidParams = TrapezoidParams()
    path: PathParams = PathParams()


@dataclass(frozen=True)
class MotionTarget:
    """Where a robot should be next: position (m), velocity on arrival (m/s), heading (rad); field
    frame."""

    x: float
    y: float
    vx: float = 0.0
    vy: float = 0.0
    theta: float = 0.0


def motion_commands(states: ArrayLike, targets: ArrayLike, params: ControlParams) -> FloatArray:
    """Commands (n, 3) vx, vy (field frame, m/s), omega (rad/s) for robots ``states`` (n, 6: x, y,
    theta, vx, vy, omega) toward ``targets`` (n, 5: x, y, vx, vy, theta), one frame period ahead."""
    s = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, 6)
    t = np.ascontiguousarray(targets, dtype=np.float64).reshape(-1, 5)
    m = params.motion
    return np.asarray(K.motion_commands(s, t, m.max_speed_m_s, m.max_accel_m_s2, m.max_brake_m_s2, m.max_omega_rad_s,
                                        m.max_alpha_rad_s2, m.period_s, params.trapezoid.split_iterations))


def motion_command(robot: RobotState, target: MotionTarget, params: ControlParams) -> RobotCommand:
    """The command of one robot toward ``target`` for the next frame period (Bruce 2006 B.4)."""
    state = np.array([[robot.x, robot.y, robot.theta, robot.vx, robot.vy, robot.omega]])
    goal = np.array([[target.x, target.y, target.vx, target.vy, target.theta]])
    vx, vy, omega = motion_commands(state, goal, params)[0]
    return RobotCommand(robot.team, robot.id, float(vx), float(vy), float(omega))


def relative_kick(cmd: RobotCommand, theta: float, velocity: tuple[float, float], robot: RobotShape,
                  gain: float = 1.0) -> RobotCommand:
    """``cmd`` with its kick (the ball's speed over the ground, as strategy asks it) turned into the
    kicker's speed relative to the robot heading ``theta`` (rad): a kicker fires relative to the robot
    that carries it, so a robot driving onto the ball at 1 m/s that kicks at 6 m/s sends it off at 7
    (over the rules' 6.5). When the kicker fires, the robot moves somewhere between its tracked
    ``velocity`` (field frame, m/s) and the command's (it speeds up or brakes toward the command
    within its limits); the faster of the two along the heading is taken off, so the ball never
    leaves faster than asked (a robot at 1.07 m/s whose command the safety search had just zeroed shot
    at 6.9 m/s), and a robot driving steadily, the two alike, kicks it off at the speed asked. A
    kicker whose ball leaves at ``gain`` of the speed asked (MotionParams ``kick_gain``) is asked that
    much more, up to the robot's ``max_kick_m_s`` (a gain measured on passes must not send a shot
    over the rules'). Flat kicks; a chip's speed is sent as asked."""
    if cmd.kick_speed <= 0.0 or cmd.chip:
        return cmd
    c, s = math.cos(theta), math.sin(theta)
    forward = max(cmd.vx * c + cmd.vy * s, velocity[0] * c + velocity[1] * s)
    kick = robot.kicker_speed(cmd.kick_speed, forward)
    if gain != 1.0:
        kick = min(max(kick / gain, robot.min_kick_m_s), max(kick, robot.max_kick_m_s))
    return dataclasses.replace(cmd, kick_speed=kick)


def follow_path(position: tuple[float, float], path: ArrayLike, theta: float, params: ControlParams,
                velocity: tuple[float, float] | None = None) -> MotionTarget:
    """The target on a planned ``path`` (k, 2) for a robot at ``position``: the first waypoint not yet
    reached, to arrive at with the fastest speed that still lets the robot stop at the path's end and
    turn into the next leg within ``corner_overshoot_m``; at the last point, stop (Bruce 2006 B.4).
    With the robot's ``velocity`` (field frame, m/s), also no faster than it can speed up to on the
    way to the waypoint at ``waypoint_accel_share`` of ``max_accel_m_s2``: a speed it cannot reach
    there makes the profile back away from the waypoint for a run-up (a robot at rest 0.11 m from a
    waypoint drove off the other way, into the centre circle at the other team's kickoff)."""
    pts = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    p = np.asarray(position, dtype=np.float64)
    if len(pts) == 0:
        return MotionTarget(float(p[0]), float(p[1]), theta=theta)
    # the first point is where the path started; skip it and every waypoint already reached (but
    # never the last point)
    k = min(1, len(pts) - 1)
    while k < len(pts) - 1 and math.dist(p, pts[k]) <= params.path.waypoint_reached_m:
        k += 1
    if k == len(pts) - 1:
        return MotionTarget(float(pts[k, 0]), float(pts[k, 1]), theta=theta)
    w, nxt = pts[k], pts[k + 1]
    incoming, outgoing = w - p, nxt - w
    n_in, n_out = float(np.hypot(*incoming)), float(np.hypot(*outgoing))
    if n_in <= 1e-9 or n_out <= 1e-9:
        return MotionTarget(float(w[0]), float(w[1]), theta=theta)
    m = params.motion
    rest = n_out + path_length(pts[k + 1 :]) if k + 2 < len(pts) else n_out
    cos_turn = float(incoming @ outgoing) / (n_in * n_out)
    # the velocity across the next leg (all of it when turning back) is cancelled at max_accel
    across = math.sqrt(max(0.0, 1.0 - cos_turn * cos_turn)) if cos_turn > 0.0 else 1.0
    turn_speed = math.sqrt(2.0 * m.max_accel_m_s2 * params.path.corner_overshoot_m) / max(across, 1e-9)
    speed = min(m.max_speed_m_s, math.sqrt(2.0 * m.max_brake_m_s2 * rest), turn_speed)
    u = incoming / n_in
    if velocity is not None:
        along = max(0.0, float(velocity[0] * u[0] + velocity[1] * u[1]))
        reach = params.path.waypoint_accel_share * m.max_accel_m_s2
        speed = min(speed, math.sqrt(along * along + 2.0 * reach * n_in))
    return MotionTarget(float(w[0]), float(w[1]), float(u[0] * speed), float(u[1] * speed), theta)


def predict_braking(
    x: float, y: float, vx: float, vy: float, t_s: float, motion: MotionParams
) -> tuple[float, float, float, float]:
    """Where a robot at (x, y) moving at (vx, vy), commanded to stop now, is ``t_s`` seconds later and
    how fast it moves: braking at full strength to rest (the robot model's braking trajectory, the
    one DSS checks; field frame, m, m/s)."""
    dt = motion.period_s
    tr = trajectory(x, y, vx, vy, *stop_accel(vx, vy, dt), dt, motion.max_accel_m_s2, motion.max_brake_m_s2)
    px, py, wx, wy = trajectory_state(tr, max(float(t_s), 0.0))
    return float(px), float(py), float(wx), float(wy)
