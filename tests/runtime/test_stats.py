"""A team's match statistics: own collisions counted apart from those an opponent pushed into."""

from __future__ import annotations

from typing import Any

from cmdragons.messages import Contact, SimEvents
from cmdragons.runtime.pass_record import PassRecorder
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.stages import StatsStage


def test_own_collisions_are_told_from_those_an_opponent_pushed_into() -> None:
    stats = StatsStage("blue", PassRecorder.of("blue", load_settings()))
    events = (
        Contact(1.0, 0.1, ("blue", 1), ("blue", 2), 0.001, 0.4),  # ours drove into each other
        Contact(2.0, 0.1, ("blue", 1), ("blue", 3), 0.001, 0.6, pushed_by=("yellow", 4)),  # pushed
        Contact(3.0, 0.1, ("blue", 1), ("yellow", 4), 0.002, 1.7),  # with an opponent
        Contact(4.0, 0.1, ("yellow", 1), ("yellow", 2), 0.001, 0.5),  # theirs among themselves
    )
    stats.on_message("events", SimEvents(1, 4.1, (0.0, 0.0), events), lambda *_: None)
    out: list[Any] = []
    stats.summarize(lambda topic, m: out.append(m))
    assert out[0].figures["collisions"] == {"own": 1, "own_pushed": 1, "opponent": 1}
