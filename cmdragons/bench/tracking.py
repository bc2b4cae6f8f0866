"""``cmdragons bench tracking``: the tracker on the simulator's rendered cameras through vision.

Per noise level (default, high): scripted play rendered by both cameras, seen by the vision
pipeline, with 5% of the ball detections dropped and the ball hidden for 0.5 s; the tracker's ball
and robot positions and velocities against the truth, next to the raw detections' position error;
id swaps; and the tracker's time per frame with 23 objects (22 robots and the ball, division A).

Robots the referee teleports (kickoff formation) are left out for 0.1 s. The tracker is scored at
capture time (its look-ahead set to zero): the look-ahead is a prediction of the future, scored by
the latency tests, not here. An id swap is a track taking another robot's detection.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from cmdragons.geometry import TEAMS
from cmdragons.messages import DetectionFrame
from cmdragons.runtime.settings import Settings
from cmdragons.tracking import Tracker
from sim.render import RenderParams
from sim.script import ScriptedPlay
from sim.simulator import Simulator

__all__ = ["run"]

LEVELS: dict[str, dict[str, Any]] = {
    "default": {},
    "high": {"noise_sigma_grey": 6.0, "vignetting_fraction": 0.25, "gradient_fraction": 0.15, "exposure_s": 0.004},
}
OCCLUSION_S = (4.0, 4.5)  # the ball's detections are removed in this window
DROP_BALL = 0.05  # share of ball detections dropped at random


def _rms(values: list[float]) -> float:
    return float(math.sqrt(np.mean(np.square(values)))) if values else math.nan


def _scenario(settings: Settings, level: str, seconds: float, seed: int) -> dict[str, Any]:
    from vision.pipeline import VisionPipeline

    render: RenderParams = dataclasses.replace(settings.sim.render, **LEVELS[level])
    sim_params = dataclasses.replace(settings.sim, render=render)
    models = settings.camera_models()
    sim = Simulator(settings.field, models, sim_params, seed=seed)
    script = ScriptedPlay(settings.field_geometry(), settings.field.robot.radius_m, settings.sim.script, sim.rng)
    pipelines = {m.id: VisionPipeline(settings.vision, settings.field, m) for m in models}
    tracker = Tracker(dataclasses.replace(settings.tracker, latency_s=0.0))
    rng = np.random.default_rng([seed, 99])
    raw_ball, raw_robot, ball_pos, ball_vel, robot_pos, robot_vel = [], [], [], [], [], []
    swaps = 0
    prev_ball_v = None
    quiet = 0  # frames since the ball's velocity last jumped (kick, bounce, contact)
    owner: dict[tuple[str, int], tuple[str, int]] = {}
    prev_xy: dict[tuple[str, int], tuple[float, float]] = {}
    placed_at: dict[tuple[str, int], float] = {}
    n = round(seconds * settings.sim.physics.frame_rate_hz)
    for _ in range(n):
        frame = sim.capture()
        gt = frame.truth
        dets = []
        for cam, img in sorted(frame.images.items()):
            d = pipelines[cam].process(img, frame.frame_number, frame.t_capture)
            hidden = OCCLUSION_S[0] <= frame.t_capture < OCCLUSION_S[1]
            balls = tuple(b for b in d.balls if not hidden and rng.random() >= DROP_BALL)
            dets.append(DetectionFrame(d.camera_id, d.frame_number, d.t_capture, d.t_sent, balls, d.robots))
            for b in balls:
                raw_ball.append(math.hypot(b.x - gt.ball.x, b.y - gt.ball.y))
            truth_xy = {(r.team, r.id): (r.x, r.y) for r in gt.robots}
            for rd in d.robots:
                if (rd.team, rd.id) in truth_xy:
                    tx, ty = truth_xy[(rd.team, rd.id)]
                    raw_robot.append(math.hypot(rd.x - tx, rd.y - ty))
        ws = tracker.step(dets)
        bv = np.array([gt.ball.vx, gt.ball.vy])
        quiet = 0 if prev_ball_v is None or np.linalg.norm(bv - prev_ball_v) > 0.15 else quiet + 1
        prev_ball_v = bv
        if ws.ball is not None and ws.ball.visible:
            ball_pos.append(math.hypot(ws.ball.x - gt.ball.x, ws.ball.y - gt.ball.y))
            # rolling freely: moving, and no kick, bounce or contact in the last 0.2 s
            if np.linalg.norm(bv) > 0.05 and quiet >= 12:
                ball_vel.append(math.hypot(ws.ball.vx - gt.ball.vx, ws.ball.vy - gt.ball.vy))
        truth = {(r.team, r.id): r for r in gt.robots}
        # the referee's placements teleport robots: not motion a tracker can follow; skip 0.1 s
        for key, true_robot in truth.items():
            last = placed_at.get(key)
            jump = math.hypot(true_robot.x - prev_xy[key][0], true_robot.y - prev_xy[key][1]) if key in prev_xy else 0.0
            if jump > 0.2:
                placed_at[key] = frame.t_capture
            elif last is not None and frame.t_capture - last > 0.1:
                del placed_at[key]
            prev_xy[key] = (true_robot.x, true_robot.y)
        for r in ws.robots:
            t = truth.get((r.team, r.id))
            if t is None or (r.team, r.id) in placed_at:
                continue
            robot_pos.append(math.hypot(r.x - t.x, r.y - t.y))
            robot_vel.append(math.hypot(r.vx - t.vx, r.vy - t.vy))
            # an id swap: a track that took another robot's detection (a coasting track is only stale)
            if not r.visible:
                continue
            nearest = min(truth.values(), key=lambda q: math.hypot(q.x - r.x, q.y - r.y))
            key = (nearest.team, nearest.id)
            if owner.get((r.team, r.id), key) != key:
                swaps += 1
            owner[(r.team, r.id)] = key
        sim.advance(script.commands(sim.world.snapshot()))
    return {
        "name": f"{level}_noise",
        "ball_rms_mm": 1e3 * _rms(ball_pos),
        "raw_ball_rms_mm": 1e3 * _rms(raw_ball),
        "ratio_ball_to_raw": _rms(ball_pos) / _rms(raw_ball) if raw_ball else math.nan,
        "ball_vel_rolling_rms_m_s": _rms(ball_vel),
        "robot_rms_mm": 1e3 * _rms(robot_pos),
        "raw_robot_rms_mm": 1e3 * _rms(raw_robot),
        "robot_vel_rms_m_s": _rms(robot_vel),
        "id_swaps": swaps,
        "frames": n,
        "ball_kicks_detected": tracker.stats.ball_kicks,
    }


def _timing(settings: Settings, frames: int) -> dict[str, Any]:
    """Tracker time per frame with 23 objects: 22 robots and the ball (division A, 4 cameras),
    on detections made from the truth (vision is not what is timed here)."""
    league = dataclasses.replace(settings.field, division="A")
    sim = Simulator(league, [], settings.sim, render=False)
    script = ScriptedPlay(settings.field_geometry(), league.robot.radius_m, settings.sim.script, sim.rng)
    tracker = Tracker(settings.tracker)
    rng = np.random.default_rng(5)
    from cmdragons.messages import BallDetection, RobotDetection

    times = []
    # detections as noisy as the tracker is configured to expect from vision
    sb, sr, sa = (settings.tracker.ball.measurement_sigma_m, settings.tracker.robot.measurement_sigma_m,
                  settings.tracker.robot.measurement_sigma_rad)
    for k in range(frames + 30):
        s = sim.world.snapshot()
        ball = (BallDetection(float(s.ball[0] + rng.normal(0, sb)), float(s.ball[1] + rng.normal(0, sb)), 1.0,
                              (0.0, 0.0)),)
        robots = tuple(RobotDetection(TEAMS[int(r[0])], int(r[1]), float(r[2] + rng.normal(0, sr)),
                                      float(r[3] + rng.normal(0, sr)), float(r[4] + rng.normal(0, sa)), 1.0,
                                      (0.0, 0.0)) for r in s.robots)
        det = DetectionFrame(0, s.frame_number, s.t, s.t, ball, robots)
        t0 = time.perf_counter()
        tracker.step([det])
        if k >= 30:
            times.append((time.perf_counter() - t0) * 1e3)
        sim.advance(script.commands(s))
    return {"name": "tracker_23_objects", "median_ms": float(np.median(times)),
            "p95_ms": float(np.percentile(times, 95)), "objects": 1 + len(sim.world.robots)}


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    seconds = 6.0 if quick else 20.0
    rows = [_scenario(settings, level, seconds, seed=7) for level in LEVELS]
    rows.append(_timing(settings, 300 if quick else 1200))
    return rows
