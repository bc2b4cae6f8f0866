"""A match in the simulator: what ``cmdragons play`` runs, as stages on a bus plus a clock.

Per camera frame the clock ticks; the simulator renders every camera; our team sees only those
images, through vision (one stage per camera) and its tracker; the brain decides; once every
playing team's commands are in, the simulator steps and the referee judges the frame. The opponent
is a built-in team playing on the true state (the simple team, or the defending team that marks
receivers and blocks shots), a copy of our team (its own tracker on the same detections, its own
brain), or nobody. :func:`built_in_wiring` plays two built-in teams against each other.

``perception = "truth"`` replaces the camera images by detections made from the simulator's truth
plus vision-like noise, drawn per team: for working on strategy, planning and control without
vision in the way.

:func:`wiring` is the table of stages; :class:`Match` runs them in lock-step over an in-process
transport. Statistics and summaries come from the bus (``summary/<stage>`` messages, the bus's own
timing), never from a stage's attributes.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from cmdragons.camera import CameraModel
from cmdragons.geometry import TEAMS, Team
from cmdragons.messages import Tick
from cmdragons.runtime.bus import Bus, Stage, Transport, run_frames
from cmdragons.runtime.pass_record import PassRecorder
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.stages import (
    BuiltInOpponentStage,
    BuiltInTeam,
    CameraTruthStage,
    RecorderStage,
    RefereeStage,
    ScriptStage,
    SimStage,
    StatsStage,
    SummaryCollector,
    TeamStage,
    TimingStage,
    TrackerStage,
    TruthPerceptionStage,
    VisionStage,
)
from cmdragons.runtime.topics import Contract, Port, WiringError, check_wiring
from cmdragons.team import Brain
from cmdragons.tracking import Tracker
from sim.params import SimParams, robot_keys

if TYPE_CHECKING:
    from cmdragons.recording import RecordingWriter
    from sim.script import ScriptedPlay
    from sim.simulator import Simulator

__all__ = ["BUILT_IN", "CLOCK", "OURS", "THEIRS", "BuiltIn", "Entry", "Match", "Opponent", "Perception", "build",
           "built_in_team", "built_in_wiring", "match_sim_params", "match_summary", "scripted_wiring",
           "served_wiring", "summary_stages", "timing_keys", "wiring"]

Opponent = Literal["simple", "defend", "self", "none", "outside", "simulation"]
BuiltIn = Literal["simple", "defend"]
BUILT_IN: tuple[BuiltIn, ...] = ("simple", "defend")  # the opponents the runtime plays itself, on the truth
Perception = Literal["vision", "truth"]
OURS: Team = "blue"
THEIRS: Team = "yellow"


@dataclass(frozen=True)
class Entry:
    """One row of a set-up's table: a stage's contract, the node that runs it in a distributed
    match ("": none does) and how to build it (only the node that runs it builds it)."""

    contract: Contract
    node: str
    build: Callable[[], Stage]


# where a topic nobody in a match writes comes from: the runtime's clock
CLOCK = (Port("clock", Tick),)


def match_sim_params(settings: Settings, opponent: Opponent) -> SimParams:
    """The simulator's parameters of a match: no robots of theirs against nobody."""
    params = settings.sim
    if opponent == "none":
        params = dataclasses.replace(params, robots_per_team={**params.robots_per_team, THEIRS: 0})
    return params


