"""The referee's calls alone: the match's and the frame's, counted by foul."""

from __future__ import annotations

from cmdragons.messages import GameEvent
from sim.calls import Calls


def test_a_frame_holds_its_own_calls_and_the_match_all() -> None:
    calls = Calls()
    first = [GameEvent(0.1, "crash", "blue", 1), GameEvent(0.1, "stop_speed", "yellow", 2)]
    for e in first:
        calls.call(e)
    assert calls.new == first and calls.all == first
    calls.next_frame()
    assert calls.new == [] and calls.all == first
    late = GameEvent(0.2, "crash", "blue", 3)
    calls.call(late)
    assert calls.new == [late] and calls.all == [*first, late]


def test_calls_are_counted_per_team_by_the_kinds_asked_for_in_name_order() -> None:
    calls = Calls()
    for kind, team in (("pushing", "blue"), ("crash", "blue"), ("pushing", "blue"), ("crash", "yellow"),
                       ("yellow_card", "blue"), ("stage_half_time", None)):
        calls.call(GameEvent(0.0, kind, team))  # type: ignore[arg-type]
    counted = calls.by_kind({"crash", "pushing"})
    assert counted == {"blue": {"crash": 1, "pushing": 2}, "yellow": {"crash": 1}}
    assert list(counted["blue"]) == ["crash", "pushing"]
