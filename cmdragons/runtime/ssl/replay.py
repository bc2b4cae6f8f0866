"""A league log (SSL_LOG_FILE) into our tracker and brain: ``cmdragons replay match.log.gz``.

The log's records are the clock: each SSL-Vision packet goes to the same receiving stage that
reads them from the network (:class:`~cmdragons.runtime.ssl.stages.VisionInStage`, fed from a
queue instead of a socket: garbage, unknown cameras and duplicates are counted and dropped the
same way), and each Referee packet to the same game-controller stage
(:class:`~cmdragons.runtime.ssl.stages.RefereeInStage`, ``referee/gc``). Our tracker steps once
every camera in the log has delivered a frame (a newer frame closes the one in progress: cameras
with counters of their own step it one by one), and our brain plays on its world states and the
game controller's word, as fast as they come, on the field of the log's geometry packets (the
config's when it has none); the log's Unix times are match time from its first record's second. The
brain's commands go nowhere but the run's log, and into the tracker (as the robots' control
input) only for a log of our own match (``own``). Tracker packets, the 2010 vision format and
unknown record types are counted and left out. A log cut off mid-record replays up to its last
whole record.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cmdragons.geometry import Team
from cmdragons.messages import MessageError
from cmdragons.runtime.bus import Bus, Stage
from cmdragons.runtime.match import Entry, build
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.logfile import LogReader, MessageType
from cmdragons.runtime.ssl.stages import RefereeInStage, VisionInStage
from cmdragons.runtime.ssl.udp import DatagramQueue
from cmdragons.runtime.ssl.vision import VisionGeometry, decode_wrapper, settings_on_geometry
from cmdragons.runtime.stages import SummaryCollector, TeamStage, TrackerStage

__all__ = ["LeagueReplay", "LogScan", "camera_ids", "league_replay_wiring", "replay_league_log", "scan_log"]


@dataclass
class LeagueReplay:
    """What a league log's replay did: records by kind, the truncation note, the stages' figures."""

    records: dict[str, int] = field(default_factory=dict)
    cameras: list[int] = field(default_factory=list)
    truncated: str | None = None
    first_ns: int | None = None
    last_ns: int | None = None
    interrupted: bool = False
    figures: dict[str, Any] = field(default_factory=dict)
    field_m: tuple[float, float] = (0.0, 0.0)  # the field played on: length, width
    field_from: str = "config"  # "log": its geometry packets; "config (why)": the log's geometry refused


@dataclass(frozen=True)
class LogScan:
    """What a league log holds before it is played: its cameras, its first geometry packet's
    contents (None: none), and the epoch of its times (its first record's whole second)."""

    cameras: list[int]
    geometry: VisionGeometry | None
    epoch: UnixEpoch


def scan_log(path: str | Path) -> LogScan:
    """One pass over a league log's SSL-Vision records (undecodable packets passed over)."""
    ids: set[int] = set()
    geometry: VisionGeometry | None = None
    first_ns: int | None = None
    for r in LogReader(path):
        first_ns = r.receive_time_ns if first_ns is None else first_ns
        if r.type == MessageType.VISION_2014:
            try:
                det, geo = decode_wrapper(r.payload)
            except MessageError:
                continue
            if det is not None:
                ids.add(det.camera_id)
            if geometry is None and geo is not None:
                geometry = geo
    return LogScan(sorted(ids), geometry, UnixEpoch.of_first(0.0 if first_ns is None else first_ns / 1e9))


def camera_ids(path: str | Path) -> list[int]:
    """The camera ids of a league log's detection packets (undecodable packets passed over)."""
    return scan_log(path).cameras


def league_replay_wiring(settings: Settings, team: Team, cameras: Sequence[int], own: bool, vision: DatagramQueue,
                         referee: DatagramQueue, epoch: UnixEpoch | None = None) -> list[Entry]:
    """The table of a league log's replay: the log's SSL-Vision packets (``cameras``) and Referee
    packets, fed from the queues ``vision`` and ``referee``, into the receiving stages that read
    them from the network (their Unix times less ``epoch``, by default the run's; a log of our own
    match, ``own``, gives its capture times in match time exactly); ``team``'s tracker on them
    (taking the brain's commands for ``own``) and its brain on the game controller's word."""
    p = settings.protocols
    world_topic = f"world/{team}"
    topics = [f"ssl/vision/{c}" for c in cameras]
    moved_m = settings.sim.referee.figures.ball_in_play_m
    return [
        Entry(VisionInStage.declare(p, cameras, False), "",
              lambda: VisionInStage(p, cameras, lockstep=False, receiver=vision, epoch=epoch, camera_clock=own)),
        Entry(RefereeInStage.declare(p, world_topic), "",
              lambda: RefereeInStage(p, world_topic, moved_m, receiver=referee, epoch=epoch)),
        Entry(TrackerStage.declare(team, topics, own), "",
              lambda: TrackerStage(team, _tracker(settings), topics, take_commands=own)),
        Entry(TeamStage.declare(team, "referee/gc"), "", lambda: TeamStage(team, _brain(team, settings), "referee/gc")),
    ]  # fmt: skip


def replay_league_log(path: str | Path, settings: Settings, team: Team = "blue", extra: tuple[Stage, ...] = (),
                      own: bool = False, should_stop: Callable[[], bool] = lambda: False,
                      on_record: Callable[[int, int], None] | None = None) -> LeagueReplay:
    """Play the league log at ``path`` into ``team``'s tracker and brain (``settings``); ``extra``:
    more stages on the bus (a logger). ``own``: the log is of a match our team played (with these
    settings): the tracker takes the brain's commands as the robots' control input, as it did in
    the match; else it follows the robots by their detections alone (a real match's robots did not
    follow our brain). The field is the log's (its first geometry packet's), else the config's.
    ``on_record(receive_time_ns, n)`` after each record."""
    scan = scan_log(path)
    out = LeagueReplay(cameras=scan.cameras)
    if scan.geometry is not None:
        try:
            settings = settings_on_geometry(settings, scan.geometry)
            out.field_from = "log"
        except MessageError as exc:
            out.field_from = f"config ({exc})"
    d = settings.field.dims
    out.field_m = (d.length_m, d.width_m)
    vision_q, referee_q = DatagramQueue(), DatagramQueue()
    summaries = SummaryCollector()
    bus = Bus()
    table = league_replay_wiring(settings, team, out.cameras, own, vision_q, referee_q, scan.epoch)
    for stage in build(table, [*extra, summaries]):
        bus.add(stage)
    bus.start()
    reader = LogReader(path)
    n = 0
    for r in reader:
        if should_stop():
            out.interrupted = True
            break
        kind = MessageType(r.type).name if r.type in MessageType._value2member_map_ else f"type {r.type}"
        out.records[kind] = out.records.get(kind, 0) + 1
        out.first_ns = r.receive_time_ns if out.first_ns is None else out.first_ns
        out.last_ns = r.receive_time_ns
        queue = {MessageType.VISION_2014: vision_q, MessageType.REFBOX_2013: referee_q}.get(r.type)  # type: ignore[call-overload]
        if queue is not None:
            queue.push(r.payload)
            bus.tick(n)
        n += 1
        if on_record is not None:
            on_record(r.receive_time_ns, n)
    out.truncated = reader.truncated
    bus.summarize()
    out.figures = summaries.figures
    return out


def _tracker(settings: Settings) -> Any:
    from cmdragons.tracking import Tracker

    return Tracker(settings.tracker)


def _brain(team: Team, settings: Settings) -> Any:
    from cmdragons.team import Brain

    return Brain(team, settings)