def wiring(settings: Settings, opponent: Opponent, perception: Perception, seed: int,
           sim: Callable[[], Simulator], render: bool = False,
           opponent_settings: Settings | None = None) -> list[Entry]:
    """The table of a match's stages, in the order they subscribe (which fixes the order of
    delivery). ``sim``: builds (or gives) the match's simulator, with ``seed``; ``render``: it draws
    the camera images also when the team plays on truth. ``opponent_settings``: the brain and
    tracker settings of the copy of our team (``self``; default ours)."""
    playing: list[Team] = [OURS] if opponent == "none" else [OURS, THEIRS]
    models = settings.camera_models()
    drawn = [m.id for m in models] if render or perception == "vision" else []
    vision_node = "sim" if settings.runtime.vision_with_sim else "vision"
    keys = robot_keys(settings.field, match_sim_params(settings, opponent))
    entries = [
        Entry(SimStage.declare(drawn), "sim", lambda: SimStage(sim(), playing)),
        Entry(RefereeStage.contract, "referee", functools.partial(_referee_stage, settings, keys)),
    ]
    brains: list[Team] = [OURS, THEIRS] if opponent == "self" else [OURS]
    # who is given detections: our team, its copy, or a team outside (``outside``: its own client on
    # the bus, commands on commands/yellow; ``simulation``: over the league's simulation protocol,
    # seeing SSL-Vision packets; the runtime runs nothing of it)
    seeing: list[Team] = [OURS, THEIRS] if opponent in ("self", "outside", "simulation") else [OURS]
    if perception == "vision":

        def vision(m: CameraModel) -> Stage:
            from vision.pipeline import VisionPipeline  # imported here: truth runs need no vision

            return VisionStage(m.id, VisionPipeline(settings.vision, settings.field, m))

        entries += [Entry(VisionStage.declare(m.id), vision_node, functools.partial(vision, m)) for m in models]
        topics = {team: [f"detections/{m.id}" for m in models] for team in brains}
        entries += _ssl_vision_stages(settings, models, topics, outside=opponent == "simulation")
        # the simulator's cameras capture together: one capture time a frame (not so SSL-Vision's packets,
        # which may come from cameras of their own)
        synchronized = settings.protocols.perception != "ssl_vision"
    else:
        t = settings.tracker  # the noise vision measures: the tracker's measurement model
        sigmas = (t.ball.measurement_sigma_m, t.robot.measurement_sigma_m, t.robot.measurement_sigma_rad)
        entries += [Entry(TruthPerceptionStage.declare(team), vision_node,
                          functools.partial(TruthPerceptionStage, team, sigmas, seed + k))
                    for k, team in enumerate(seeing)]
        topics = {team: [f"perception/{team}"] for team in brains}
        synchronized = True  # (one topic)
        if opponent == "simulation":  # the outside team's noisy truth, as SSL-Vision packets
            entries += _ssl_vision_stages(settings, models, {}, outside=True, topics_out=[f"perception/{THEIRS}"])
    referee_topic = "referee"
    p = settings.protocols
    if p.referee.send or p.referee.source == "game_controller" or opponent == "simulation":
        referee_stages, referee_topic = _ssl_referee_stages(settings, brains, send=opponent == "simulation")
        entries += referee_stages
    if opponent == "simulation":
        from cmdragons.runtime.ssl.stages import SimulationInStage

        entries.append(_protocol(SimulationInStage, p, THEIRS))
    for team in brains:
        own = opponent_settings if team == THEIRS and opponent_settings is not None else settings
        node = "team" if team == OURS else "opponent"
        entries += [Entry(TrackerStage.declare(team, topics[team]), node,
                          functools.partial(_tracker_stage, team, own, topics[team], synchronized)),
                    Entry(TeamStage.declare(team, referee_topic), node,
                          functools.partial(_team_stage, team, own, referee_topic))]
    entries += _ssl_out_stages(settings)
    if opponent in BUILT_IN:
        entries.append(Entry(BuiltInOpponentStage.declare(THEIRS), "opponent",
                             functools.partial(_built_in_stage, opponent, THEIRS, settings)))
    entries += [Entry(StatsStage.declare(OURS), "team", functools.partial(_stats_stage, OURS, settings)),
                Entry(TimingStage.contract, "team", TimingStage)]
    if opponent == "self":  # the copy of our team: its own figures too
        entries.append(Entry(StatsStage.declare(THEIRS), "opponent",
                             functools.partial(_stats_stage, THEIRS, opponent_settings or settings)))
    return entries


def _referee_stage(settings: Settings, keys: list[tuple[Team, int]]) -> Stage:
    from sim.referee import Referee  # (only the node that judges loads it)

    return RefereeStage(Referee(settings.field_geometry(), keys, settings.sim.referee))


