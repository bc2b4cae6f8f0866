"""Tracker packets: our :class:`WorldState` <-> the league's ``TrackerWrapperPacket`` bytes.

The tracked frame inside is the wire's own mapping (:func:`cmdragons.runtime.wire.to_proto` of a
WorldState is the league's TrackedFrame already: metres, m/s, radians, the field frame; the
timestamp is our clock's seconds); this module adds the wrapper: the tracker's ``uuid`` (one per
run) and its ``source_name``.
"""

from __future__ import annotations

from cmdragons.messages import WorldState
from cmdragons.runtime import wire
from cmdragons.runtime.proto import ssl_tracker_wrapper_pb2 as tw_pb

__all__ = ["decode_tracker", "tracker_packet"]


def tracker_packet(world: WorldState, uuid: str, source_name: str) -> bytes:
    """A ``TrackerWrapperPacket`` with ``world`` as its tracked frame."""
    m = tw_pb.TrackerWrapperPacket(uuid=uuid, source_name=source_name)
    m.tracked_frame.CopyFrom(wire.to_proto(world))
    return m.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def decode_tracker(data: bytes) -> tuple[str, str, WorldState | None]:
    """The uuid, source name and world state of a ``TrackerWrapperPacket``'s bytes (the state None
    when it has no tracked frame); :class:`MessageError` for bytes that are not one."""
    m = wire.parse(tw_pb.TrackerWrapperPacket, data)
    world = wire.from_proto(m.tracked_frame) if m.HasField("tracked_frame") else None
    return m.uuid, m.source_name, world
