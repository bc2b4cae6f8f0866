"""A match in the simulator: what ``cmdragons play`` runs.

Per camera frame: the simulator renders every camera; our team sees only those images, through
vision (one pipeline per camera) and its tracker; the brain decides; the simulator applies both
teams' commands. The opponent is the built-in simple team (playing on the true state), a copy of
our team (seeing through its own tracker), or nobody.

``perception = "truth"`` replaces the camera images by detections made from the simulator's truth
plus vision-like noise: for working on strategy, planning and control without vision in the way.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from cmdragons.geometry import Team
from cmdragons.messages import (
    BallDetection,
    BallState,
    DetectionFrame,
    GroundTruth,
    RobotCommand,
    RobotDetection,
    RobotState,
    WorldState,
)
from cmdragons.runtime.settings import Settings
from cmdragons.team import Brain
from cmdragons.tracking import Tracker
from sim.simulator import Frame, Simulator
from sim.world import Contact, Kick
from strategy.simple import SimpleTeam

__all__ = ["Match", "MatchStats", "Opponent", "Perception"]

Opponent = Literal["simple", "self", "none"]
Perception = Literal["vision", "truth"]
OURS: Team = "blue"
THEIRS: Team = "yellow"


def truth_world(gt: GroundTruth) -> WorldState:
    """The simulator's truth as a world state (what the simple opponent plays on)."""
    b = gt.ball
    return WorldState(gt.t, BallState(b.x, b.y, b.vx, b.vy), tuple(
        RobotState(r.team, r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega) for r in gt.robots))  # fmt: skip


@dataclass
class MatchStats:
    shots: int = 0
    passes_tried: int = 0
    passes_completed: int = 0
    own_collisions: int = 0
    opponent_collisions: int = 0
    pending_pass: tuple[float, int] | None = None  # (time kicked, passer id)
    stage_ms: dict[str, list[float]] = field(default_factory=dict)

    def time(self, stage: str, ms: float) -> None:
        self.stage_ms.setdefault(stage, []).append(ms)


class _Eyes:
    """One team's perception: camera images (or truth) -> detections -> tracked world state."""

    def __init__(self, settings: Settings, sim: Simulator, perception: Perception, seed: int) -> None:
        self.perception = perception
        self.tracker = Tracker(settings.tracker)
        self.rng = np.random.default_rng(seed)
        # truth perception: detections with the noise vision measures (the tracker's measurement model)
        t = settings.tracker
        self.noise = (t.ball.measurement_sigma_m, t.robot.measurement_sigma_m, t.robot.measurement_sigma_rad)
        self.pipelines: dict[int, Any] = {}
        if perception == "vision":
            from vision.pipeline import VisionPipeline  # imported here: truth runs need no vision

            self.pipelines = {m.id: VisionPipeline(settings.vision, settings.field, m) for m in sim.cameras}

    def detections(self, frame: Frame) -> list[DetectionFrame]:
        if self.perception == "vision":
            return [self.pipelines[cam].process(img, frame.frame_number, frame.t_capture)
                    for cam, img in sorted(frame.images.items())]  # fmt: skip
        gt, n = frame.truth, self.rng.normal
        s_ball, s_xy, s_theta = self.noise
        ball = (BallDetection(gt.ball.x + n(0, s_ball), gt.ball.y + n(0, s_ball), 1.0, (0.0, 0.0)),)
        robots = tuple(RobotDetection(r.team, r.id, r.x + n(0, s_xy), r.y + n(0, s_xy), r.theta + n(0, s_theta), 1.0,
                                      (0.0, 0.0)) for r in gt.robots)  # fmt: skip
        return [DetectionFrame(0, frame.frame_number, frame.t_capture, frame.t_capture, ball, robots)]


