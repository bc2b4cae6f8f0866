"""The stages of a match, each a thin adapter between the bus and one algorithm object.

Each declares its contract (:class:`~cmdragons.runtime.topics.Contract`: the topics it reads and
writes, with their messages), as a class attribute or a ``declare`` of the arguments that shape its
topics; the topic reference of docs/architecture.md is generated from them (docs/topics.py).

Nothing here reaches into another stage: what a stage needs from another comes on a topic.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.geometry import TEAMS, Team, wrap_angle
from cmdragons.messages import (
    BallDetection,
    CameraFrame,
    Contact,
    DetectionFrame,
    GameEvents,
    GameState,
    GroundTruth,
    Kick,
    KickPurpose,
    PhysicsFacts,
    RefereeCommand,
    RobotCommand,
    RobotDetection,
    RobotReport,
    SimEvents,
    StageSummary,
    TeamCommands,
    TeamReport,
    Teleport,
    Tick,
    Timing,
    WorldState,
)
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.log import RunLog
from cmdragons.runtime.pass_record import PassRecorder
from cmdragons.runtime.topics import ANY, Contract, Port, summary_port, topic_matches
from cmdragons.team import Brain, BrainOutput
from cmdragons.tracking import Tracker

if TYPE_CHECKING:
    from cmdragons.recording import RecordingWriter
    from sim.referee import Referee
    from sim.script import ScriptedPlay
    from sim.simulator import Simulator
    from sim.world import World

__all__ = [
    "CameraTruthStage",
    "LoggerStage",
    "RecorderStage",
    "RefereeStage",
    "ScriptStage",
    "BuiltInOpponentStage",
    "BuiltInTeam",
    "SimStage",
    "StatsStage",
    "SummaryCollector",
    "Tap",
    "TeamStage",
    "TimingStage",
    "TrackerStage",
    "TruthPerceptionStage",
    "VisionStage",
    "message_time",
]


class SimStage(BaseStage):
    """The simulator with its cameras. On a tick it captures the frame (truth, then each camera's
    image); once every playing team's commands for that frame came, it steps the physics and
    publishes the frame's events; teleports it carries out at once; the referee's game state tells
    it which goal each team defends (the sides change at half time), so that a goal names its scorer.

    Commands that answer an older frame (they came after that frame was stepped without them: a
    team slower than the free-running clock, or silent past the lock-step wait) are what a real
    robot's radio would get late: the newest of them is sent with the next step that has no
    commands of its own frame from that team, once."""

    @staticmethod
    def declare(camera_ids: Sequence[int], referee: bool = False) -> Contract:
        """``referee``: the simulator judges the game itself (``cmdragons sim``): it publishes the
        referee's word after the truth and carries out its restarts, so it takes no teleports (and
        follows its own referee's sides); else it follows the referee's word on topic ``referee``."""
        outside = (Port("teleport", Teleport), Port("referee", GameState))
        reads = (Port("clock", Tick), Port("commands/*", TeamCommands), *(() if referee else outside))
        return Contract("sim", reads,
                        (Port("truth", GroundTruth), *((Port("referee", GameState),) if referee else ()),
                         *(Port(f"camera/{c}/frame", CameraFrame) for c in camera_ids),
                         Port("events", SimEvents), summary_port("sim")))

    def __init__(self, sim: Simulator, teams: Sequence[Team]) -> None:
        # the cameras it draws; the referee when the simulator judges
        self.contract = self.declare([r.model.id for r in sim.renderers], sim.referee is not None)
        self.sim = sim
        self.teams = tuple(t for t in TEAMS if t in teams)
        self.frame_number = -1
        self._commands: dict[Team, TeamCommands] = {}
        self._late: dict[Team, TeamCommands] = {}  # per team: the newest commands for an older frame
        self._sent: dict[Team, int] = {}  # per team: the frame the commands last sent answered

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == "clock":
            self._capture(publish)
        elif topic == "teleport":
            self.sim.teleport(message)
        elif topic == "referee":
            self.sim.follow(message)
        elif isinstance(message, TeamCommands) and message.team in self.teams:
            if message.frame_number == self.frame_number:
                self._commands[message.team] = message
                if all(t in self._commands for t in self.teams):
                    self._advance(publish)
            elif message.frame_number > self._sent.get(message.team, -1):
                late = self._late.get(message.team)
                if late is None or message.frame_number >= late.frame_number:
                    self._late[message.team] = message

    def _capture(self, publish: Publish) -> None:
        frame = self.sim.capture()
        self.frame_number = frame.frame_number
        self._commands = {}
        publish("truth", frame.truth)
        if frame.game is not None:
            publish("referee", frame.game)
        for cam, image in sorted(frame.images.items()):
            publish(f"camera/{cam}/frame", CameraFrame(cam, frame.frame_number, frame.t_capture, image))
        if not self.teams:
            self._advance(publish)

    def advance_without_missing(self, publish: Publish) -> list[Team]:
        """Step the frame in progress with the commands that came (a team that is silent keeps its
        robots' last commands until the robots' own command timeout brakes them); the teams that
        were missing. Nothing happens between frames."""
        if self.frame_number < 0:
            return []
        missing = [t for t in self.teams if t not in self._commands]
        self._advance(publish)
        return missing

    def _advance(self, publish: Publish) -> None:
        sent = {**self._late, **self._commands}
        self._late = {}
        commands = [c for t in self.teams if t in sent for c in sent[t].commands]
        self._sent.update({t: tc.frame_number for t, tc in sent.items()})
        self._commands = {}
        events = self.sim.advance(commands)
        publish("events", SimEvents(self.frame_number, self.sim.t, self.sim.ball_xy(), tuple(events)))
        self.frame_number = -1  # until the next capture, commands are stale

    def summarize(self, publish: Publish) -> None:
        figures = dict(self.sim.summary())
        figures["open_contacts"] = [[list(c.a), list(c.b)] for c in self.sim.world.open_contacts()]
        publish(f"summary/{self.name}", StageSummary(self.name, figures))


class ScriptStage(BaseStage):
    """The scripted robots of ``cmdragons sim`` (both teams): on each frame's truth, every team's
    commands. They are the simulator's own players and read its world as it stands."""

    contract = Contract("script", (Port("truth", GroundTruth),),
                        tuple(Port(f"commands/{team}", TeamCommands) for team in TEAMS))

    def __init__(self, script: ScriptedPlay, world: World) -> None:
        self.script = script
        self.world = world

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        truth: GroundTruth = message
        commands = self.script.commands(self.world.snapshot())
        for team in TEAMS:
            mine = tuple(c for c in commands if c.team == team)
            publish(f"commands/{team}", TeamCommands(team, truth.frame_number, truth.t, mine))


