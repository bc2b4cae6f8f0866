"""Our team in a simulator of someone else's: ``cmdragons play --simulator grsim|sim-protocol``.

The simulator (grSim, the ER-Force simulator, our own ``cmdragons sim --serve``) is the world: we
build no simulator, renderer or vision of our own. What our team knows of it comes as the league's
software would have it:

- perception: the simulator's SSL-Vision packets (multicast; grSim and the ER-Force simulator send
  on port 10020, the league's SSL-Vision on 10006: ``protocols.grsim.vision_port`` or
  ``protocols.simulation.vision_port``). The cameras are whichever the packets come from, learnt
  before the match (:func:`listen`) from the detections heard and the geometry's calibrations;
- the field: the geometry the simulator sends (its size, goals and defense areas), which our
  planner, strategy and referee play on (:func:`field_settings`; a difference from field.yaml is
  one line on stderr);
- the clock: vision's capture time, from the whole second of the first frame the match plays on.
  The frame loop waits for the simulator's packets (a frame is the tracker's step on them), and
  ``--seconds`` is match time on that clock;
- commands: grSim packets to its command port, resent on each vision frame (grSim stops a robot
  whose last packet is older than one of its frames), or the simulation protocol (each team's
  ``RobotControl`` to its port, teleports as ``SimulatorCommand`` to the control port).

:func:`outside_wiring` is the set-up's table of stages (checked by
:func:`~cmdragons.runtime.match.build` as every set-up's is); :class:`OutsideMatch` runs it.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cmdragons.geometry import Team
from cmdragons.messages import MessageError, WorldState
from cmdragons.runtime.autoref import autoref_rows
from cmdragons.runtime.bus import Bus, Stage, Transport
from cmdragons.runtime.match import Entry, build
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.params import CommandsTo, ProtocolParams
from cmdragons.runtime.ssl.stages import (
    CommandsOutStage,
    RefereeInStage,
    RefereeOutStage,
    RobotCountStage,
    TrackerOutStage,
    VisionInStage,
    close_sockets,
)
from cmdragons.runtime.ssl.vision import VisionGeometry, decode_wrapper, field_dims_of
from cmdragons.runtime.stages import SummaryCollector, Tap, TeamStage, TimingStage, TrackerStage
from sim.substitution import RobotCount

__all__ = ["FrameGate", "Heard", "OutsideError", "OutsideMatch", "SimulatorKind", "beyond_division", "field_settings",
           "listen", "outside_settings", "outside_summary", "outside_wiring", "take_off", "vision_params"]


class SimulatorKind(enum.Enum):
    """Whose simulator a match plays in (``play --simulator``)."""

    OWN = "own"  # our own, embedded (cmdragons.runtime.match)
    GRSIM = "grsim"  # grSim's own command packets
    SIM_PROTOCOL = "sim-protocol"  # the league's simulation protocol (grSim, the ER-Force simulator, sim --serve)


class OutsideError(RuntimeError):
    """The outside simulator cannot be played in (nothing heard from it, a field we cannot play on)."""


def vision_params(params: ProtocolParams, kind: SimulatorKind) -> ProtocolParams:
    """The protocols with SSL-Vision on the simulator's port: grSim's ``grsim.vision_port`` or the
    simulation protocol's ``simulation.vision_port``."""
    port = params.grsim.vision_port if kind is SimulatorKind.GRSIM else params.simulation.vision_port
    commands_to: CommandsTo = "grsim" if kind is SimulatorKind.GRSIM else "simulation"
    return dataclasses.replace(params, vision=dataclasses.replace(params.vision, port=port), commands_to=commands_to,
                               perception="ssl_vision")


