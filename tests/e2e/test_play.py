"""`cmdragons play`: matches in the simulator where our team sees only the rendered camera images."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cmdragons.cli import main
from cmdragons.runtime.match import Match
from cmdragons.runtime.settings import load_settings

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.mark.slow
def test_alone_on_the_field_the_team_scores() -> None:
    summary = Match(load_settings(CONFIGS), opponent="none", perception="vision", seed=1).run(30.0)
    assert summary["score"]["blue"] >= 1
    assert summary["collisions"]["own"] == 0


@pytest.mark.slow
def test_against_the_simple_opponent_runs_with_no_own_collision() -> None:
    # one test for the one match (two tests on a module fixture may run it once in each xdist worker)
    summary = Match(load_settings(CONFIGS), opponent="simple", perception="vision", seed=2).run(30.0)
    assert summary["seconds"] == pytest.approx(30.0)
    assert summary["command_faults"]["non_finite"] == 0
    assert summary["collisions"]["own"] == 0


@pytest.mark.slow
def test_play_cli_writes_the_summary(tmp_path: Path) -> None:
    out = tmp_path / "play"
    assert main(["play", "--seconds", "1", "--out", str(out), "--no-progress", "--video", "--opponent", "self"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert {"score", "shots", "passes", "collisions", "cycle_ms", "seconds", "seed"} <= set(summary)
    assert set(summary["score"]) == {"blue", "yellow"}
    assert set(summary["passes"]) == {"tried", "completed", "ends", "list"}  # (each pass recorded, and how it ended)
    assert set(summary["collisions"]) == {"own", "own_pushed", "opponent"}
    assert {"brain", "vision", "tracker"} <= set(summary["cycle_ms"])
    assert (out / "match.mp4").stat().st_size > 0 and (out / "run.mcap").stat().st_size > 0
