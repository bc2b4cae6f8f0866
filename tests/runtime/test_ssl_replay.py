"""`cmdragons replay` of a league log: a match's log written as an SSL log file, read back and
replayed into our tracker and brain gives the same world states and commands as the match; a log
cut off mid-record replays up to its last whole record; the zenoh-only options are refused in one
line."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from cmdragons.cli import main
from cmdragons.runtime.log import read_log


@pytest.fixture(scope="module")
def match(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A 1 s match on our vision (seed 1) and its league log."""
    d = tmp_path_factory.mktemp("league")
    assert main(["play", "--seconds", "1", "--seed", "1", "--no-progress", "--out", str(d / "run")]) == 0
    assert main(["log", "convert", str(d / "run" / "run.mcap"), str(d / "match.log")]) == 0
    return d / "run" / "run.mcap", d / "match.log"


def _topic(path: Path, topic: str) -> list[object]:
    return [m for t, _, m in read_log(path) if t == topic]


def test_a_league_log_of_a_match_replays_to_the_same_tracks(match: tuple[Path, Path], tmp_path: Path) -> None:
    mcap, league = match
    gz = tmp_path / "match.log.gz"
    assert main(["log", "convert", str(mcap), str(gz)]) == 0
    for log in (league, gz):
        out = tmp_path / log.name.replace(".", "_")
        assert main(["replay", str(log), "--out", str(out), "--no-progress"]) == 0
        ours, theirs = _topic(mcap, "/world/blue"), _topic(out / "run.mcap", "/world/blue")
        assert len(ours) == 60 and theirs == ours  # to the bit
        assert _topic(out / "run.mcap", "/commands/blue") == _topic(mcap, "/commands/blue")
        assert (out / "summary.json").exists()


def test_a_league_log_cut_mid_record_replays_to_its_last_whole_record(
        match: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    mcap, league = match
    cut = tmp_path / "cut.log"
    data = league.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    assert main(["replay", str(cut), "--out", str(tmp_path / "cut"), "--no-progress"]) == 0
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "cut short in record" in err
    theirs = _topic(tmp_path / "cut" / "run.mcap", "/world/blue")
    ours = _topic(mcap, "/world/blue")
    assert 20 < len(theirs) < 40 and theirs == ours[: len(theirs)]


def test_a_league_replay_refuses_the_zenoh_options_in_one_line(
        match: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    _, league = match
    assert main(["replay", str(league), "--speed", "2", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--speed" in err
    garbage = tmp_path / "garbage.log"
    garbage.write_bytes(b"NOT A LOG FILE AT ALL")
    assert main(["replay", str(garbage), "--out", str(tmp_path / "y"), "--no-progress"]) == 2
    assert "not an SSL log file" in capsys.readouterr().err
    shutil.rmtree(tmp_path / "y", ignore_errors=True)
