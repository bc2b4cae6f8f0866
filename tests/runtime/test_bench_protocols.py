"""`cmdragons bench protocols`: every kind of packet crosses loopback whole and decodes, none lost."""

from __future__ import annotations

from cmdragons.bench import SUITES
from cmdragons.bench.protocols import _packet_rows
from cmdragons.runtime.settings import load_settings


def test_every_kind_of_packet_crosses_loopback_and_none_is_lost() -> None:
    assert "protocols" in SUITES
    rows = _packet_rows(load_settings(), 256)
    names = [r["name"] for r in rows]
    assert names == ["ssl_vision_detections_2_cameras", "ssl_vision_geometry", "tracker_packet", "referee",
                     "grsim_commands", "robot_control", "simulator_command"]
    for r in rows:
        assert r["packets"] == 256 and r["lost"] == 0 and r["packets_per_s"] > 0 and r["bytes"] > 0, r