class RecorderStage(BaseStage):
    """Writes each frame's camera images and truth (:class:`~cmdragons.recording.RecordingWriter`)
    once every camera of the frame came; keeps the newest images (a snapshot)."""

    @staticmethod
    def declare(camera_ids: Sequence[int]) -> Contract:
        return Contract("recorder", (Port("truth", GroundTruth),
                                     *(Port(f"camera/{c}/frame", CameraFrame) for c in camera_ids)))

    def __init__(self, writer: RecordingWriter | None, camera_ids: Sequence[int]) -> None:
        self.contract = self.declare(camera_ids)
        self.writer = writer
        self.camera_ids = tuple(camera_ids)
        self.images: dict[int, NDArray[np.uint8]] = {}
        self._truth: GroundTruth | None = None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, GroundTruth):
            self._truth, self.images = message, {}
            return
        f: CameraFrame = message
        self.images[f.camera_id] = f.image
        if self.writer is not None and self._truth is not None and len(self.images) == len(self.camera_ids):
            self.writer.write(f.frame_number, {c: self.images[c] for c in self.camera_ids}, self._truth)


class VisionStage(BaseStage):
    """One camera's vision: image -> detections."""

    @staticmethod
    def declare(camera_id: int) -> Contract:
        return Contract(f"vision/{camera_id}", (Port(f"camera/{camera_id}/frame", CameraFrame),),
                        (Port(f"detections/{camera_id}", DetectionFrame),))

    def __init__(self, camera_id: int, pipeline: Any) -> None:
        self.contract = self.declare(camera_id)
        self.camera_id = camera_id
        self.pipeline = pipeline

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        f: CameraFrame = message
        publish(f"detections/{self.camera_id}", self.pipeline.process(f.image, f.frame_number, f.t_capture))


