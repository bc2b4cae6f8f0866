"""Time on the league's wire: SSL-Vision's ``t_capture`` and ``t_sent``, the tracker's
``timestamp``, the game controller's ``packet_timestamp`` and ``command_timestamp`` and the league
log's receive times are Unix time; our own messages carry match time (seconds from the match's
start). One :class:`UnixEpoch` a run, the Unix time of match time 0 in whole seconds, turns one into
the other: packets out add it, packets in take it off. Whole seconds keep the referee's and the
log's integer microseconds and nanoseconds exact both ways.

Precision: a Unix time in a double is good to about 0.24 µs, so a match time read back from a
packet is that close to the one sent, not equal to the bit; SSL-Vision packets of ours carry the
match time exactly in ``t_capture_camera`` (the league's field for the camera's own clock, which
for our simulated cameras is the match clock), read where the packets are known to be ours.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass

__all__ = ["UnixEpoch", "run_epoch"]

_US = 1_000_000
_NS = 1_000_000_000


@dataclass(frozen=True)
class UnixEpoch:
    """Match time <-> Unix time: ``unix_s = match_s + epoch_s`` (a sender whose clock counts from
    its own start, grSim's simulation time: its time for Unix time)."""

    epoch_s: int = 0  # whole seconds: the Unix time of match time 0

    def to_unix(self, match_s: float) -> float:
        return match_s + self.epoch_s

    def to_match(self, unix_s: float) -> float:
        return unix_s - self.epoch_s

    def to_unix_us(self, match_s: float) -> int:
        """Unix microseconds (the game controller's unit) of a match time."""
        return round(match_s * _US) + self.epoch_s * _US

    def from_unix_us(self, unix_us: int) -> float:
        return (unix_us - self.epoch_s * _US) / _US

    def to_unix_ns(self, match_s: float) -> int:
        """Unix nanoseconds (the league log's receive times) of a match time."""
        return round(match_s * _NS) + self.epoch_s * _NS

    def from_unix_ns(self, unix_ns: int) -> float:
        return (unix_ns - self.epoch_s * _NS) / _NS

    @staticmethod
    def of_first(t_s: float) -> UnixEpoch:
        """The epoch that makes a sender's first time ``t_s`` (s) the start of match time: its
        whole second, Unix time or a clock that counts from the sender's own start (grSim's
        simulation time: how long grSim ran before the match began is no match time)."""
        return UnixEpoch(math.floor(t_s))


@functools.cache
def run_epoch() -> UnixEpoch:
    """This run's epoch: the wall clock's whole second when first asked, the same after."""
    return UnixEpoch(math.floor(time.time()))