def built_in_team(kind: BuiltIn, team: Team, settings: Settings) -> BuiltInTeam:
    """A built-in team of ``kind`` playing ``team``: its own section of configs/team.yaml
    (``simple_opponent``, ``defend_opponent``) and the strategy's parts (only the opponent's node
    loads them)."""
    if kind == "defend":
        from strategy.defend import DefendTeam

        return DefendTeam(team, settings.field_geometry(), settings.team.defend_opponent, settings.strategy)
    from strategy.simple import SimpleTeam

    return SimpleTeam(team, settings.field_geometry(), settings.team.simple_opponent, settings.strategy)


def _built_in_stage(kind: BuiltIn, team: Team, settings: Settings) -> Stage:
    return BuiltInOpponentStage(team, built_in_team(kind, team, settings))


def built_in_wiring(settings: Settings, blue: BuiltIn, yellow: BuiltIn, sim: Callable[[], Simulator]) -> list[Entry]:
    """The table of a match between two built-in teams on the true state (no cameras, no brain):
    the simulator, the referee and both teams; ``sim`` builds (or gives) the simulator."""
    keys = robot_keys(settings.field, settings.sim)
    sides: tuple[tuple[Team, BuiltIn], ...] = (("blue", blue), ("yellow", yellow))
    return [
        Entry(SimStage.declare([]), "sim", lambda: SimStage(sim(), list(TEAMS))),
        Entry(RefereeStage.contract, "referee", functools.partial(_referee_stage, settings, keys)),
        *(Entry(BuiltInOpponentStage.declare(team), "opponent",
                functools.partial(_built_in_stage, kind, team, settings)) for team, kind in sides),
    ]  # fmt: skip


def _stats_stage(team: Team, own: Settings) -> Stage:
    return StatsStage(team, PassRecorder.of(team, own))


def _tracker_stage(team: Team, own: Settings, topics: Sequence[str], synchronized: bool) -> Stage:
    return TrackerStage(team, Tracker(own.tracker), topics, synchronized=synchronized)


def _team_stage(team: Team, own: Settings, referee_topic: str) -> Stage:
    return TeamStage(team, Brain(team, own), referee_topic)


def scripted_wiring(sim: Simulator, script: ScriptedPlay, recorder: RecordingWriter | None) -> list[Entry]:
    """The table of ``cmdragons sim``: the simulator judging its own game (its referee inside),
    both teams' scripted robots, and the recorder of the camera images and truth (``None``: it
    only keeps the newest images)."""
    ids = [r.model.id for r in sim.renderers]
    return [Entry(SimStage.declare(ids, referee=True), "sim", lambda: SimStage(sim, TEAMS)),
            Entry(ScriptStage.contract, "sim", lambda: ScriptStage(script, sim.world)),
            Entry(RecorderStage.declare(ids), "sim", lambda: RecorderStage(recorder, ids))]  # fmt: skip


def served_wiring(settings: Settings, sim: Simulator, seed: int) -> list[Entry]:
    """The table of ``cmdragons sim --serve``: our simulator alone as a league simulator. Both
    teams' robots take the simulation protocol (``RobotControl`` on each team's port, teleports on
    the control port, a robot taken off the field parked out of view; a team that sends nothing has
    its robots stand; with ``protocols.serve.wait_s`` a frame waits for each team that has sent
    commands: lock-step), the field is seen as
    SSL-Vision packets from every camera of the division (detections made from the truth, with the
    geometry now and then), and the simulator's referee judges on the truth and speaks the league's
    Referee packets. ``sim``: built without rendering and without its own referee; ``seed``: the
    vision noise's."""
    from cmdragons.runtime.ssl.stages import RefereeOutStage, SimulationInStage, VisionOutStage
    from cmdragons.runtime.ssl.vision import geometry_packet
    from sim.restarts import park

    p, league = settings.protocols, settings.field
    # its vision where a simulation-protocol simulator sends it (grSim's and the ER-Force simulator's port)
    p = dataclasses.replace(p, vision=dataclasses.replace(p.vision, port=p.simulation.vision_port))
    models = settings.camera_models()
    ids = [m.id for m in models]
    geometry = geometry_packet(settings.field_geometry(), models)
    keys = robot_keys(league, settings.sim)
    sigmas = _measurement_sigmas(settings) if p.serve.vision_noise else (0.0, 0.0, 0.0)
    touch_m = settings.sim.kicker.touch_tolerance_m
    pitch = settings.field_geometry()  # a robot taken off the field waits where the referee parks robots sent off
    parked = {key: park(pitch, i, key[0], settings.sim.referee.park_distance_m) for i, key in enumerate(keys)}
    return [
        Entry(SimStage.declare([]), "sim", lambda: SimStage(sim, TEAMS)),
        Entry(RefereeStage.contract, "sim", functools.partial(_referee_stage, settings, keys)),
        Entry(CameraTruthStage.declare(ids), "sim",
              functools.partial(CameraTruthStage, models, league.robot.height_m, sigmas, seed)),
        Entry(SimulationInStage.declare(p, TEAMS), "", functools.partial(SimulationInStage, p, TEAMS, p.serve.wait_s,
                                                                           league, touch_m, parked, heard_only=True)),
        Entry(VisionOutStage.declare(p, ids, geometry), "", functools.partial(VisionOutStage, p, ids, geometry)),
        Entry(RefereeOutStage.contract, "", functools.partial(RefereeOutStage, p)),
    ]  # fmt: skip


