"""``cmdragons bench safety``: the safety experiment of Bruce 2006 §5.6.1 in the simulator, on the
loop ``cmdragons play`` runs.

N robots of one team (2, 4, 6, 8, 11, 22) cross the field at once: half start near the left goal
line and drive to the right one, half the other way, at random lateral positions (seeded), so that
paths cross head-on and diagonally. Each frame the robots' true poses plus Gaussian noise become a
detection frame (what vision hands over), the tracker (configs/tracker.yaml) turns it into the world
state, and the brain's own loop (:meth:`cmdragons.team.Brain.drive`: each robot's global planner and
local navigator toward its goal, then team safety) gives the commands that drive the pymunk world
(sim.world.World directly, no rendering). A trial ends when every robot has come within
``ARRIVED_M`` of its goal, or at ``TIMEOUT_S``.

Methods: ``dss`` is the shipped loop (configs as they are: ERRT, trajectory following, DSS);
``none`` the same without safety; ``dynamic_window`` the dynamic-window navigator with DSS behind
it. The labelled extra row ``standin_keep_right_dss`` replaces planner and navigator by a passing
rule (:func:`keep_right_targets`) and the trapezoid controller, with DSS behind them: the stand-in
earlier versions of this bench measured.

Metrics per N, method and noise level: ``collisions`` (robot-robot contacts, summed over the
trials), ``collisions_above_1_5_m_s`` (those closing faster than 1.5 m/s), ``penetration_mm_s``
(depth x duration of the contacts, mean per trial), ``completion_s`` (mean time until the last robot arrived;
a timed-out trial counts its timeout), ``completion_ratio_to_none``, ``ms_per_frame`` (tracker,
planning, navigation and safety together: the mean over trials of each trial's median frame, which
keeps the kernels' first compiling in a fresh worker out) and ``ms_per_agent``.
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing
import os
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from cmdragons.control import ControlParams, follow_path, motion_commands
from cmdragons.messages import BallDetection, DetectionFrame, GameState, RobotCommand, RobotDetection, WorldState
from cmdragons.planning.world import field_world
from cmdragons.runtime.settings import Settings
from cmdragons.safety.registry import make_safety
from cmdragons.team import Brain
from cmdragons.tracking import Tracker
from sim.world import Contact, World
from strategy.skills import Intent

__all__ = ["TrialResult", "keep_right_targets", "noise_levels", "run", "run_trial"]

# Gaussian noise on the detected poses (position sigma m, heading sigma rad); default: what the
# tracker's measurement model assumes of vision (configs/tracker.yaml); the tracker is told the level
HIGH_NOISE = (0.01, 0.05)
METHODS = ("none", "dss", "dynamic_window")
STANDIN = "standin_keep_right_dss"  # the extra row: the passing stand-in and the trapezoid controller, then DSS
ROBOTS = (2, 4, 6, 8, 11, 22)
QUICK_ROBOTS = (2, 6, 11)
TRIALS, QUICK_TRIALS = 20, 3
ARRIVED_M = 0.05  # a robot this close to its goal has arrived
TIMEOUT_S = 15.0
WARMUP_FRAMES = 10  # frames left out of the timing (the first compile most kernels in a fresh process)
FAST_M_S = 1.5  # collisions closing faster than this are reported apart
LINE_OFFSET_M = 1.2  # starts and goals lie this far inside the goal lines: outside the defense areas (1 m deep)
# navigation stand-in (the planner's job in the team): keep right of a robot in the way
LOOKAHEAD_M = 1.0  # robots this far ahead on the way to the goal count as in the way
CORRIDOR_M = 0.25  # ... when their centre is this close to the straight line
PASS_M = 0.45  # the detour waypoint lies this far beside the robot in the way
EDGE_M = 0.12  # ... and at least this far inside the touch and goal lines (a robot radius and a little)


@dataclass(frozen=True)
class TrialResult:
    n: int
    method: str
    noise: str
    collisions: int
    fast_collisions: int
    penetration_mm_s: float
    completion_s: float
    completed: bool
    brain_ms: float  # median per frame: tracker, planning, navigation and safety


def _layout(settings: Settings, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Starts and goals (n, 2): even robots on the left, odd on the right, lateral slots shuffled."""
    f = settings.field_geometry()
    x = f.half_length - LINE_OFFSET_M
    side = np.where(np.arange(n) % 2 == 0, -1.0, 1.0)
    k = (n + 1) // 2
    edge = f.half_width - 0.4
    slots = np.linspace(-edge, edge, k) if k > 1 else np.zeros(1)
    jitter = min((slots[1] - slots[0]) * 0.25, 0.3) if k > 1 else 0.3
    starts = np.empty((n, 2))
    goals = np.empty((n, 2))
    for s in (-1.0, 1.0):
        idx = np.flatnonzero(side == s)
        starts[idx, 0] = s * x
        # lateral slots, jittered but kept on the field (0.1 m from the touch lines at the most)
        starts[idx, 1] = np.clip(rng.permutation(slots)[: len(idx)] + rng.uniform(-jitter, jitter, len(idx)),
                                 -edge - 0.3, edge + 0.3)
        goals[idx, 0] = -s * x
        goals[idx, 1] = np.clip(rng.permutation(slots)[: len(idx)] + rng.uniform(-jitter, jitter, len(idx)),
                                -edge - 0.3, edge + 0.3)
    return starts, goals


