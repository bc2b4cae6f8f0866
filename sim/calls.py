"""The referee's calls: every :class:`~cmdragons.messages.GameEvent` of the match and those of the
current frame (what the referee publishes on ``referee/events``), and their count by foul."""

from __future__ import annotations

from cmdragons.geometry import TEAMS, Team
from cmdragons.messages import GameEvent

__all__ = ["Calls"]


class Calls:
    """The match's calls in order, and the current frame's."""

    def __init__(self) -> None:
        self.all: list[GameEvent] = []  # every call of the match
        self.new: list[GameEvent] = []  # the calls of the current frame

    def next_frame(self) -> None:
        """A new frame: no call in it yet."""
        self.new = []

    def call(self, event: GameEvent) -> None:
        self.all.append(event)
        self.new.append(event)

    def by_kind(self, kinds: frozenset[str] | set[str]) -> dict[Team, dict[str, int]]:
        """Per team, how many calls of each of ``kinds`` it committed (kinds sorted by name)."""
        out: dict[Team, dict[str, int]] = {t: {} for t in TEAMS}
        for e in self.all:
            if e.team is not None and e.kind in kinds:
                out[e.team][e.kind] = out[e.team].get(e.kind, 0) + 1
        return {t: dict(sorted(out[t].items())) for t in TEAMS}