class TruthPerceptionStage(BaseStage):
    """Detections made from the simulator's truth plus vision-like noise, for one team (its own
    draws): for work on strategy, planning and control without vision in the way."""

    @staticmethod
    def declare(team: Team) -> Contract:
        return Contract(f"perception/{team}", (Port("truth", GroundTruth),),
                        (Port(f"perception/{team}", DetectionFrame),))

    def __init__(self, team: Team, sigmas: tuple[float, float, float], seed: int) -> None:
        self.contract = self.declare(team)
        self.topic = f"perception/{team}"
        self.sigma_ball, self.sigma_xy, self.sigma_theta = sigmas
        self.rng = np.random.default_rng(seed)

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        gt: GroundTruth = message
        n, sb, sxy, sth = self.rng.normal, self.sigma_ball, self.sigma_xy, self.sigma_theta
        ball = (BallDetection(gt.ball.x + n(0, sb), gt.ball.y + n(0, sb), 1.0, (0.0, 0.0)),)
        robots = tuple(RobotDetection(r.team, r.id, r.x + n(0, sxy), r.y + n(0, sxy), r.theta + n(0, sth), 1.0,
                                      (0.0, 0.0)) for r in gt.robots)
        publish(self.topic, DetectionFrame(0, gt.frame_number, gt.t, gt.t, ball, robots))


class CameraTruthStage(BaseStage):
    """The served simulator's vision (``cmdragons sim --serve``), as grSim's: each camera's
    detections made from the truth, without rendering: the ball where its centre projects into the
    camera's image, each robot where the centre of its top does (so an object in the strip two
    cameras share is seen by both, as on a real field), with its pixel there. ``sigmas`` (ball m,
    robot m, robot rad): vision-like noise, drawn per camera (all zero: the exact truth)."""

    @staticmethod
    def declare(camera_ids: Sequence[int]) -> Contract:
        return Contract("vision/truth", (Port("truth", GroundTruth),),
                        tuple(Port(f"detections/{c}", DetectionFrame) for c in camera_ids))

    def __init__(self, cameras: Sequence[CameraModel], robot_height_m: float, sigmas: tuple[float, float, float],
                 seed: int) -> None:
        self.cameras = tuple(cameras)
        self.contract = self.declare([m.id for m in self.cameras])
        self.robot_height_m = robot_height_m
        self.sigma_ball, self.sigma_xy, self.sigma_theta = sigmas
        self.rng = np.random.default_rng(seed)

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        gt: GroundTruth = message
        b = gt.ball
        points = np.array([[b.x, b.y, b.z], *([r.x, r.y, self.robot_height_m] for r in gt.robots)])
        n, sb, sxy, sth = self.rng.normal, self.sigma_ball, self.sigma_xy, self.sigma_theta
        for m in self.cameras:
            px = m.project(points)
            seen = m.in_image(px)
            balls = (BallDetection(b.x + n(0, sb), b.y + n(0, sb), 1.0, (float(px[0, 0]), float(px[0, 1]))),) \
                if seen[0] else ()
            robots = tuple(RobotDetection(r.team, r.id, r.x + n(0, sxy), r.y + n(0, sxy),
                                          wrap_angle(r.theta + n(0, sth)), 1.0, (float(p[0]), float(p[1])))
                           for r, p, s in zip(gt.robots, px[1:], seen[1:], strict=True) if s)
            publish(f"detections/{m.id}", DetectionFrame(m.id, gt.frame_number, gt.t, gt.t, balls, robots))