class Match:
    """Runs one match frame by frame; ``summary()`` gives the figures of summary.json."""

    def __init__(self, settings: Settings, opponent: Opponent = "simple", perception: Perception = "vision",
                 seed: int | None = None, render: bool = False) -> None:  # fmt: skip
        """``render``: draw the camera images even when the team plays on truth (for videos)."""
        params = settings.sim
        if opponent == "none":
            counts = dict(params.robots_per_team)
            counts[THEIRS] = 0
            params = dataclasses.replace(params, robots_per_team=counts)
        self.settings = settings
        self.opponent: Opponent = opponent
        models = settings.camera_models()
        self.sim = Simulator(settings.field, models, params, seed=seed,
                             render=render or perception == "vision")  # fmt: skip
        self.seed = self.sim.seed
        self.eyes = _Eyes(settings, self.sim, perception, self.seed)
        self.brain = Brain(OURS, settings)
        self.their_eyes: _Eyes | None = None
        self.their_brain: Brain | None = None
        self.simple: SimpleTeam | None = None
        if opponent == "self":
            self.their_eyes = _Eyes(settings, self.sim, perception, self.seed + 1)
            self.their_eyes.pipelines = self.eyes.pipelines  # the same cameras: one vision pass serves both
            self.their_brain = Brain(THEIRS, settings)
        elif opponent == "simple":
            self.simple = SimpleTeam(THEIRS, settings.field_geometry(), settings.team.simple_opponent,
                                     settings.strategy)  # fmt: skip
        self.stats = MatchStats()
        self.last_frame: Frame | None = None
        self.last_world: WorldState | None = None
        self.last_commands: list[RobotCommand] = []
        self.last_events: list[Any] = []  # the simulator's events of the last step (goals, kicks, ...)

    def step(self) -> Frame:
        """One camera frame of the match; returns what the cameras saw."""
        stats = self.stats
        t0 = time.perf_counter()
        frame = self.sim.capture()
        t1 = time.perf_counter()
        detections = self.eyes.detections(frame)
        t2 = time.perf_counter()
        world = self.eyes.tracker.step(detections)
        t3 = time.perf_counter()
        ours = self.brain.step(world, frame.game)
        t4 = time.perf_counter()
        self.eyes.tracker.command_sent(ours, frame.t_capture)
        theirs = self._their_commands(frame, detections)
        events = self.sim.advance(ours + theirs)
        t5 = time.perf_counter()
        for stage, ms in (("render", t1 - t0), ("vision", t2 - t1), ("tracker", t3 - t2), ("brain", t4 - t3),
                          ("physics_and_opponent", t5 - t4), ("frame", t5 - t0)):  # fmt: skip
            stats.time(stage, ms * 1e3)
        for name in ("strategy", "planning_control", "safety"):
            if self.brain.times.get(name):
                stats.time(name, self.brain.times[name][-1])
        self._count(frame, events)
        self.last_frame, self.last_world, self.last_commands = frame, world, ours
        self.last_events = events
        return frame

    def _their_commands(self, frame: Frame, detections: list[DetectionFrame]) -> list[RobotCommand]:
        if self.simple is not None:
            return self.simple.commands(truth_world(frame.truth), frame.game)
        if self.their_brain is not None and self.their_eyes is not None:
            world = self.their_eyes.tracker.step(detections)
            cmds = self.their_brain.step(world, frame.game)
            self.their_eyes.tracker.command_sent(cmds, frame.t_capture)
            return cmds
        return []

    def _count(self, frame: Frame, events: list[Any]) -> None:
        s = self.stats
        for e in events:
            if isinstance(e, Kick) and e.team == OURS:
                action = self.brain.strategy.last_action.get(e.id)
                if action == "shot":
                    s.shots += 1
                elif action == "pass":
                    s.passes_tried += 1
                    s.pending_pass = (e.t, e.id)
            elif isinstance(e, Contact):
                teams = {e.a[0], e.b[0]}
                if teams == {OURS}:
                    s.own_collisions += 1
                elif OURS in teams:
                    s.opponent_collisions += 1
        if s.pending_pass is not None:
            t_kick, passer = s.pending_pass
            b = frame.truth.ball
            holders = [r for r in frame.truth.robots if math.hypot(r.x - b.x, r.y - b.y) < 0.15]
            if frame.t_capture - t_kick > self.settings.strategy.pass_timeout_s or frame.game.command != "normal":
                s.pending_pass = None
            elif frame.t_capture - t_kick > 0.2 and holders:
                if any(r.team == OURS and r.id != passer for r in holders):
                    s.passes_completed += 1
                s.pending_pass = None

    def run(self, seconds: float, on_frame: Callable[[Frame], None] | None = None) -> dict[str, Any]:
        n = max(1, round(seconds * self.settings.sim.physics.frame_rate_hz))
        for _ in range(n):
            frame = self.step()
            if on_frame is not None:
                on_frame(frame)
        return self.summary()

    def summary(self) -> dict[str, Any]:
        sim = self.sim.summary()
        s = self.stats
        return {
            "score": sim["score"],
            "shots": s.shots,
            "passes": {"tried": s.passes_tried, "completed": s.passes_completed},
            "collisions": {"own": s.own_collisions + self._open_contacts({OURS}),
                           "opponent": s.opponent_collisions + self._open_contacts({OURS, THEIRS})},
            "cycle_ms": {k: {"median": float(np.median(v)), "p95": float(np.percentile(v, 95))}
                         for k, v in s.stage_ms.items() if v},
            "seconds": sim["seconds"],
            "seed": self.seed,
            "opponent": self.opponent,
            "perception": self.eyes.perception,
            "kicks": sim["kicks"],
            "balls_out": sim["balls_out"],
            "command_faults": sim["command_faults"],
            "tracker": self.eyes.tracker.stats.as_dict(),
        }  # fmt: skip

    def _open_contacts(self, teams: set[str]) -> int:
        return sum(1 for c in self.sim.world.open_contacts() if {c.a[0], c.b[0]} == teams)