def keep_right_targets(
    state: np.ndarray, goals: np.ndarray, headings: np.ndarray, control: ControlParams,
    half_size: tuple[float, float] = (math.inf, math.inf),
) -> np.ndarray:
    """Targets (n, 5) for the controller: straight to the goal, or, when another robot stands in the
    way within ``LOOKAHEAD_M``, along a path through a waypoint ``PASS_M`` beside it.

    A stand-in for the global planner, which the team runs but this benchmark does not (it costs more
    than the whole rest of the frame). The robot passes on the side of the other robot it is already
    on, and keeps right when the other robot lies dead ahead: for two robots heading at each other
    this is the same side for both, so they pass instead of stepping into each other. The waypoint
    stays ``EDGE_M`` inside the touch and goal lines (``half_size``: half length and half width of
    the field, m), where a planner would keep it. Every safety method runs behind the same rule."""
    pos = state[:, :2]
    n = len(pos)
    to_goal = goals - pos
    dist = np.hypot(to_goal[:, 0], to_goal[:, 1])
    unit = to_goal / np.maximum(dist, 1e-9)[:, None]
    rel = pos[None, :, :] - pos[:, None, :]  # rel[i, j] = pos_j - pos_i
    along = np.einsum("ijk,ik->ij", rel, unit)
    across = unit[:, None, 0] * rel[:, :, 1] - unit[:, None, 1] * rel[:, :, 0]
    ahead = (along > 0) & (along < np.minimum(LOOKAHEAD_M, dist[:, None])) & (np.abs(across) < CORRIDOR_M)
    ahead[np.arange(n), np.arange(n)] = False
    targets = np.column_stack([goals, np.zeros((n, 2)), headings])
    lim = np.array([half_size[0] - EDGE_M, half_size[1] - EDGE_M])
    for i in np.flatnonzero(ahead.any(axis=1)):
        j = int(np.argmin(np.where(ahead[i], along[i], np.inf)))
        right = np.array([unit[i, 1], -unit[i, 0]])
        side = 1.0 if across[i, j] >= 0.0 else -1.0  # the other robot on the left (or ahead): pass right
        path = np.array([pos[i], np.clip(pos[j] + side * right * PASS_M, -lim, lim), goals[i]])
        t = follow_path((float(pos[i, 0]), float(pos[i, 1])), path, float(headings[i]), control)
        targets[i] = (t.x, t.y, t.vx, t.vy, t.theta)
    return targets