def _measurement_sigmas(settings: Settings) -> tuple[float, float, float]:
    """The noise vision measures (ball m, robot m, robot rad): the tracker's measurement model."""
    t = settings.tracker
    return t.ball.measurement_sigma_m, t.robot.measurement_sigma_m, t.robot.measurement_sigma_rad


def _protocol(cls: Any, *args: Any) -> Entry:
    """A league protocol's stage, which no node of a distributed match runs: its contract is its
    own (it opens its sockets when built)."""
    return Entry(cls.declare(*args) if hasattr(cls, "declare") else cls.contract, "", lambda: cls(*args))


def build(entries: Sequence[Entry], extra: Sequence[Stage] = (), node: str | None = None,
          outside: Sequence[Port] = CLOCK) -> list[Stage]:
    """The stages of a set-up's table (``node``: only those that node runs), checked: the table's
    contracts with ``extra``'s fit (:func:`~cmdragons.runtime.topics.check_wiring`) and each stage
    built is what its row declared."""
    check_wiring([*(e.contract for e in entries), *(s.contract for s in extra)], outside)
    stages = []
    for e in entries:
        if node is not None and e.node != node:
            continue
        stage = e.build()
        if stage.contract != e.contract:
            raise WiringError(f"stage {e.contract.name!r} was built with the contract {stage.contract} but its row "
                              f"declares {e.contract}")
        stages.append(stage)
    return [*stages, *extra]


def _ssl_vision_stages(settings: Settings, models: Sequence[CameraModel], topics: dict[Team, list[str]],
                       outside: bool = False, topics_out: list[str] | None = None) -> list[Entry]:
    """Our vision as SSL-Vision packets (``protocols.vision.send``, or ``outside``: a team outside
    sees them; ``topics_out``: the detection topics sent, default our cameras') and our trackers on
    SSL-Vision packets (``protocols.perception: ssl_vision``; in lock-step with our own packets when
    we send them). ``topics`` (each team's detection topics) is changed to the packets' for the
    latter."""
    from cmdragons.runtime.ssl.stages import VisionInStage, VisionOutStage
    from cmdragons.runtime.ssl.vision import geometry_packet

    p = settings.protocols
    ids = [m.id for m in models]
    entries: list[Entry] = []
    if p.vision.send or outside:
        sent_ids = ids if topics_out is None else [0]
        entries.append(_protocol(VisionOutStage, p, sent_ids, geometry_packet(settings.field_geometry(), list(models)),
                                 topics_out))
    if topics_out is not None:
        return entries
    if p.perception == "ssl_vision":
        entries.append(_protocol(VisionInStage, p, ids, p.vision.send or outside))
        for team in topics:
            topics[team] = [f"ssl/vision/{i}" for i in ids]
    return entries


def _ssl_referee_stages(settings: Settings, brains: list[Team], send: bool = False) -> tuple[list[Entry], str]:
    """Our referee's word as the league's Referee packets (``protocols.referee.send`` or ``send``)
    and our brains on a game controller's packets (``protocols.referee.source: game_controller``);
    the referee topic the brains read."""
    from cmdragons.runtime.ssl.stages import RefereeInStage, RefereeOutStage

    p = settings.protocols
    entries: list[Entry] = [_protocol(RefereeOutStage, p)] if p.referee.send or send else []
    if p.referee.source == "simulator":
        return entries, "referee"
    moved_m = settings.sim.referee.figures.ball_in_play_m
    entries.append(_protocol(RefereeInStage, p, f"world/{brains[0]}", moved_m))
    return entries, "referee/gc"


