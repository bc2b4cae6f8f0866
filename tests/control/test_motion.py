"""The motion controller: kernels against their references, limits, path following, and closed-loop
driving in the simulator (ground truth; latency compensation is the tracker's, tests/tracking)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.control import (
    ControlParams,
    MotionTarget,
    follow_path,
    motion_command,
    motion_commands,
)
from cmdragons.control import _reference as R
from cmdragons.control import acceleration as A
from cmdragons.geometry import LeagueParams, wrap_angle
from cmdragons.messages import RobotCommand, RobotState
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World

PARAMS = ControlParams()
M = PARAMS.motion


def test_clip_accel_agrees_with_reference_and_stays_in_the_model() -> None:
    rng = np.random.default_rng(0)
    v = rng.normal(0, 1.5, (400, 2))
    v[:20] = 0.0
    a = rng.normal(0, 8, (400, 2))
    got = np.array([A.clip_accel(*v[i], *a[i], 3.0, 6.0) for i in range(len(v))])
    np.testing.assert_allclose(got, R.clip_accel(v, a, 3.0, 6.0), atol=1e-12)
    # inside A(v): at most 3 m/s^2 unless braking; never more than 6; direction kept
    mags = np.linalg.norm(got, axis=1)
    along = np.einsum("ij,ij->i", got, v)
    assert np.all(mags <= 6.0 + 1e-9)
    assert np.all(mags[along >= 0] <= 3.0 + 1e-9)
    cross = got[:, 0] * a[:, 1] - got[:, 1] * a[:, 0]
    assert np.all(np.abs(cross) < 1e-9) and np.all(np.einsum("ij,ij->i", got, a) >= 0)


def test_commands_never_exceed_the_limits() -> None:
    rng = np.random.default_rng(2)
    n = 500
    states = np.column_stack([rng.uniform(-4, 4, (n, 2)), rng.uniform(-3, 3, n), rng.normal(0, 1.5, (n, 2)),
                              rng.normal(0, 5, n)])
    speed = np.hypot(states[:, 3], states[:, 4])
    states[:, 3:5] *= np.minimum(1.0, M.max_speed_m_s / speed)[:, None]  # start within the limits
    targets = np.column_stack([rng.uniform(-4, 4, (n, 2)), rng.normal(0, 1, (n, 2)), rng.uniform(-3, 3, n)])
    cmd = motion_commands(states, targets, PARAMS)
    dt = M.period_s
    assert np.all(np.hypot(cmd[:, 0], cmd[:, 1]) <= M.max_speed_m_s + 1e-9)
    acc = (cmd[:, :2] - states[:, 3:5]) / dt
    # the acceleration asked for lies inside A(v): clipping it again changes nothing
    again = R.clip_accel(states[:, 3:5], acc, M.max_accel_m_s2, M.max_brake_m_s2)
    np.testing.assert_allclose(again, acc, atol=1e-6)
    assert np.all(np.abs(cmd[:, 2]) <= M.max_omega_rad_s + 1e-9)
    assert np.all(np.abs(cmd[:, 2] - states[:, 5]) <= M.max_alpha_rad_s2 * dt + 1e-9)


def test_command_follows_the_profile_for_one_period() -> None:
    robot = RobotState("blue", 3, 0.0, 0.0, 0.0)
    cmd = motion_command(robot, MotionTarget(3.0, 0.0), PARAMS)
    # from rest toward a far target: full acceleration along x for one period
    assert (cmd.team, cmd.id) == ("blue", 3)
    assert cmd.vx == pytest.approx(M.max_accel_m_s2 * M.period_s)
    assert cmd.vy == pytest.approx(0.0, abs=1e-12) and cmd.omega == pytest.approx(0.0)


def test_follow_path_targets_the_next_waypoint_with_a_turnable_speed() -> None:
    path = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0)]
    t = follow_path((0.0, 0.0), path, 0.5, PARAMS)
    assert (t.x, t.y, t.theta) == (2.0, 0.0, 0.5)
    # a right angle: the speed at the corner lets the robot cancel it within the overshoot
    speed = math.hypot(t.vx, t.vy)
    overshoot = speed**2 / (2 * M.max_accel_m_s2)
    assert overshoot == pytest.approx(PARAMS.path.corner_overshoot_m)
    assert t.vy == 0.0 and t.vx > 0
    # straight on: full speed; the corner reached: the next one; the last point: stop there
    t = follow_path((0.0, 0.0), [(0.0, 0.0), (2.0, 0.0), (6.0, 0.0)], 0.0, PARAMS)
    assert t.vx == pytest.approx(M.max_speed_m_s)
    t = follow_path((1.98, 0.0), path, 0.0, PARAMS)
    assert (t.x, t.y, t.vx, t.vy) == (2.0, 2.0, 0.0, 0.0)
    # short remaining path: no faster than what still stops at its end
    t = follow_path((0.0, 0.0), [(0.0, 0.0), (2.0, 0.0), (2.1, 0.0)], 0.0, PARAMS)
    assert math.hypot(t.vx, t.vy) == pytest.approx(math.sqrt(2 * M.max_brake_m_s2 * 0.1))


def make_world(n: int) -> World:
    # robots that act on a command at once: what the controller sees after the tracker's prediction
    w = World(LeagueParams(), PhysicsParams(), RobotParams(command_latency_s=0.0), BallParams(), KickerParams(),
              DribblerParams(), robots_per_team={"blue": n, "yellow": 0})
    w.place_ball(0.0, 3.1)
    return w


@pytest.mark.parametrize(
    ("start", "goal"), [((-3.0, -2.0, 0.0), (3.0, 1.0, 1.5)), ((0.0, 0.0, 0.0), (0.3, -0.2, -2.0))]
)
def test_closed_loop_in_the_simulator_reaches_the_goal_in_the_profile_time(
    start: tuple[float, float, float], goal: tuple[float, float, float]
) -> None:
    w = make_world(1)
    w.place_robot("blue", 0, *start)
    from cmdragons.control import trapezoid_2d

    ideal = trapezoid_2d((goal[0] - start[0], goal[1] - start[1]), (0, 0), (0, 0), 3.0, 3.0, 6.0).duration_s
    arrived = None
    for _ in range(round((ideal + 1.5) * 60)):
        row = w.snapshot().robots[0]
        cmd = motion_commands(row[None, 2:8], np.array([[goal[0], goal[1], 0.0, 0.0, goal[2]]]), PARAMS)[0]
        w.step_frame([RobotCommand("blue", 0, *cmd)])
        row = w.snapshot().robots[0]
        if arrived is None and math.hypot(row[2] - goal[0], row[3] - goal[1]) < 0.01:
            arrived = w.t
    row = w.snapshot().robots[0]
    # arrives about when the profile says, and stays: within 1 cm and 0.02 rad
    assert arrived is not None and arrived <= ideal + 0.1
    assert math.hypot(row[2] - goal[0], row[3] - goal[1]) < 0.01
    assert abs(wrap_angle(row[4] - goal[2])) < 0.02
    assert w.faults.clamped == 0


@pytest.mark.parametrize("theta, omega, target", [(0.0, 0.0, 1.0), (3.0, 2.0, -3.0), (-1.0, -4.0, 0.5),
                                                  (0.2, 0.0, 0.2)])
def test_the_heading_command_is_the_motion_command_s_rotation(theta: float, omega: float, target: float) -> None:
    # the reactive navigators take the rotation alone; it must be the full command's
    from cmdragons.control._kernels import heading_command

    m = PARAMS.motion
    full = motion_commands(np.array([[0.1, -0.2, theta, 0.5, 0.0, omega]]), np.array([[1.0, 1.0, 0.0, 0.0, target]]),
                           PARAMS)[0]
    turn = heading_command(theta, omega, target, m.max_omega_rad_s, m.max_alpha_rad_s2, m.period_s)
    assert turn == full[2]  # rad/s, the same arithmetic


def test_follow_path_never_backs_away_from_a_near_waypoint_for_a_run_up() -> None:
    # a robot at rest 0.11 m short of a waypoint whose path goes on 1 m: the speed the leg allows
    # there (1.45 m/s) is more than it reaches in 0.11 m, and the profile drove it the other way first
    start, path = (0.14, -0.63), [(0.14, -0.63), (0.17, -0.74), (0.14, -1.70)]
    u = np.array([0.03, -0.11]) / math.hypot(0.03, -0.11)
    uncapped = follow_path(start, path, 0.43, PARAMS)
    cmd = motion_command(RobotState("blue", 4, *start, 0.47, 0.0, 0.0, 0.0), uncapped, PARAMS)
    assert cmd.vx * u[0] + cmd.vy * u[1] < 0.0  # what the velocity-blind target did
    # with the robot's velocity: at rest and drifting away, the command heads for the waypoint
    for v in [(0.0, 0.0), (-0.04, 0.36), (0.2, 0.0)]:
        t = follow_path(start, path, 0.43, PARAMS, v)
        cmd = motion_command(RobotState("blue", 4, *start, 0.47, *v, 0.0), t, PARAMS)
        dv = np.array([cmd.vx - v[0], cmd.vy - v[1]])
        assert dv @ u > 0.0, v
    # the speed at the waypoint is what the share of max_accel reaches on the way from rest
    t = follow_path(start, path, 0.43, PARAMS, (0.0, 0.0))
    reach = PARAMS.path.waypoint_accel_share * M.max_accel_m_s2
    assert math.hypot(t.vx, t.vy) == pytest.approx(math.sqrt(2 * reach * math.hypot(0.03, 0.11)))


def test_follow_path_with_the_velocity_heads_for_the_waypoint_from_random_states() -> None:
    # random robots near a waypoint, at rest or moving towards it (a little sideways): the command
    # never drives away from it
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(1500):
        p = rng.uniform(-1.0, 1.0, 2)
        w = p + rng.uniform(-0.3, 0.3, 2)
        e = w + rng.uniform(-2.0, 2.0, 2)
        gap = float(np.hypot(*(w - p)))
        if gap <= PARAMS.path.waypoint_reached_m:
            continue
        u = (w - p) / gap
        v = u * rng.uniform(0.0, 1.0) + np.array([-u[1], u[0]]) * rng.uniform(-0.05, 0.05)
        t = follow_path((float(p[0]), float(p[1])), [p, w, e], 0.0, PARAMS, (float(v[0]), float(v[1])))
        cmd = motion_command(RobotState("blue", 0, float(p[0]), float(p[1]), 0.0, float(v[0]), float(v[1]), 0.0),
                             t, PARAMS)
        assert cmd.vx * u[0] + cmd.vy * u[1] >= -1e-9, (p, w, e, v)
        checked += 1
    assert checked > 500