def noise_levels(settings: Settings) -> dict[str, tuple[float, float]]:
    """Detection noise (position sigma m, heading sigma rad) per level."""
    robot = settings.tracker.robot
    return {"default": (robot.measurement_sigma_m, robot.measurement_sigma_rad), "high": HIGH_NOISE}


def _method_settings(settings: Settings, method: str) -> Settings:
    """The settings of one method: its navigator and safety stage, everything else as configured."""
    if method == "none":
        return dataclasses.replace(settings, safety=dataclasses.replace(settings.safety, method="none"))
    if method == "dynamic_window":
        return dataclasses.replace(settings, team=dataclasses.replace(settings.team, navigator="dynamic_window"))
    return settings


class _StandIn:
    """The passing rule and the trapezoid controller toward the goals, then DSS."""

    def __init__(self, settings: Settings, goals: np.ndarray, headings: np.ndarray, seed: int) -> None:
        f = settings.field_geometry()
        self.settings, self.goals, self.headings = settings, goals, headings
        self.half = (f.half_length, f.half_width)
        self.safety = make_safety(settings.safety, settings.control, settings.field.robot.radius_m,
                                  field_world(f, defense_areas=False), "dss", stream=seed)

    def drive(self, world: WorldState, n: int) -> list[RobotCommand]:
        seen = {r.id: r for r in world.robots}
        ids = [i for i in range(n) if i in seen]
        if not ids:
            return []
        state = np.array([(seen[i].x, seen[i].y, seen[i].theta, seen[i].vx, seen[i].vy, seen[i].omega) for i in ids])
        targets = keep_right_targets(state, self.goals[ids], self.headings[ids], self.settings.control, self.half)
        cmd = motion_commands(state, targets, self.settings.control)
        cmd[:, :2] = self.safety.filter(state[:, [0, 1, 3, 4]], cmd[:, :2], np.zeros((0, 4))).velocities
        return [RobotCommand("blue", i, float(c[0]), float(c[1]), float(c[2])) for i, c in zip(ids, cmd, strict=True)]


def run_trial(settings: Settings, n: int, method: str, noise: str, seed: int) -> TrialResult:
    """One traversal of ``n`` robots with ``method`` under detection ``noise``; same seed, same layout
    and noise for every method."""
    sp = settings.sim
    world = World(settings.field, sp.physics, sp.robot, sp.ball, sp.kicker, sp.dribbler,
                  robots_per_team={"blue": n, "yellow": 0})
    f = settings.field_geometry()
    world.place_ball(0.0, f.half_width + 0.15)  # in the boundary strip, out of the way
    layout_rng = np.random.default_rng([seed, n])
    starts, goals = _layout(settings, n, layout_rng)
    headings = np.where(goals[:, 0] > starts[:, 0], 0.0, math.pi)
    for i in range(n):
        world.place_robot("blue", i, float(starts[i, 0]), float(starts[i, 1]), float(headings[i]))
    noise_rng = np.random.default_rng([seed, n, 7])
    s_xy, s_theta = noise_levels(settings)[noise]
    # the tracker knows how noisy its detections are (as vision's own calibration would tell it)
    model = dataclasses.replace(settings.tracker.robot, measurement_sigma_m=s_xy, measurement_sigma_rad=s_theta)
    tracker = Tracker(dataclasses.replace(settings.tracker, robot=model))
    game = GameState(0.0)
    intents = {i: Intent(float(goals[i, 0]), float(goals[i, 1]), float(headings[i])) for i in range(n)}
    brain = Brain("blue", _method_settings(settings, method)) if method != STANDIN else None
    standin = _StandIn(settings, goals, headings, seed) if method == STANDIN else None
    contacts: list[Contact] = []
    spent: list[float] = []
    frames = round(TIMEOUT_S * sp.physics.frame_rate_hz)
    arrived = np.full(n, np.nan)
    for frame in range(frames):
        snap = world.snapshot()
        noisy = snap.robots[:, 2:5] + noise_rng.normal(0.0, 1.0, (n, 3)) * np.array([s_xy, s_xy, s_theta])
        robots = tuple(RobotDetection("blue", int(r[1]), float(p[0]), float(p[1]), float(p[2]), 1.0, (0.0, 0.0))
                       for r, p in zip(snap.robots, noisy, strict=True))
        ball = (BallDetection(float(snap.ball[0]), float(snap.ball[1]), 1.0, (0.0, 0.0)),)
        t0 = time.perf_counter()
        seen = tracker.step([DetectionFrame(0, snap.frame_number, world.t, world.t, ball, robots)])
        if brain is not None:
            commands = brain.drive(seen, {i: it for i, it in intents.items() if any(r.id == i for r in seen.robots)},
                                   game)
        else:
            assert standin is not None
            commands = standin.drive(seen, n)
        tracker.command_sent(commands, world.t)
        if frame >= WARMUP_FRAMES:
            spent.append(time.perf_counter() - t0)
        contacts += [e for e in world.step_frame(commands) if isinstance(e, Contact)]
        after = world.snapshot().robots
        near = np.hypot(after[:, 2] - goals[:, 0], after[:, 3] - goals[:, 1]) < ARRIVED_M
        arrived[near & np.isnan(arrived)] = world.t
        if not np.isnan(arrived).any():
            break
    done = not np.isnan(arrived).any()
    completion = float(np.max(arrived)) if done else TIMEOUT_S
    contacts += world.open_contacts()
    return TrialResult(
        n, method, noise, len(contacts), sum(c.relative_speed_m_s > FAST_M_S for c in contacts),
        sum(c.max_depth_m * 1e3 * c.duration_s for c in contacts), completion, done,
        float(np.median(spent)) * 1e3 if spent else 0.0,
    )


