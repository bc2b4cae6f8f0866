"""The robox bench's crossing: the same seed gives the same scene and the same run, and the Robox
settings change only the planner, the navigator and (on request) safety."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from cmdragons.bench.robox import crossing, robox_settings
from cmdragons.runtime.settings import load_settings

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


def test_the_robox_settings_change_the_planner_and_the_navigator_only() -> None:
    s = load_settings(CONFIGS)
    r = robox_settings(s)
    assert (r.planner.planner, r.team.navigator, r.safety.method) == ("estar", "robox", s.safety.method)
    assert dataclasses.replace(r, team=s.team, planner=s.planner) == s
    assert robox_settings(s, safety=False).safety.method == "none"


@pytest.mark.slow
def test_a_crossing_is_the_same_for_the_same_seed() -> None:
    # the deadlines are the safety net of a stalled machine (a first call compiling, a loaded CI
    # box): raised out of reach, only the work budgets bound each frame, as the property needs
    stalls = ["team.brain.navigate_deadline_ms=10000", "planner.deadline_ms=10000"]
    s = robox_settings(load_settings(CONFIGS, stalls))
    a, b = crossing(s, 3), crossing(s, 3)
    assert (a.contacts, a.time_s, a.min_clearance_m) == (b.contacts, b.time_s, b.min_clearance_m)
    assert a.time_s > 0.0  # it arrives
