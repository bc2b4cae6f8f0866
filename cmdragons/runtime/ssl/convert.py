"""Between the league's log files and our MCAP logs.

League -> MCAP: each SSL-Vision packet's detections as ``/ssl/vision/<camera id>`` (metres), each
Referee packet as ``/referee/gc`` (our GameState), at the packets' receive times; other records
(tracker packets, the 2010 vision format, unknown types) are counted and left out.
MCAP -> league: our ``/detections/<id>`` as SSL-Vision packets, ``/referee`` as Referee packets, at
the messages' own times (a match's simulated clock, from 0).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from cmdragons.messages import DetectionFrame, GameState, MessageError
from cmdragons.runtime.log import RunLog, read_log
from cmdragons.runtime.ssl.logfile import LogReader, LogRecord, MessageType, write_log
from cmdragons.runtime.ssl.referee import RefereeReader, referee_packet
from cmdragons.runtime.ssl.vision import decode_wrapper, detection_packet
from cmdragons.runtime.topics import topic_matches

__all__ = ["is_league_log", "league_to_mcap", "mcap_to_league"]


def is_league_log(path: str | Path) -> bool:
    """A league log by its name: ``.log`` or ``.log.gz``."""
    name = Path(path).name
    return name.endswith(".log") or name.endswith(".log.gz")


def league_to_mcap(source: str | Path, out: str | Path) -> tuple[dict[str, int], str | None]:
    """Convert; the counts written and left out by kind, and the truncation note (None: whole)."""
    reader = LogReader(source)
    referee = RefereeReader()
    counts: dict[str, int] = {}
    with RunLog(out) as log:
        for r in reader:
            t = r.receive_time_ns / 1e9
            kind = "left out"
            try:
                if r.type == MessageType.VISION_2014:
                    det, _ = decode_wrapper(r.payload)
                    if det is not None:
                        log.write(f"/ssl/vision/{det.camera_id}", t, det)
                        kind = "detections"
                    else:
                        kind = "geometry"
                elif r.type == MessageType.REFBOX_2013:
                    log.write("/referee/gc", t, referee.read(r.payload))
                    kind = "referee"
            except MessageError:
                kind = "undecodable"
            counts[kind] = counts.get(kind, 0) + 1
    return counts, reader.truncated


def _records(source: str | Path) -> Iterator[LogRecord]:
    for topic, t, m in read_log(source):
        ns = round(t * 1e9)
        if topic_matches("/detections/*", topic) and isinstance(m, DetectionFrame):
            yield LogRecord(ns, MessageType.VISION_2014, detection_packet(m))
        elif topic == "/referee" and isinstance(m, GameState):
            yield LogRecord(ns, MessageType.REFBOX_2013, referee_packet(m))


def mcap_to_league(source: str | Path, out: str | Path) -> int:
    """Convert; the number of records written."""
    return write_log(out, _records(source))
