"""Between the league's log files and our MCAP logs.

League -> MCAP: each SSL-Vision packet's detections as ``/ssl/vision/<camera id>`` (metres), each
Referee packet as ``/referee/gc`` (our GameState), at the packets' receive times; the log's Unix
times become match time from its first record's whole second. Other records (tracker packets, the
2010 vision format, unknown types) are counted and left out.
MCAP -> league: our ``/detections/<id>`` as SSL-Vision packets, ``/referee`` as Referee packets, at
the messages' own times in Unix time (the run's epoch: match time 0 is when the conversion
started), and a geometry packet (the settings' field and cameras) first and then every
``protocols.vision.geometry_interval_s`` of log time, as SSL-Vision sends it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

from cmdragons.messages import DetectionFrame, GameState, MessageError
from cmdragons.runtime.log import RunLog, read_log
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.ssl.clock import UnixEpoch, run_epoch
from cmdragons.runtime.ssl.logfile import LogReader, LogRecord, MessageType, write_log
from cmdragons.runtime.ssl.referee import RefereeReader, referee_packet
from cmdragons.runtime.ssl.vision import decode_wrapper, detection_packet, geometry_packet
from cmdragons.runtime.topics import topic_matches

__all__ = ["is_league_log", "league_to_mcap", "mcap_to_league"]


def is_league_log(path: str | Path) -> bool:
    """A league log by its name: ``.log`` or ``.log.gz``."""
    name = Path(path).name
    return name.endswith(".log") or name.endswith(".log.gz")


def league_to_mcap(source: str | Path, out: str | Path) -> tuple[dict[str, int], str | None]:
    """Convert; the counts written and left out by kind, and the truncation note (None: whole)."""
    reader = LogReader(source)
    epoch: UnixEpoch | None = None
    referee = RefereeReader()
    counts: dict[str, int] = {}
    with RunLog(out) as log:
        for r in reader:
            if epoch is None:
                epoch = UnixEpoch.of_first(r.receive_time_ns / 1e9)
                referee = RefereeReader(epoch)
            t = epoch.from_unix_ns(r.receive_time_ns)
            kind = "left out"
            try:
                if r.type == MessageType.VISION_2014:
                    det, _ = decode_wrapper(r.payload, epoch)
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


def _records(source: str | Path, geometry: bytes, interval_s: float, epoch: UnixEpoch) -> Iterator[LogRecord]:
    next_geometry = -math.inf
    for topic, t, m in read_log(source):
        ns = epoch.to_unix_ns(t)
        if topic_matches("/detections/*", topic) and isinstance(m, DetectionFrame):
            if t >= next_geometry:
                yield LogRecord(ns, MessageType.VISION_2014, geometry)
                next_geometry = t + interval_s
            yield LogRecord(ns, MessageType.VISION_2014, detection_packet(m, epoch))
        elif topic == "/referee" and isinstance(m, GameState):
            yield LogRecord(ns, MessageType.REFBOX_2013, referee_packet(m, epoch=epoch))


def mcap_to_league(source: str | Path, out: str | Path, settings: Settings, epoch: UnixEpoch | None = None) -> int:
    """Convert (the geometry packets of ``settings``' field and cameras: the match's config; Unix
    times by ``epoch``, by default the run's); the number of records written."""
    geometry = geometry_packet(settings.field_geometry(), settings.camera_models())
    e = run_epoch() if epoch is None else epoch
    return write_log(out, _records(source, geometry, settings.protocols.vision.geometry_interval_s, e))
