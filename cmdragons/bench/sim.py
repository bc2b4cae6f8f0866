"""``cmdragons bench sim``: physics per frame (12 and 22 robots), rendering per camera frame next to
a plain OpenCV 2D drawing of the same scene, and the whole simulator step against real time."""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import cv2
import numpy as np

from cmdragons.camera import CameraModel
from cmdragons.geometry import LeagueParams
from cmdragons.runtime.settings import Settings
from sim.script import ScriptedPlay
from sim.simulator import Simulator
from sim.snapshot import Snapshot

__all__ = ["run"]


def _simulator(settings: Settings, league: LeagueParams, render: bool) -> tuple[Simulator, ScriptedPlay]:
    from cmdragons.camera import cameras_from_config
    from cmdragons.geometry import Field

    models = cameras_from_config(settings.cameras, league)
    sim = Simulator(league, models, settings.sim, render=render)
    script = ScriptedPlay(Field(league), league.robot.radius_m, settings.sim.script, sim.rng)
    return sim, script


def _physics_ms(sim: Simulator, script: ScriptedPlay, frames: int) -> list[float]:
    out = []
    for _ in range(frames):
        commands = script.commands(sim.world.snapshot())
        t0 = time.perf_counter()
        sim.advance(commands)
        out.append((time.perf_counter() - t0) * 1e3)
    return out


def _opencv_draw(model: CameraModel, league: LeagueParams, background: np.ndarray, snap: Snapshot) -> np.ndarray:
    """Baseline: the scene drawn flat with OpenCV circles (no lens, parallax, occlusion or blur)."""
    img = background.copy()
    scale = model.pixels_per_metre((float(model.center[0]), float(model.center[1])), league.robot.height_m)
    pat = league.pattern
    for row in snap.robots:
        th = row[4]
        c, s = np.cos(th), np.sin(th)
        centre = model.project_xy(row[2:4], league.robot.height_m)
        cv2.circle(img, (int(centre[0]), int(centre[1])), int(league.robot.radius_m * scale), (20, 20, 20), -1)
        colour = (230, 120, 20) if row[0] == 0 else (20, 220, 240)
        cv2.circle(img, (int(centre[0]), int(centre[1])), int(pat.center_dot_diameter_m / 2 * scale), colour, -1)
        for (dx, dy), pink in zip(pat.dot_positions_m, pat.dot_is_pink(int(row[1])), strict=True):
            p = model.project_xy(np.array([row[2] + c * dx - s * dy, row[3] + s * dx + c * dy]), league.robot.height_m)
            cv2.circle(img, (int(p[0]), int(p[1])), int(pat.id_dot_diameter_m / 2 * scale),
                       (200, 80, 255) if pink else (60, 230, 60), -1)
    b = model.project_xy(snap.ball[:2], snap.ball[2])
    cv2.circle(img, (int(b[0]), int(b[1])), max(1, int(league.ball.radius_m * scale)), (0, 128, 255), -1)
    return img


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    frames = 120 if quick else 900
    warm = 30
    frame_ms = 1e3 / settings.sim.physics.frame_rate_hz
    rows: list[dict[str, Any]] = []

    # physics alone, 12 robots (division B) and 22 robots (division A)
    for league in (settings.field, dataclasses.replace(settings.field, division="A")):
        n = 2 * league.dims.robots_per_team
        sim, script = _simulator(settings, league, render=False)
        _physics_ms(sim, script, warm)
        ms = _physics_ms(sim, script, frames)
        med = float(np.median(ms))
        rows.append({"name": f"physics_{n}_robots", "median_ms": med, "p95_ms": float(np.percentile(ms, 95)),
                     "realtime_factor": frame_ms / med})

    # rendering, per camera frame, next to the OpenCV baseline on the same snapshots
    sim, script = _simulator(settings, settings.field, render=True)
    for _ in range(warm):
        sim.capture()
        sim.advance(script.commands(sim.world.snapshot()))
    ours: list[float] = []
    base: list[float] = []
    backgrounds = {r.model.id: r.render(sim.world.snapshot())[0] for r in sim.renderers}
    for _ in range(frames // 2):
        snap = sim.world.snapshot()
        for r in sim.renderers:
            t0 = time.perf_counter()
            r.render(snap)
            ours.append((time.perf_counter() - t0) * 1e3)
            t0 = time.perf_counter()
            _opencv_draw(r.model, settings.field, backgrounds[r.model.id], snap)
            base.append((time.perf_counter() - t0) * 1e3)
        sim.advance(script.commands(snap))
    m = sim.cameras[0]
    res = f"{m.width}x{m.height}"
    rows.append({"name": f"render_per_camera_{res}", "median_ms": float(np.median(ours)),
                 "p95_ms": float(np.percentile(ours, 95)),
                 "ratio_to_opencv_flat": float(np.median(ours) / np.median(base))})
    rows.append({"name": f"opencv_flat_per_camera_{res} (baseline)", "median_ms": float(np.median(base)),
                 "p95_ms": float(np.percentile(base, 95))})

    # the whole step: both cameras + scripted commands + physics, as `cmdragons sim` runs it
    step: list[float] = []
    for _ in range(frames):
        t0 = time.perf_counter()
        sim.capture()
        sim.advance(script.commands(sim.world.snapshot()))
        step.append((time.perf_counter() - t0) * 1e3)
    med = float(np.median(step))
    rows.append({"name": f"whole_step_{len(sim.cameras)}_cameras", "median_ms": med,
                 "p95_ms": float(np.percentile(step, 95)), "realtime_factor": frame_ms / med})
    return rows