class TrackerStage(BaseStage):
    """One team's tracker: steps once every detection topic it reads has delivered the frame (a
    newer frame first closes the one in progress with what came), and takes its team's commands as
    the robots' control input (``take_commands``; not when the robots seen are driven by someone
    else, as in a real match's log). The physics facts it measured go to the brain whenever the tracker
    hands on those in use (``physics/<team>``), and into its summary.

    ``synchronized``: the cameras of a frame share its capture time (the simulator's cameras), so
    each camera's detections are taken as they come, in the order of ``detection_topics``, and the
    frame is closed when the last comes: the same work in the same order as taking them together,
    but done while the other cameras are still being seen (in another process, the tracker works on
    the first camera while vision works on the second). Otherwise a frame's detections wait for
    one another and are taken in capture-time order.

    ``team`` names its topics (``world/<team>``); a tracker of no team (the auto-referee's,
    ``autoref``) takes no commands."""

    @staticmethod
    def declare(team: Team | Literal["autoref"], detection_topics: Sequence[str],
                take_commands: bool = True) -> Contract:
        name = f"tracker/{team}"
        return Contract(name, (*(Port(t, DetectionFrame) for t in detection_topics),
                               *((Port(f"commands/{team}", TeamCommands),) if take_commands else ())),
                        (Port(f"physics/{team}", PhysicsFacts, sometimes=True), Port(f"world/{team}", WorldState),
                         summary_port(name)))

    def __init__(self, team: Team | Literal["autoref"], tracker: Tracker, detection_topics: Sequence[str],
                 take_commands: bool = True, synchronized: bool = False) -> None:
        self.contract = self.declare(team, detection_topics, take_commands)
        self.team = team
        self.detection_topics = tuple(detection_topics)
        self.tracker = tracker
        self.synchronized = synchronized
        self._frame = -1
        self._pending: dict[str, DetectionFrame] = {}
        self._taken = 0  # synchronized: how many of the frame's topics, in order, the tracker took
        self._t_frame = -math.inf  # the newest capture time of the frame in progress
        self._t_capture: dict[int, float] = {}
        self._handed = tracker.handed  # the physics facts the brain was handed last

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, TeamCommands):
            t = self._t_capture.pop(message.frame_number, None)
            if t is not None:
                self.tracker.command_sent(message.commands, t)
            return
        det: DetectionFrame = message
        if det.frame_number != self._frame and (self._pending or self._taken):
            self._step(publish)
        self._frame = det.frame_number
        self._pending[topic] = det
        self._t_frame = max(self._t_frame, det.t_capture)
        if self.synchronized:
            while self._taken < len(self.detection_topics) and self.detection_topics[self._taken] in self._pending:
                self.tracker.take(self._pending.pop(self.detection_topics[self._taken]))
                self._taken += 1
        if self._taken + len(self._pending) == len(self.detection_topics):
            self._step(publish)

    def _step(self, publish: Publish) -> None:
        frames = [self._pending[t] for t in sorted(self._pending, key=self.detection_topics.index)]
        if self.synchronized:
            for frame in frames:  # (a frame closed early: what came after the first missing camera)
                self.tracker.take(frame)
            world = self.tracker.finish()
        else:
            world = self.tracker.step(frames)
        self._pending, self._taken = {}, 0
        self._t_capture = {self._frame: self._t_frame}
        self._t_frame = -math.inf
        if self.tracker.handed is not self._handed:
            self._handed = self.tracker.handed
            publish(f"physics/{self.team}", self._handed)
        publish(f"world/{self.team}", WorldState(world.t, world.ball, world.robots, self._frame))

    def summarize(self, publish: Publish) -> None:
        figures: dict[str, Any] = dict(self.tracker.stats.as_dict())
        if self.tracker.estimator is not None:
            figures["physics"] = self.tracker.physics.summary()
        publish(f"summary/{self.name}", StageSummary(self.name, figures))