class FrameGate:
    """The vision socket as the frame loop sees it: :meth:`wait` blocks until a packet came (kept
    for the receiving stage's :meth:`drain`), so that each frame starts when the simulator's
    vision does, not on our clock. A frame that came while we were busy with an earlier one is
    passed over when a newer one of the same camera is here (a team plays on the newest frame):
    :attr:`skipped` counts them; geometry packets and what cannot be read go through (the receiving
    stage reads and counts them)."""

    def __init__(self, receiver: Any) -> None:
        self.receiver = receiver
        self._held: list[bytes] = []
        self.skipped = 0

    def wait(self, timeout_s: float) -> bool:
        """Whether a packet is here, waiting up to ``timeout_s`` for one."""
        if self._held:
            return True
        data = self.receiver.receive(timeout_s)
        if data is None:
            return False
        self._held.append(data)
        return True

    def receive(self, timeout_s: float = 0.0) -> bytes | None:
        if self._held:
            return self._held.pop(0)
        data: bytes | None = self.receiver.receive(timeout_s)
        return data

    def drain(self) -> list[bytes]:
        came, self._held = [*self._held, *self.receiver.drain()], []
        frames: list[tuple[int, int] | None] = []  # (camera, frame number) of each packet's detections
        for data in came:
            try:
                det, _ = decode_wrapper(data)
            except MessageError:
                det = None
            frames.append(None if det is None else (det.camera_id, det.frame_number))
        newest: dict[int, int] = {}
        for f in frames:
            if f is not None:
                newest[f[0]] = max(newest.get(f[0], f[1]), f[1])
        passed = {f for f in frames if f is not None and f[1] < newest[f[0]]}
        self.skipped += len({n for _, n in passed})
        return [data for data, f in zip(came, frames, strict=True) if f not in passed]

    def close(self) -> None:
        self._held = []
        self.receiver.close()


@dataclass(frozen=True)
class Heard:
    """What the simulator's vision said before the match: its geometry, its cameras (those whose
    detections came), the packets heard and the robots seen."""

    geometry: VisionGeometry
    cameras: tuple[int, ...]
    packets: int
    robots: tuple[tuple[Team, int], ...] = ()  # (team, id) of every robot seen

    @property
    def uncalibrated(self) -> tuple[int, ...]:
        """Cameras that send detections but have no calibration in the geometry (played all the same)."""
        return tuple(sorted(set(self.cameras) - {c.camera_id for c in self.geometry.cameras}))


def listen(receiver: Any, timeout_s: float, learn_s: float, where: str,
           clock: Callable[[], float] = time.monotonic) -> Heard:
    """Read the simulator's SSL-Vision packets until its geometry came and ``learn_s`` passed since
    its first detection (the cameras it sends from are those heard by then); :class:`OutsideError`
    naming ``where`` when neither came within ``timeout_s``."""
    t0 = clock()
    geometry: VisionGeometry | None = None
    seen: set[int] = set()
    robots: set[tuple[Team, int]] = set()
    packets = undecodable = 0
    t_first: float | None = None  # when the first detection came
    while True:
        now = clock()
        if geometry is not None and t_first is not None and now - t_first >= learn_s:
            break
        if now - t0 >= timeout_s:
            lacks = " and ".join(w for w, got in (("a geometry", geometry), ("a detection", seen)) if not got)
            heard = f"{packets} packets heard ({undecodable} undecodable), none with {lacks}" if packets \
                else "nothing heard"
            raise OutsideError(f"no SSL-Vision geometry and detections from the simulator on {where} in "
                               f"{timeout_s:g} s ({heard}): is it running, and sending on that port?")
        data = receiver.receive(min(0.05, max(0.0, timeout_s - (now - t0))))
        if data is None:
            continue
        packets += 1
        try:
            det, geo = decode_wrapper(data, UnixEpoch(0))  # (the sender's own times)
        except MessageError:
            undecodable += 1
            continue
        if geo is not None:
            geometry = geo
        if det is not None:
            if t_first is None:
                t_first = clock()
            seen.add(det.camera_id)
            robots.update((r.team, r.id) for r in det.robots)
    assert geometry is not None
    return Heard(geometry, tuple(sorted(seen)), packets, tuple(sorted(robots)))


def beyond_division(robots: Sequence[tuple[Team, int]], per_team: int) -> tuple[tuple[Team, int], ...]:
    """The robots (team, id) beyond the division's ``per_team`` a team: of a team with more, those of
    the highest ids (the ER-Force simulator puts 11 a team on its Division B field too)."""
    out: list[tuple[Team, int]] = []
    for team in ("blue", "yellow"):
        ids = sorted(rid for t, rid in robots if t == team)
        out += [(team, rid) for rid in ids[per_team:]]
    return tuple(out)


def take_off(params: ProtocolParams, robots: Sequence[tuple[Team, int]], times: int = 3) -> None:
    """Take ``robots`` off the simulator's field: a ``SimulatorCommand`` with ``present: false`` for
    each to its control port (grSim's and every simulation-protocol simulator's), sent ``times``
    times (UDP: one may be lost; a robot off the field stays off)."""
    from cmdragons.runtime.ssl.commands import off_field_packet
    from cmdragons.runtime.ssl.udp import UdpEndpoint

    s = params.simulation
    endpoint = UdpEndpoint(s.address)
    try:
        for _ in range(times):
            endpoint.send_to(off_field_packet(robots), (s.address, s.control_port))
            time.sleep(0.05)
    finally:
        endpoint.close()


