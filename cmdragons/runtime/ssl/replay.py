"""A league log (SSL_LOG_FILE) into our tracker and brain: ``cmdragons replay match.log.gz``.

The log's records are the clock: each SSL-Vision packet goes to the same receiving stage that
reads them from the network (:class:`~cmdragons.runtime.ssl.stages.VisionInStage`, fed from a
queue instead of a socket: garbage, unknown cameras and duplicates are counted and dropped the
same way), and each Referee packet to the same game-controller stage
(:class:`~cmdragons.runtime.ssl.stages.RefereeInStage`, ``referee/gc``). Our tracker steps once
every camera in the log has delivered a frame (a newer frame closes the one in progress: cameras
with counters of their own step it one by one), and our brain plays on its world states and the
game controller's word, as fast as they come (the log's own times stay in the messages). The
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
from cmdragons.runtime.ssl.logfile import LogReader, MessageType
from cmdragons.runtime.ssl.stages import RefereeInStage, VisionInStage
from cmdragons.runtime.ssl.udp import DatagramQueue
from cmdragons.runtime.ssl.vision import decode_wrapper
from cmdragons.runtime.stages import SummaryCollector, TeamStage, TrackerStage

__all__ = ["LeagueReplay", "camera_ids", "league_replay_wiring", "replay_league_log"]


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


def camera_ids(path: str | Path) -> list[int]:
    """The camera ids of a league log's detection packets (undecodable packets passed over)."""
    ids: set[int] = set()
    for r in LogReader(path):
        if r.type == MessageType.VISION_2014:
            try:
                det, _ = decode_wrapper(r.payload)
            except MessageError:
                continue
            if det is not None:
                ids.add(det.camera_id)
    return sorted(ids)


def league_replay_wiring(settings: Settings, team: Team, cameras: Sequence[int], own: bool, vision: DatagramQueue,
                         referee: DatagramQueue) -> list[Entry]:  # fmt: skip
    """The table of a league log's replay: the log's SSL-Vision packets (``cameras``) and Referee
    packets, fed from the queues ``vision`` and ``referee``, into the receiving stages that read
    them from the network; ``team``'s tracker on them (taking the brain's commands for a log of
    our own match, ``own``) and its brain on the game controller's word."""
    p = settings.protocols
    world_topic = f"world/{team}"
    topics = [f"ssl/vision/{c}" for c in cameras]
    moved_m = settings.sim.referee.figures.ball_in_play_m
    return [
        Entry(VisionInStage.declare(p, cameras, False), "",
              lambda: VisionInStage(p, cameras, lockstep=False, receiver=vision)),
        Entry(RefereeInStage.declare(p, world_topic), "",
              lambda: RefereeInStage(p, world_topic, moved_m, receiver=referee)),
        Entry(TrackerStage.declare(team, topics, own), "",
              lambda: TrackerStage(team, _tracker(settings), topics, take_commands=own)),
        Entry(TeamStage.declare(team, "referee/gc"), "", lambda: TeamStage(team, _brain(team, settings), "referee/gc")),
    ]  # fmt: skip


def replay_league_log(path: str | Path, settings: Settings, team: Team = "blue", extra: tuple[Stage, ...] = (),
                      own: bool = False, should_stop: Callable[[], bool] = lambda: False,
                      on_record: Callable[[int, int], None] | None = None) -> LeagueReplay:  # fmt: skip
    """Play the league log at ``path`` into ``team``'s tracker and brain (``settings``); ``extra``:
    more stages on the bus (a logger). ``own``: the log is of a match our team played (with these
    settings): the tracker takes the brain's commands as the robots' control input, as it did in
    the match; else it follows the robots by their detections alone (a real match's robots did not
    follow our brain). ``on_record(receive_time_ns, n)`` after each record."""
    out = LeagueReplay(cameras=camera_ids(path))
    vision_q, referee_q = DatagramQueue(), DatagramQueue()
    summaries = SummaryCollector()
    bus = Bus()
    for stage in build(league_replay_wiring(settings, team, out.cameras, own, vision_q, referee_q),
                       [*extra, summaries]):  # fmt: skip
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
