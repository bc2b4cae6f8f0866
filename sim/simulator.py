"""The simulator as one object: physics, referee and overhead cameras, frame by frame.

``capture()`` renders every camera at the current instant and returns the images with their
ground truth; ``advance(commands)`` sends commands at that instant and steps one camera frame.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, RealisticParams
from cmdragons.geometry import TEAMS, LeagueParams, Team
from cmdragons.messages import BallOut, Contact, GameState, Goal, GroundTruth, Kick, RobotCommand, Teleport
from sim.params import SimParams, robot_counts
from sim.referee import Referee
from sim.render import CameraRenderer, Lighting
from sim.world import World

__all__ = ["Frame", "Simulator", "referee_summary"]


@dataclass(frozen=True)
class Frame:
    """One camera frame: an image per camera id (BGR uint8) and the truth at capture time."""

    t_capture: float
    frame_number: int
    images: dict[int, NDArray[np.uint8]]
    truth: GroundTruth
    game: GameState | None  # None when the referee runs as a stage of its own


@dataclass
class StageTimes:
    """Wall-clock milliseconds per call, for summaries and benchmarks."""

    physics_ms: list[float] = field(default_factory=list)
    render_ms: list[float] = field(default_factory=list)


class Simulator:
    def __init__(
        self,
        league: LeagueParams,
        cameras: Sequence[CameraModel],
        params: SimParams,
        *,
        seed: int | None = None,
        render: bool = True,
        referee: bool = True,
        look: RealisticParams | None = None,
    ) -> None:
        """``referee``: judge the game here (``cmdragons sim``); off, the referee is a stage of its own
        that sends teleports (:meth:`teleport`). ``look``: the cameras are a lab's (cameras.yaml
        ``preset: realistic``, :meth:`CamerasParams.look`), under one light seeded by the match's seed."""
        self.league, self.params = league, params
        self.seed = params.seed if seed is None else seed
        counts = robot_counts(league, params)
        self.world = World(league, params.physics, params.world_robot(), params.world_ball(), params.kicker,
                           params.dribbler, robots_per_team=counts)
        self.world.blue_defends = -1 if params.referee.blue_defends == "negative_x" else 1
        self.referee: Referee | None = None
        if referee:
            # scripted robots place no balls and know no fouls: the referee of ``cmdragons sim`` keeps the basics
            basic = dataclasses.replace(params.referee, rules="basic")
            self.referee = Referee(self.world.field, self.world.robot_keys(), basic)
            self.world.apply(self.referee.kickoff_setup("blue"))
        self.cameras = list(cameras)
        seeds = np.random.SeedSequence(self.seed).spawn(len(self.cameras) + 1)
        self.rng = np.random.default_rng(seeds[0])  # for scripted play and anything else of the sim
        lighting = None if look is None else Lighting(league, look, self.seed)
        self.renderers = (
            [CameraRenderer(m, league, params.render, seed=int(s.generate_state(1)[0]), lighting=lighting)
             for m, s in zip(self.cameras, seeds[1:], strict=True)]
            if render else []
        )
        self.times = StageTimes()

    @property
    def t(self) -> float:
        return self.world.t

    @property
    def frame_dt(self) -> float:
        return self.world.frame_dt

    def capture(self) -> Frame:
        """Render all cameras at the current instant."""
        snap = self.world.snapshot()
        images: dict[int, NDArray[np.uint8]] = {}
        ball_px: dict[int, tuple[float, float, float]] = {}
        robot_px: dict[tuple[Team, int], dict[int, tuple[float, float]]] = {}
        t0 = time.perf_counter()
        for renderer in self.renderers:
            cam = renderer.model.id
            image, truth = renderer.render(snap)
            images[cam] = image
            if truth.ball is not None:
                ball_px[cam] = truth.ball
            for (team, rid), px in truth.robots.items():
                robot_px.setdefault((TEAMS[team], rid), {})[cam] = px
        if self.renderers:
            self.times.render_ms.append((time.perf_counter() - t0) * 1e3)
        gt = self.world.ground_truth(snap, ball_px, robot_px)
        return Frame(snap.t, snap.frame_number, images, gt, None if self.referee is None else self.referee.state())

    def advance(self, commands: Iterable[RobotCommand] = ()) -> list[Goal | BallOut | Kick | Contact]:
        """Send ``commands`` now and step one camera frame; returns the frame's events."""
        t0 = time.perf_counter()
        events = self.world.step_frame(commands)
        if self.referee is not None:
            teleport = self.referee.observe(self.world.t, events, self.ball_xy())
            if teleport is not None:
                self.world.apply(teleport)
            self.follow(self.referee.state())
        self.times.physics_ms.append((time.perf_counter() - t0) * 1e3)
        return events

    def ball_xy(self) -> tuple[float, float]:
        """Where the ball lies now (field frame, m)."""
        x, y = self.world.ball_body.position
        return (float(x), float(y))

    def teleport(self, teleport: Teleport) -> None:
        """Put objects in place at once (a referee's restart)."""
        self.world.apply(teleport)

    def follow(self, game: GameState) -> None:
        """Take the referee's word on which goal each team defends (the sides change at half
        time): a goal is the team's that attacks it."""
        self.world.blue_defends = -1 if game.blue_defends_negative_x else 1

    def summary(self) -> dict[str, object]:
        """Facts of the run so far, for summary.json (the referee's too when it judges here)."""
        out: dict[str, object] = {
            "seconds": round(self.world.t, 6),
            "frames": self.world.frame_number,
            "seed": self.seed,
            "command_faults": self.world.faults.as_dict(),
        }
        if self.referee is not None:
            out |= referee_summary(self.referee, self.world.open_contacts())
        return out


def referee_summary(referee: Referee, open_contacts: Sequence[Contact]) -> dict[str, object]:
    """The referee's figures of a run: score, kicks, balls out, keeper-held balls, robot contacts
    (those still open at the end included)."""
    contacts = referee.contacts + list(open_contacts)
    return {
        "score": dict(referee.score),
        "kicks": referee.kicks,
        "balls_out": referee.balls_out,
        "keeper_held_ball": referee.keeper_held_ball,
        "robot_contacts": {
            "count": len(contacts),
            "max_depth_m": max((c.max_depth_m for c in contacts), default=0.0),
            "max_relative_speed_m_s": max((c.relative_speed_m_s for c in contacts), default=0.0),
            "total_duration_s": sum(c.duration_s for c in contacts),
        },
    }