# the sizes a geometry packet gives, compared with field.yaml's (m)
_COMPARED = ("length_m", "width_m", "boundary_width_m", "goal_width_m", "goal_depth_m", "defense_depth_m",
             "defense_width_m", "center_circle_radius_m", "line_width_m", "goal_height_m")
_SAME_M = 0.0015  # sent in whole millimetres: a difference below this is rounding


def field_settings(settings: Settings, geometry: VisionGeometry) -> tuple[Settings, str | None]:
    """The settings on the simulator's field: the division whose length is nearest the sent one,
    sized as the geometry's field (:func:`~cmdragons.runtime.ssl.vision.field_dims_of`: what it
    leaves out, field.yaml's); and one line that says how the field differs from field.yaml's
    division in force (None: it does not)."""
    league = settings.field
    division = min(league.divisions, key=lambda d: abs(league.divisions[d].length_m - geometry.field_length_m))
    try:
        dims = field_dims_of(geometry, league.divisions[division])
    except MessageError as exc:
        raise OutsideError(str(exc)) from None
    new = dataclasses.replace(league, division=division, divisions={**league.divisions, division: dims})
    ours = league.dims
    diffs = [f"{k.removesuffix('_m')} {getattr(dims, k):.3f} m (field.yaml {getattr(ours, k):.3f})" for k in _COMPARED
             if abs(getattr(ours, k) - getattr(dims, k)) >= _SAME_M]
    if division != league.division:
        diffs.insert(0, f"division {division} (field.yaml {league.division})")
    line = None
    if diffs:
        line = f"field: the simulator's differs from field.yaml's division {league.division}: {', '.join(diffs)}; " \
               "we play on the simulator's"
    return dataclasses.replace(settings, field=new), line


_BRAKE_KEY = "field.robot.max_brake_m_s2"


def outside_settings(config: str | None, overrides: Sequence[str]) -> Settings:
    """The settings of a match in an outside simulator: ``config`` with ``overrides`` (play's --config
    and --set), the robots' braking the simulator's as far as our team knows before our tracker
    measured it (``protocols.outside.robot_max_brake_m_s2``; field.yaml's robot is our own
    simulator's): motion control brakes for it, the safety search keeps two robots apart by it, and
    the tracker's measurement replaces it once confident and off it. A --set of field.yaml's
    braking itself stays as given."""
    from cmdragons.runtime.settings import load_settings

    settings = load_settings(config, overrides)
    brake = settings.protocols.outside.robot_max_brake_m_s2
    if brake <= 0.0 or any(o.partition("=")[0].strip() == _BRAKE_KEY for o in overrides):
        return settings
    return load_settings(config, [f"{_BRAKE_KEY}={brake!r}", *overrides])


def outside_wiring(settings: Settings, kind: SimulatorKind, teams: Sequence[Team], cameras: Sequence[int],
                   receiver: Any, robots: Sequence[tuple[Team, int]]) -> list[Entry]:
    """The table of a match in an outside simulator: the simulator's SSL-Vision packets (``cameras``,
    read from ``receiver``) into each of our ``teams``' tracker and brain, their commands out to
    the simulator (``kind``; the referee's teleports through the first team's stage). Match time
    counts from the first packet the match plays on (its whole second): how long the simulator's
    clock ran while the team listened and was built is no match time (the referee's first kickoff
    was most of its time gone when the team first saw it). The referee:
    ours on the tracked world (the autoref, for the match's ``robots``), or a game controller's
    packets with ``protocols.referee.source: game_controller``."""
    p = vision_params(settings.protocols, kind)
    topics = [f"ssl/vision/{c}" for c in cameras]
    entries = [Entry(VisionInStage.declare(p, cameras, False), "",
                     lambda: VisionInStage(p, cameras, lockstep=False, receiver=receiver))]
    referee, referee_topic, teleports = _referee(settings, p, teams[0], topics, robots)
    entries += referee
    chip = settings.sim.kicker.chip_angle_rad
    pitch = settings.field_geometry()
    for k, team in enumerate(teams):
        sends = teleports and k == 0  # one team's stage sends the referee's teleports
        entries += [
            Entry(TrackerStage.declare(team, topics), "", functools.partial(_tracker, team, settings, topics)),
            Entry(TeamStage.declare(team, referee_topic), "",
                  functools.partial(_team, team, settings, referee_topic)),
            Entry(CommandsOutStage.declare(p, team, chip, teleports=sends), "",
                  functools.partial(CommandsOutStage, p, team, chip, teleports=sends, pitch=pitch)),
        ]  # fmt: skip
    if p.simulation.robot_count.keep:  # the league's simulation controller's part: robots over the count out
        world = f"world/{teams[0]}"
        entries.append(Entry(RobotCountStage.declare(world, referee_topic), "", functools.partial(
            RobotCountStage, p, RobotCount(pitch, p.simulation.robot_count), world, referee_topic)))
        if p.tracker.send and k == 0:
            entries.append(Entry(TrackerOutStage.declare(p, team), "", functools.partial(TrackerOutStage, p, team)))
    entries.append(Entry(TimingStage.contract, "", TimingStage))
    return entries


