"""Tracker packets: our :class:`WorldState` <-> the league's ``TrackerWrapperPacket`` bytes.

The tracked frame inside is the wire's own mapping (:func:`cmdragons.runtime.wire.to_proto` of a
WorldState is the league's TrackedFrame already: metres, m/s, radians, the field frame); this
module adds the wrapper: the tracker's ``uuid`` (one per run) and its ``source_name``, and puts the
timestamp in Unix time (:mod:`cmdragons.runtime.ssl.clock`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from cmdragons.messages import WorldState
from cmdragons.runtime import wire
from cmdragons.runtime.proto import ssl_tracked_pb2 as trk_pb
from cmdragons.runtime.proto import ssl_tracker_wrapper_pb2 as tw_pb
from cmdragons.runtime.ssl.clock import UnixEpoch, run_epoch

__all__ = ["TrackerContents", "decode_tracker", "read_tracker", "tracker_packet"]


def tracker_packet(world: WorldState, uuid: str, source_name: str, epoch: UnixEpoch | None = None) -> bytes:
    """A ``TrackerWrapperPacket`` with ``world`` as its tracked frame, its timestamp in Unix time
    (``epoch``, by default the run's)."""
    m = tw_pb.TrackerWrapperPacket(uuid=uuid, source_name=source_name)
    m.tracked_frame.CopyFrom(wire.to_proto(world))
    m.tracked_frame.timestamp = (run_epoch() if epoch is None else epoch).to_unix(world.t)
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


@dataclass(frozen=True)
class TrackerContents:
    """A TrackerWrapperPacket read: its uuid, source name, world state (None: no tracked frame) and
    the robots left out for a team neither blue nor yellow (the league's UNKNOWN)."""

    uuid: str
    source_name: str
    world: WorldState | None
    unknown_team: int = 0


def read_tracker(data: bytes, epoch: UnixEpoch | None = None) -> TrackerContents:
    """A ``TrackerWrapperPacket``'s bytes read, the world state in match time (the timestamp less
    ``epoch``, by default the run's); :class:`MessageError` for bytes that are not one. A robot of
    no known team is left out and counted, the rest of the packet kept."""
    m = wire.parse(tw_pb.TrackerWrapperPacket, data)
    if not m.HasField("tracked_frame"):
        return TrackerContents(m.uuid, m.source_name, None)
    f = m.tracked_frame
    known = [r for r in f.robots if r.robot_id.team in (trk_pb.BLUE, trk_pb.YELLOW)]
    unknown = len(f.robots) - len(known)
    if unknown:
        del f.robots[:]
        f.robots.extend(known)
    e = run_epoch() if epoch is None else epoch
    world = dataclasses.replace(wire.from_proto(f), t=e.to_match(f.timestamp))
    return TrackerContents(m.uuid, m.source_name, world, unknown)


def decode_tracker(data: bytes, epoch: UnixEpoch | None = None) -> tuple[str, str, WorldState | None]:
    """:func:`read_tracker`'s uuid, source name and world state."""
    got = read_tracker(data, epoch)
    return got.uuid, got.source_name, got.world
