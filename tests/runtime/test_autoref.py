"""The autoref's rows: they fit a match's table (driving it in place of the simulator's referee, or
watching beside it), and in a short match through the cameras the passive autoref makes the truth
referee's calls."""

from __future__ import annotations

import dataclasses

import pytest

from cmdragons.bench.autoref import OWN_COLLISION, WINDOW_S, Call, match_calls, missed, rows, watch
from cmdragons.messages import Teleport
from cmdragons.runtime.autoref import PASSIVE, WORLD, autoref_rows
from cmdragons.runtime.match import CLOCK, match_sim_params, wiring
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.topics import Port, check_wiring
from sim.params import robot_keys


def _table(passive: bool, place_by: str = "teleport") -> list[str]:
    s = load_settings()
    s = dataclasses.replace(s, sim=dataclasses.replace(s.sim, referee=dataclasses.replace(s.sim.referee,
                                                                                          place_by=place_by)))
    cams = [f"detections/{m.id}" for m in s.camera_models()]
    keys = robot_keys(s.field, match_sim_params(s, "simple"))
    table = wiring(s, "simple", "vision", 1, lambda: None)  # type: ignore[arg-type,return-value]
    if not passive:  # the autoref in place of the simulator's referee
        table = [e for e in table if e.contract.name != "referee"]
    extra = autoref_rows(s, cams, keys, passive=passive)
    # (placed by robots nothing asks our simulator for a teleport: a simulator outside reads none)
    outside = (*CLOCK, Port("teleport", Teleport)) if place_by == "robots" else CLOCK
    check_wiring([e.contract for e in [*table, *extra]], outside)
    return [p.topic for e in extra for p in e.contract.writes]


@pytest.mark.parametrize(("passive", "place_by", "written"), [
    (True, "teleport", {WORLD, PASSIVE + "referee", PASSIVE + "referee/events", PASSIVE + "teleport"}),
    (False, "teleport", {WORLD, "referee", "referee/events", "teleport"}),
    (False, "robots", {WORLD, "referee", "referee/events"}),
])
def test_the_autoref_rows_fit_a_match_table(passive: bool, place_by: str, written: set[str]) -> None:
    # (its tracker also says what it measured of the physics, as every tracker does)
    assert {t for t in _table(passive, place_by) if not t.startswith("summary/")} == written | {"physics/autoref"}


def test_a_game_controller_referees_in_place_of_the_autoref() -> None:
    s = load_settings(overrides=["protocols.referee.source=game_controller"])
    keys = robot_keys(s.field, match_sim_params(s, "simple"))
    assert autoref_rows(s, ["detections/0"], keys) == []
    assert len(autoref_rows(s, ["detections/0"], keys, passive=True)) == 2  # watching still


def test_calls_pair_by_kind_team_and_window() -> None:
    truth = [Call(1.0, "goal", "blue"), Call(5.0, "crash", "yellow"), Call(9.0, "ball_out", "blue")]
    seen = [Call(1.1, "goal", "blue"), Call(5.0, "crash", "blue"), Call(9.0 + WINDOW_S + 0.1, "ball_out", "blue"),
            Call(12.0, "pushing", "blue")]
    assert match_calls(truth, seen) == [(truth[0], seen[0])]
    table = {r["name"]: r for r in rows(truth, seen)}
    assert table["goal"]["matched_share"] == 1.0
    assert table["all"]["matched"] == 1 and table["all"]["own_calls"] == 3


def test_each_missed_call_is_named_with_what_the_autoref_called_instead() -> None:
    """A ball out given to the wrong side: missed, and the autoref's call of that kind beside it; the
    same call in another match is no pair; own collisions are a row of their own, in no group."""
    truth = [Call(9.0, "ball_out", "blue", seed=2), Call(3.0, "goal", "yellow", seed=1),
             Call(4.0, "own_collision", "yellow", seed=1)]
    seen = [Call(9.1, "ball_out", "yellow", seed=2), Call(3.0, "goal", "yellow", seed=3),
            Call(4.2, "own_collision", "yellow", seed=1)]
    assert missed(truth, seen) == ["seed 1 3.00 s goal yellow (autoref's: none)",
                                   "seed 2 9.00 s ball_out blue (autoref's: yellow at +0.10 s)"]
    table = {r["name"]: r for r in rows(truth, seen)}
    assert table["ball_out"]["missed"] == "seed 2 9.00 s ball_out blue (autoref's: yellow at +0.10 s)"
    assert table["goals_and_outs"]["truth_calls"] == 2 and table["all"]["truth_calls"] == 2
    assert table["own_collision"]["matched"] == 1 and table["own_collision"]["own_calls"] == 0


@pytest.mark.slow
def test_the_passive_autoref_makes_the_truth_referees_calls_in_a_match_through_the_cameras() -> None:
    """Seed 1, 10 s, our team through the cameras against the simple opponent, the truth referee
    driving: every call of it (a crash) the autoref makes too within the window, and none of its
    own."""
    truth, seen = (
        [c for c in calls if c.kind != OWN_COLLISION] for calls in watch(load_settings(), 1, 10.0))  # calls only
    assert truth, "the match has calls to compare"
    pairs = match_calls(truth, seen)
    assert len(pairs) == len(truth)
    assert len(seen) == len(pairs)