def _referee(settings: Settings, p: ProtocolParams, ours: Team, topics: Sequence[str],
             robots: Sequence[tuple[Team, int]]) -> tuple[list[Entry], str, bool]:
    """The referee's rows, the topic of its word and whether it teleports: a game controller's
    packets (``protocols.referee.source: game_controller``), else our referee on the tracked world
    (the autoref: its own tracker on every camera's packets ``topics``, judging the match's
    ``robots``), with its Referee packets out when ``protocols.referee.send``."""
    if p.referee.source == "game_controller":
        world_topic, moved_m = f"world/{ours}", settings.sim.referee.figures.ball_in_play_m
        return [Entry(RefereeInStage.declare(p, world_topic), "",
                      lambda: RefereeInStage(p, world_topic, moved_m))], "referee/gc", False
    rows = autoref_rows(settings, topics, robots)
    if p.referee.send:
        rows.append(Entry(RefereeOutStage.contract, "", functools.partial(RefereeOutStage, p)))
    return rows, "referee", settings.sim.referee.place_by == "teleport"


def _tracker(team: Team, settings: Settings, topics: Sequence[str]) -> Stage:
    from cmdragons.tracking import Tracker

    return TrackerStage(team, Tracker(settings.tracker), topics)


def _team(team: Team, settings: Settings, referee_topic: str) -> Stage:
    from cmdragons.team import Brain

    return TeamStage(team, Brain(team, settings), referee_topic)


class OutsideMatch:
    """Runs one match in an outside simulator, frame by frame as its vision comes.

    ``settings``: on the simulator's field (:func:`field_settings`); ``teams``: ours (one, or both
    for self-play); ``heard``: the cameras :func:`listen` learnt, on ``receiver``; ``extra``: more
    stages on the same bus (a logger, a video)."""

    def __init__(self, settings: Settings, kind: SimulatorKind, teams: Sequence[Team], heard: Heard, receiver: Any,
                 extra: Sequence[Stage] = (), transport: Transport | None = None) -> None:
        if kind is SimulatorKind.OWN:
            raise ValueError("our own simulator plays in cmdragons.runtime.match.Match")
        self.settings = settings
        self.kind = kind
        self.teams = tuple(teams)
        self.heard = heard
        self.gate = FrameGate(receiver)
        self.bus = Bus(transport)
        self._summaries = SummaryCollector()
        self.t0: float | None = None  # the first world state's capture time (s, the simulator's clock)
        self.t = math.nan  # the newest
        self.frames_waited_out = 0  # frames whose vision did not come within the wait
        table = outside_wiring(settings, kind, teams, heard.cameras, self.gate, heard.robots)
        self.table = table
        watch = Tap("outside/clock", (f"world/{teams[0]}",), self._world)
        for stage in build(table, [*extra, watch, self._summaries]):
            self.bus.add(stage)
        self.frames = 0  # the frame loop's turns (each when vision came)
        self.worlds = 0  # our (first) team's world states: the simulator's vision frames we played on
        self.stage_ms: dict[str, list[float]] = {}
        self.bus.start()

    def skip_stale(self) -> int:
        """Drop the vision packets that came before now (while the match was being built); how many."""
        n = len(self.gate.drain())
        self.gate.skipped = 0
        return n

    def _world(self, _topic: str, world: WorldState) -> None:
        self.t0 = world.t if self.t0 is None else self.t0
        self.t = world.t
        self.worlds += 1

    @property
    def frames_behind(self) -> int:
        """The simulator's vision frames passed over: they came while we were busy with an earlier one."""
        return self.gate.skipped

    @property
    def seconds(self) -> float:
        """Match time so far (s): vision's capture time since the first frame."""
        return 0.0 if self.t0 is None else self.t - self.t0

    def step(self) -> bool:
        """One frame: wait (up to ``protocols.outside.frame_wait_s``) for the simulator's vision, then
        see, decide and send; False when no vision came."""
        if not self.gate.wait(self.settings.protocols.outside.frame_wait_s):
            self.frames_waited_out += 1
            return False
        t0 = time.perf_counter()
        self.bus.tick(self.frames)
        frame_ms = (time.perf_counter() - t0) * 1e3
        self.frames += 1
        times = self.bus.take_times()
        timings = _timings(self.teams[0], self.teams)
        for name, keys in timings.items():
            self.stage_ms.setdefault(name, []).append(sum(times.get(k, 0.0) for k in keys))
        # the rest: the log, the viewers, the summaries
        known = {k for keys in timings.values() for k in keys} | {"timing"}
        rest = sum(times.get(s.name, 0.0) for s in self.bus.stages if s.name not in known)
        self.stage_ms.setdefault("log_and_viewers", []).append(rest)
        self.stage_ms.setdefault("frame", []).append(frame_ms)
        return True

    def run(self, seconds: float, should_stop: Callable[[], bool] = lambda: False,
            on_frame: Callable[[int], None] | None = None) -> dict[str, Any]:
        """Frames until ``seconds`` of match time passed (or ``should_stop``, or the simulator fell
        silent for ``frame_wait_s``); the summary."""
        while self.seconds < seconds and not should_stop():
            if not self.step():
                break
            if on_frame is not None:
                on_frame(self.frames - 1)
        return self.summary()

    def summary(self) -> dict[str, Any]:
        self.bus.summarize()
        return outside_summary(self._summaries.figures, self.stage_ms, self)

    def close(self) -> None:
        close_sockets(self.bus.stages)