def _ssl_out_stages(settings: Settings) -> list[Entry]:
    """Our tracker's world state as tracker packets (``protocols.tracker.send``) and our team's
    commands to a league simulator (``protocols.commands_to``)."""
    p = settings.protocols
    if not p.tracker.send and p.commands_to == "none":
        return []
    from cmdragons.runtime.ssl.stages import CommandsOutStage, TrackerOutStage

    entries: list[Entry] = [_protocol(TrackerOutStage, p, OURS)] if p.tracker.send else []
    if p.commands_to != "none":
        entries.append(_protocol(CommandsOutStage, p, OURS, settings.sim.kicker.chip_angle_rad))
    return entries


def timing_keys(table: Sequence[Entry]) -> dict[str, tuple[str, ...]]:
    """The per-frame timings of the summary, from a match's table: name -> the bus timing keys (a
    stage's name, or ``<stage>:<input>``) summed into it. The simulator's capture is ``render``, its
    steps go with ``physics_and_opponent``; our perception (vision per camera, our truth perception,
    the league's protocols) is ``vision``; our tracker and brain their own; what the match runs for
    the other side (the referee, the opponent and its perception) goes with the physics; the
    statistics are not timed."""
    keys: dict[str, list[str]] = {"render": [], "vision": [], "tracker": [], "brain": [], "physics_and_opponent": []}
    for e in table:
        name = e.contract.name
        if name == "sim":
            keys["render"].append("sim:clock")
            keys["physics_and_opponent"] += [f"sim:{t}" for t in e.contract.inputs if t != "clock"]
        elif name.startswith("vision/") or name == f"perception/{OURS}" or not e.node:
            keys["vision"].append(name)
        elif name in (f"tracker/{OURS}", f"team/{OURS}"):
            keys["tracker" if name.startswith("tracker/") else "brain"].append(name)
        elif not (name.startswith("stats/") or name == "timing"):
            keys["physics_and_opponent"].append(name)
    return {k: tuple(v) for k, v in keys.items()}


class Match:
    """Runs one match frame by frame; ``summary()`` gives the figures of summary.json.

    ``render``: draw the camera images even when the team plays on truth (for videos).
    ``extra``: more stages on the same bus (a logger, a video, a progress bar).
    ``opponent_settings``: with ``opponent="self"``, the copy's own brain and tracker settings
    (:func:`~cmdragons.runtime.settings.load_team_settings`; default ours)."""

    def __init__(self, settings: Settings, opponent: Opponent = "simple", perception: Perception = "vision",
                 seed: int | None = None, render: bool = False, extra: Sequence[Stage] = (),
                 transport: Transport | None = None, opponent_settings: Settings | None = None) -> None:
        if opponent_settings is not None and opponent != "self":
            raise ValueError("opponent_settings are for a copy of our team (opponent 'self')")
        self.settings = settings
        self.opponent: Opponent = opponent
        self.perception: Perception = perception
        from sim.simulator import Simulator  # (a distributed node that runs no simulator never loads it)

        self.sim = Simulator(settings.field, settings.camera_models(), match_sim_params(settings, opponent), seed=seed,
                             render=render or perception == "vision", referee=False,
                             look=settings.cameras.look())
        self.seed = self.sim.seed
        self.cameras = list(self.sim.cameras)
        self.bus = Bus(transport)
        self._summaries = SummaryCollector()
        table = wiring(settings, opponent, perception, self.seed, lambda: self.sim, render, opponent_settings)
        for stage in build(table, [*extra, self._summaries]):
            self.bus.add(stage)
        self._timings = timing_keys(table)
        self.frames = 0
        self.stage_ms: dict[str, list[float]] = {}
        self.bus.start()

    def step(self) -> None:
        """One camera frame of the match: capture, see, decide, act, judge."""
        t0 = time.perf_counter()
        self.bus.tick(self.frames)
        frame_ms = (time.perf_counter() - t0) * 1e3
        self.frames += 1
        times = self.bus.take_times()
        for name, keys in self._timings.items():
            self.stage_ms.setdefault(name, []).append(sum(times.get(k, 0.0) for k in keys))
        self.stage_ms.setdefault("frame", []).append(frame_ms)
        if self.opponent == "self":  # the copy's brain apart (it is also in physics_and_opponent)
            self.stage_ms.setdefault("opponent_brain", []).append(times.get(f"team/{THEIRS}", 0.0))

    def run(self, seconds: float, on_frame: Callable[[int], None] | None = None) -> dict[str, Any]:
        run_frames(lambda _i: self.step(), self.frames_in(seconds), on_frame=on_frame)
        return self.summary()

    def frames_in(self, seconds: float) -> int:
        """The camera frames of ``seconds`` of match (at least one)."""
        return max(1, round(seconds * self.settings.sim.physics.frame_rate_hz))

    def summary(self) -> dict[str, Any]:
        """The figures of the match so far, gathered from the stages' summaries on the bus."""
        self.bus.summarize()
        return match_summary(self._summaries.figures, self.stage_ms, self.seed, self.opponent, self.perception)

    def close(self) -> None:
        """Close what the stages hold open (the league protocols' sockets)."""
        from cmdragons.runtime.ssl.stages import close_sockets

        close_sockets(self.bus.stages)