_SETTINGS: list[Settings] = []  # handed to the forked workers (settings hold mapping proxies that do not pickle)


def _cell(args: tuple[int, str, str, Sequence[int]]) -> list[TrialResult]:
    n, method, noise, seeds = args
    return [run_trial(_SETTINGS[0], n, method, noise, s) for s in seeds]


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    robots = QUICK_ROBOTS if quick else ROBOTS
    trials = QUICK_TRIALS if quick else TRIALS
    seeds = list(range(trials))
    # chunks of trials, so that two processes share the work evenly (the machine has 2 cores)
    chunk = max(1, trials // 4)
    methods = (*METHODS, STANDIN)
    jobs = [(n, m, z, seeds[i : i + chunk]) for n in robots for z in ("default", "high") for m in methods
            for i in range(0, trials, chunk)]
    workers = max(1, min(2, os.cpu_count() or 1))
    results: list[TrialResult] = []
    _SETTINGS[:] = [settings]
    with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork")) as pool:
        for part in pool.map(_cell, jobs):
            results += part
    rows: list[dict[str, Any]] = []
    for n in robots:
        for z in ("default", "high"):
            base = float(np.mean([r.completion_s for r in results if (r.n, r.method, r.noise) == (n, "none", z)]))
            for m in methods:
                rs = [r for r in results if (r.n, r.method, r.noise) == (n, m, z)]
                completion = float(np.mean([r.completion_s for r in rs]))
                ms = float(np.mean([r.brain_ms for r in rs]))
                rows.append({
                    "name": f"{m} n={n} noise={z}", "robots": n, "trials": len(rs),
                    "collisions": sum(r.collisions for r in rs),
                    "collisions_above_1_5_m_s": sum(r.fast_collisions for r in rs),
                    "penetration_mm_s": float(np.mean([r.penetration_mm_s for r in rs])),
                    "completion_s": completion, "completion_ratio_to_none": completion / base,
                    "incomplete": sum(not r.completed for r in rs),
                    "ms_per_frame": ms, "ms_per_agent": ms / n,
                })
    return rows