class _PlayingStage(BaseStage, ABC):
    """A team that plays: keeps the referee's latest word and answers each of its world inputs
    with that frame's commands (:meth:`play`)."""

    def __init__(self, contract: Contract, team: Team, referee_topic: str = "referee") -> None:
        self.contract = contract
        self.referee_topic = referee_topic
        self.team = team
        self.game = GameState(0.0)

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == self.referee_topic:
            self.game = message
            return
        world, commands = self.play(message)
        publish(f"commands/{self.team}", TeamCommands(self.team, world.frame_number, world.t, tuple(commands)))
        self.after(world, publish)

    @abstractmethod
    def play(self, message: Any) -> tuple[WorldState, list[RobotCommand]]:
        """The world state ``message`` gives and this frame's commands on it."""

    def after(self, world: WorldState, publish: Publish) -> None:
        return None


class TeamStage(_PlayingStage):
    """One team's brain: world state and game state -> that frame's commands, its report and its
    parts' times, all from the brain's output of the frame; the physics facts its tracker measured
    tune it when they come."""

    @staticmethod
    def declare(team: Team, referee_topic: str = "referee") -> Contract:
        return Contract(f"team/{team}", (Port(f"world/{team}", WorldState), Port(referee_topic, GameState),
                                         Port(f"physics/{team}", PhysicsFacts, sometimes=True)),
                        (Port(f"commands/{team}", TeamCommands), Port(f"report/{team}", TeamReport),
                         Port(f"timing/{team}", Timing)))

    def __init__(self, team: Team, brain: Brain, referee_topic: str = "referee") -> None:
        super().__init__(self.declare(team, referee_topic), team, referee_topic)
        self.brain = brain
        self._out: BrainOutput | None = None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, PhysicsFacts):
            self.brain.use_physics(message)
            return
        super().on_message(topic, message, publish)

    def play(self, message: Any) -> tuple[WorldState, list[RobotCommand]]:
        self._out = self.brain.step(message, self.game)
        return message, list(self._out.commands)

    def after(self, world: WorldState, publish: Publish) -> None:
        out = self._out
        assert out is not None
        publish(f"report/{self.team}", _report(self.team, world, out))
        publish(f"timing/{self.team}", Timing(self.name, world.frame_number, dict(out.times_ms)))


def _report(team: Team, world: WorldState, out: BrainOutput) -> TeamReport:
    """The brain's output of a frame as its report (the pass evaluation on the frames it was redone)."""
    robots = tuple(
        RobotReport(rid, p.status.value, (p.intent.x, p.intent.y, p.intent.theta), _points(p.path), p.command,
                    _points(out.braking.get(rid, ())))
        for rid, p in out.plans.items()
    )
    points, values = out.pass_heat if out.pass_heat is not None else (_points(()), np.zeros(0))
    return TeamReport(team, world.frame_number, world.t, robots, dict(out.last_actions), points, values, out.passing)


def _points(a: Any) -> NDArray[np.float64]:
    """(k, 2) points, field frame, m."""
    return np.asarray(a, dtype=np.float64).reshape(-1, 2)


class BuiltInTeam(Protocol):
    """A built-in opponent (:class:`strategy.simple.SimpleTeam`, :class:`strategy.defend.DefendTeam`):
    one frame's commands of its robots from the true state and the referee's word."""

    def commands(self, world: WorldState, game: GameState) -> list[RobotCommand]: ...