def _timings(ours: Team, teams: Sequence[Team]) -> dict[str, tuple[str, ...]]:
    """The per-frame timings of the summary (bus timing keys summed into each): our perception
    (the vision packets received), our tracker, our brain, the commands sent, the referee (the
    autoref's tracker and rules) and, in self-play, the other colour's tracker and brain."""
    others = [t for t in teams if t != ours]
    return {"vision": ("ssl/vision_in",), "tracker": (f"tracker/{ours}",), "brain": (f"team/{ours}",),
            "commands": tuple(f"ssl/commands_out/{t}" for t in teams), "referee": ("tracker/autoref", "autoref"),
            **({"opponent_tracker": tuple(f"tracker/{t}" for t in others),
                "opponent_brain": tuple(f"team/{t}" for t in others)} if others else {})}


def outside_summary(f: dict[str, Any], stage_ms: dict[str, list[float]], match: OutsideMatch) -> dict[str, Any]:
    """summary.json's figures of a match in an outside simulator: what our stages saw (the score
    only as a referee of ours or a game controller told it)."""
    ours = match.teams[0]
    cycle = {k: {"median": float(np.median(v)), "p95": float(np.percentile(v, 95))}
             for k, v in stage_ms.items() if v}
    cycle.update(f.get("timing", {}).get(f"team/{ours}", {}))
    vision = f.get("ssl/vision_in", {})
    g = match.heard.geometry
    referee = f.get("autoref", {})  # our referee on the tracked world (none: a game controller's word)
    return {
        **({"score": referee["score"], "balls_out": referee["balls_out"], "kicks": referee["kicks_seen"],
            "rules": {k: referee[k] for k in ("rules", "game_stage", "fouls", "cards", "placements", "penalties",
                                              "shootout") if k in referee},
            # counted by our referee from the tracks: the collisions among each of our teams' robots
            "collisions": {"own": {t: referee["own_collisions"][t] for t in match.teams},
                           "each": [c for c in referee["own_collisions"]["each"] if c["team"] in match.teams]}}
           if referee else {}),
        "simulator": match.kind.value,
        "teams": list(match.teams),
        "seconds": round(match.seconds, 3),
        "frames": match.worlds,
        "loop_turns": match.frames,
        "frames_behind": match.frames_behind,
        "frames_waited_out": match.frames_waited_out,
        "cameras": list(match.heard.cameras),
        "field_m": [g.field_length_m, g.field_width_m],
        "field": dataclasses.asdict(match.settings.field.dims),  # the sizes played on (the geometry's)
        "division": match.settings.field.division,
        "cycle_ms": cycle,
        "tracker": {t: f.get(f"tracker/{t}", {}) for t in match.teams},
        "vision": vision,
        "protocols": {k: v for k, v in f.items() if k.startswith("ssl/")},
    }