def summary_stages(opponent: Opponent) -> set[str]:
    """The stages whose summaries :func:`match_summary` reads."""
    return {"sim", "referee", f"stats/{OURS}", "timing", f"tracker/{OURS}"} | (
        {f"stats/{THEIRS}"} if opponent == "self" else set())


def match_summary(f: dict[str, Any], stage_ms: dict[str, list[float]], seed: int, opponent: Opponent,
                  perception: Perception) -> dict[str, Any]:
    """summary.json's figures from every stage's summary (``f``: stage name -> figures) and the
    per-frame stage times (ms) the runtime measured."""
    sim, referee, stats = f["sim"], f["referee"], f[f"stats/{OURS}"]
    tracker = dict(f[f"tracker/{OURS}"])
    physics = tracker.pop("physics", None)  # what our tracker measured of the ball and robots
    open_pairs = [{a[0], b[0]} for a, b in sim["open_contacts"]]
    cycle = {k: {"median": float(np.median(v)), "p95": float(np.percentile(v, 95))}
             for k, v in stage_ms.items() if v}
    cycle.update(f["timing"].get(f"team/{OURS}", {}))  # the brain's parts
    return {
        "score": referee["score"],
        "shots": stats["shots"],
        "passes": stats["passes"],
        "kickoff_to_shot_s": stats["kickoff_to_shot_s"],
        "collisions": {"own": stats["collisions"]["own"] + sum(p == {OURS} for p in open_pairs),
                       "own_pushed": stats["collisions"]["own_pushed"],
                       "opponent": stats["collisions"]["opponent"] + sum(p == {OURS, THEIRS} for p in open_pairs)},
        "cycle_ms": cycle,
        "seconds": sim["seconds"],
        "seed": seed,
        "opponent": opponent,
        "perception": perception,
        "kicks": referee["kicks"],
        "balls_out": referee["balls_out"],
        "command_faults": sim["command_faults"],
        "tracker": tracker,
        **({"physics": physics} if physics is not None else {}),
        "rules": {k: referee[k] for k in ("rules", "game_stage", "fouls", "cards", "placements", "penalties",
                                           "shootout")},
        **({"opponent_team": _their_figures(f, open_pairs)} if opponent == "self" else {}),
        **({"protocols": protocols} if (protocols := {k: v for k, v in f.items() if k.startswith("ssl/")}) else {}),
    }  # fmt: skip


def _their_figures(f: dict[str, Any], open_pairs: list[set[str]]) -> dict[str, Any]:
    """The copy of our team's own figures: shots, passes, collisions among its robots."""
    stats = f[f"stats/{THEIRS}"]
    return {"shots": stats["shots"], "passes": stats["passes"],
            "collisions": {"own": stats["collisions"]["own"] + sum(p == {THEIRS} for p in open_pairs),
                           "own_pushed": stats["collisions"]["own_pushed"]}}