class BuiltInOpponentStage(_PlayingStage):
    """A built-in opponent: plays on the true state (the simple team, the defending team)."""

    @staticmethod
    def declare(team: Team) -> Contract:
        return Contract(f"opponent/{team}", (Port("truth", GroundTruth), Port("referee", GameState)),
                        (Port(f"commands/{team}", TeamCommands),))

    def __init__(self, team: Team, plays: BuiltInTeam) -> None:
        super().__init__(self.declare(team), team)
        self.plays = plays

    def play(self, message: Any) -> tuple[WorldState, list[RobotCommand]]:
        world = message.world()
        return world, self.plays.commands(world, self.game)


class RefereeStage(BaseStage):
    """The simulator's referee: the frame's events (and, for the full rules, the true state the
    auto-referee judges) -> the game state, the frame's calls and a restart's teleport."""

    contract = Contract("referee", (Port("truth", GroundTruth), Port("events", SimEvents)),
                        (Port("teleport", Teleport), Port("referee", GameState),
                         Port("referee/events", GameEvents, sometimes=True),
                         summary_port("referee")))

    def __init__(self, referee: Referee) -> None:
        self.referee = referee
        self._truth: GroundTruth | None = None

    def start(self, publish: Publish) -> None:
        publish("teleport", self.referee.kickoff_setup("blue"))
        publish("referee", self.referee.state())

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == "truth":
            self._truth = message
            return
        ev: SimEvents = message
        teleport = self.referee.observe(ev.t, ev.events, ev.ball_xy, self._truth)
        if self.referee.calls.new:
            publish("referee/events", GameEvents(ev.t, tuple(self.referee.calls.new)))
        if teleport is not None:
            publish("teleport", teleport)
        publish("referee", self.referee.state())

    def summarize(self, publish: Publish) -> None:
        r = self.referee
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "score": dict(r.score), "kicks": r.kicks, "balls_out": r.balls_out,
            "keeper_held_ball": r.keeper_held_ball, "robot_contacts": len(r.contacts), **r.summary()}))


class StatsStage(BaseStage):
    """One team's match statistics from the bus: shots and passes (kicks with the action the
    strategy had decided), each pass's record (:mod:`cmdragons.runtime.pass_record`: its plan, kick,
    timing and how it ended), the time from each kickoff to our first shot after it, collisions
    among own robots (apart: those where an opponent touched one of the two, pushing it into the
    other) and with opponents."""

    @staticmethod
    def declare(team: Team) -> Contract:
        return Contract(f"stats/{team}", (Port("truth", GroundTruth), Port("referee", GameState),
                                          Port(f"report/{team}", TeamReport), Port("events", SimEvents)),
                        (summary_port(f"stats/{team}"),))

    def __init__(self, team: Team, passes: PassRecorder) -> None:
        self.contract = self.declare(team)
        self.team = team
        self.passes = passes
        self.shots = 0
        self.own_collisions = self.own_pushed = self.opponent_collisions = 0
        self.kickoff_to_shot_s: list[float | None] = []  # per kickoff: to our first shot (None: none before the next)
        self._kickoff_t: float | None = None  # the kickoff's normal start, our shot after it not yet taken
        self._truth: GroundTruth | None = None
        self._game = GameState(0.0)
        self._actions: dict[int, KickPurpose] = {}

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if topic == "truth":
            self._truth = message
            self.passes.truth(message)
        elif topic == "referee":
            self._referee(message)
        elif isinstance(message, TeamReport):
            self._actions = dict(message.actions)
            self.passes.report(message)
        elif isinstance(message, SimEvents):
            self._count(message)

    def _referee(self, game: GameState) -> None:
        started = game.command == RefereeCommand.KICKOFF and game.ready
        if started and not (self._game.command == RefereeCommand.KICKOFF and self._game.ready):
            if self._kickoff_t is not None:
                self.kickoff_to_shot_s.append(None)
            self._kickoff_t = game.t
        self._game = game
        self.passes.referee(game)

    def _count(self, ev: SimEvents) -> None:
        for e in ev.events:
            if isinstance(e, Kick) and e.team == self.team:
                action = self._actions.get(e.id)
                if action is KickPurpose.SHOT:
                    self.shots += 1
                    if self._kickoff_t is not None:
                        self.kickoff_to_shot_s.append(e.t - self._kickoff_t)
                        self._kickoff_t = None
                self.passes.kick(e, action, self._truth)
            elif isinstance(e, Contact):
                teams = {e.a[0], e.b[0]}
                if teams == {self.team} and e.pushed_by is not None:
                    self.own_pushed += 1
                elif teams == {self.team}:
                    self.own_collisions += 1
                elif self.team in teams:
                    self.opponent_collisions += 1

    def summarize(self, publish: Publish) -> None:
        shots = [s for s in self.kickoff_to_shot_s if s is not None]
        publish(f"summary/{self.name}", StageSummary(self.name, {
            "shots": self.shots, "passes": self.passes.summary(),
            "kickoff_to_shot_s": {"kickoffs": len(self.kickoff_to_shot_s) + (self._kickoff_t is not None),
                                  "with_shot": len(shots),
                                  "median": round(float(np.median(shots)), 3) if shots else None,
                                  "each": [None if s is None else round(s, 3) for s in self.kickoff_to_shot_s]},
            "collisions": {"own": self.own_collisions, "own_pushed": self.own_pushed,
                           "opponent": self.opponent_collisions},
        }))


