"""configs/runtime.yaml: the distributed runtime (zenoh session, key space, lock-step, faults)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from cmdragons.config import Validated, setting

__all__ = ["ROLES", "RuntimeParams", "ZenohParams"]

# the nodes of a distributed match (cmdragons/runtime/distributed.py says what each runs)
ROLES = ("sim", "vision", "team", "opponent", "referee", "log")

_LOOPBACK = "tcp/127.0.0.1:"


@dataclass(frozen=True)
class ZenohParams(Validated):
    """One node's zenoh session. The default keeps every packet on this machine: a router on
    127.0.0.1 that the nodes connect to, no multicast scouting, no gossip. For a real network set
    ``router`` to the router machine's endpoint and ``network: true``."""

    router: str = setting("tcp/127.0.0.1:7447")  # the endpoint the router listens on and the nodes connect to
    network: bool = False  # allow endpoints off this machine (then router may name another host)
    multicast_scouting: bool = False  # UDP multicast discovery of peers: off, the router is named
    shared_memory: bool = True  # same-host payloads over shm_min_bytes go through zenoh's shared memory
    shm_min_bytes: int = setting(65536, lo=0, hi=2**31)  # smaller payloads are copied (cheaper than a buffer)
    shm_pool_mb: int = setting(64, lo=1, hi=4096)  # each publishing node's shared-memory pool

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.router.startswith("tcp/"):
            raise ValueError(f"router must be a tcp/<host>:<port> endpoint, got {self.router!r}")
        if not self.network and not self.router.startswith(_LOOPBACK):
            raise ValueError(f"router {self.router!r} is off this machine: set network: true to allow it")

    def session(self, role: str) -> dict[str, Any]:
        """The zenoh config of a ``role`` ("router" or "client") session, as JSON values."""
        endpoints = {"listen": {"endpoints": [self.router] if role == "router" else []},
                     "connect": {"endpoints": [] if role == "router" else [self.router]}}
        return {"mode": role, **endpoints,
                "scouting": {"multicast": {"enabled": self.multicast_scouting}, "gossip": {"enabled": False}},
                "transport": {"shared_memory": {"enabled": self.shared_memory}}}

    def config(self, role: str) -> Any:
        """A ``zenoh.Config`` for a ``role`` session (never a bare default, which listens everywhere)."""
        import zenoh

        return zenoh.Config.from_json5(json.dumps(self.session(role)))


@dataclass(frozen=True)
class RuntimeParams(Validated):
    field_name: str = setting("main")  # <field> of the key space cmdragons/<field>/...
    zenoh: ZenohParams = ZenohParams()
    lockstep_wait_s: float = setting(2.0, lo=0.01, hi=600.0)  # lock-step: a team silent this long is stepped without
    peer_timeout_s: float = setting(5.0, lo=0.1, hi=600.0)  # a node that heard nothing this long says so
    drop_report_interval_s: float = setting(1.0, lo=0.01, hi=60.0)  # undecodable messages: one line at most this often
    start_timeout_s: float = setting(60.0, lo=1.0, hi=3600.0)  # the match starts once every node is up, or gives up
    settle_s: float = setting(0.5, lo=0.0, hi=60.0)  # every node up: subscriptions reach every publisher in this
    rehearsal_frames: int = setting(12, lo=0, hi=600)  # frames of a throwaway match a node plays before it is ready
    vision_with_sim: bool = False  # vision (or the truth perception) runs in the sim node; camera frames stay there
    realtime_priority: int = setting(0, lo=0, hi=99)  # the frame path's nodes (sim, vision, team) on the real-time
    # scheduler (SCHED_FIFO at this priority) so that other work on the host waits for them; 0: the normal scheduler
    cpu_latency_us: int = setting(-1, lo=-1, hi=1_000_000)  # >= 0: while a frame path node runs, the host's CPUs
    # stay out of idle states slower to wake than this (µs; Linux PM QoS, /dev/cpu_dma_latency; 0: an idle CPU
    # polls, at the cost of its power); -1: the kernel's choice

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.field_name or any(c in self.field_name for c in "/*$?#"):
            raise ValueError(f"field_name must be one key chunk (no / * $ ? #), got {self.field_name!r}")