class TimingStage(BaseStage):
    """Median and 95th percentile of every timed part on ``timing/*`` (ms), per stage."""

    contract = Contract("timing", (Port("timing/*", Timing),), (summary_port("timing"),))

    def __init__(self) -> None:
        self.ms: dict[str, dict[str, list[float]]] = {}

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        t: Timing = message
        parts = self.ms.setdefault(t.stage, {})
        for k, v in t.ms.items():
            parts.setdefault(k, []).append(v)

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, {
            stage: {k: {"median": float(np.median(v)), "p95": float(np.percentile(v, 95))} for k, v in parts.items()}
            for stage, parts in self.ms.items()}))


def message_time(message: Any, default: float) -> float:
    """A message's own time stamp (capture time, else its time), else ``default`` (s)."""
    for attr in ("t_capture", "t"):
        t = getattr(message, attr, None)
        if isinstance(t, float | int) and math.isfinite(t):
            return float(t)
    return default


class LoggerStage(BaseStage):
    """Every topic into an MCAP log, each message at its own time stamp; camera images only when
    asked (about 2.4 MB a frame and camera). Wall-clock timings are left out by default, so the same
    seed gives the same log byte for byte."""

    contract = Contract("logger", (Port("*", ANY),))

    def __init__(self, log: RunLog, images: bool = False,
                 skip: Sequence[str] = ("clock", "control/*", "timing/*", "summary/timing")) -> None:
        self.log = log
        self.skip = tuple(skip) + (() if images else ("camera/*",))
        self._t = 0.0

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if any(topic_matches(p, topic) for p in self.skip):
            return
        self._t = message_time(message, self._t)
        self.log.write("/" + topic, self._t, message)


class SummaryCollector(BaseStage):
    """Keeps the latest summary of every stage (topic ``summary/<stage>``)."""

    contract = Contract("summaries", (Port("summary/*", StageSummary),))

    def __init__(self) -> None:
        self.figures: dict[str, dict[str, Any]] = {}

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        s: StageSummary = message
        self.figures[s.stage] = dict(s.figures)


class Tap(BaseStage):
    """Calls ``fn(topic, message)`` for every message on its topics (progress bars, viewers)."""

    def __init__(self, name: str, inputs: Sequence[str], fn: Callable[[str, Any], None]) -> None:
        self.contract = Contract(name, tuple(Port(t, ANY) for t in inputs))
        self.fn = fn

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        self.fn(topic, message)
