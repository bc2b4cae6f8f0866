"""The league's log files: written and read back (plain and gzip, with the index), a file cut off
mid-record reads up to its last whole record with a one-line note, `cmdragons log convert` takes a
match's MCAP log to a league log and back with the same detections and game states."""

from __future__ import annotations

import dataclasses
import gzip
import struct
from pathlib import Path

import pytest

from cmdragons import messages as msg
from cmdragons.cli import main
from cmdragons.runtime import wire
from cmdragons.runtime.log import read_log
from cmdragons.runtime.ssl.logfile import LogFileError, LogReader, LogRecord, MessageType, write_log
from cmdragons.runtime.ssl.referee import referee_packet
from cmdragons.runtime.ssl.vision import decode_wrapper, detection_packet

RECORDS = [LogRecord(1_700_000_000_000_000_000 + i * 16_666_667, MessageType.VISION_2014,
                     detection_packet(msg.DetectionFrame(i % 2, i, i / 60, i / 60))) for i in range(6)]
RECORDS.insert(3, LogRecord(RECORDS[2].receive_time_ns, MessageType.REFBOX_2013, referee_packet(msg.GameState(0.05))))


@pytest.mark.parametrize("name", ["game.log", "game.log.gz"])
@pytest.mark.parametrize("index", [True, False])
def test_a_log_written_reads_back(tmp_path: Path, name: str, index: bool) -> None:
    path = tmp_path / name
    assert write_log(path, RECORDS, index=index) == len(RECORDS)
    raw = gzip.decompress(path.read_bytes()) if name.endswith(".gz") else path.read_bytes()
    assert raw[:16] == b"SSL_LOG_FILE\x00\x00\x00\x01"  # big-endian version 1
    assert struct.unpack(">qii", raw[16:32]) == (RECORDS[0].receive_time_ns, 4, len(RECORDS[0].payload))
    reader = LogReader(path)
    assert list(reader) == RECORDS and reader.truncated is None
    if index:
        assert reader.index is not None and reader.index[0] == 16 and len(reader.index) == len(RECORDS)
        # the league's layout: offsets, the distance back from the file's end, the marker
        assert raw[-7:] == b"INDEXED"
        (back,) = struct.unpack(">q", raw[-15:-7])
        index_at = len(raw) - back
        for off, r in zip(reader.index, RECORDS, strict=True):
            assert raw[off + 16: off + 16 + len(r.payload)] == r.payload
        t_ns, kind, size = struct.unpack(">qii", raw[index_at: index_at + 16])
        assert (kind, size, index_at + 16 + size) == (MessageType.INDEX_2021, 8 * len(RECORDS) + 8 + 7, len(raw))
        assert struct.unpack(f">{len(RECORDS)}q", raw[index_at + 16: index_at + 16 + 8 * len(RECORDS)]) == \
            tuple(reader.index)
    else:
        assert reader.index is None


@pytest.mark.parametrize("name", ["cut.log", "cut.log.gz"])
def test_a_log_cut_mid_record_reads_up_to_the_last_whole_record(tmp_path: Path, name: str) -> None:
    whole = tmp_path / "whole.log"
    write_log(whole, RECORDS, index=False)
    data = whole.read_bytes()
    cut = data[: len(data) - 5]  # the last record's payload short by 5 bytes
    path = tmp_path / name
    path.write_bytes(gzip.compress(cut)[:-12] if name.endswith(".gz") else cut)
    reader = LogReader(path)
    got = list(reader)
    assert got == RECORDS[: len(got)] and len(got) >= len(RECORDS) - 2
    assert reader.truncated is not None and "cut short in record" in reader.truncated and "\n" not in reader.truncated


def test_not_a_log_is_an_error(tmp_path: Path) -> None:
    (tmp_path / "x.log").write_bytes(b"GARBAGE_HEADER")
    with pytest.raises(LogFileError, match="not an SSL log file"):
        list(LogReader(tmp_path / "x.log"))
    (tmp_path / "v.log").write_bytes(b"SSL_LOG_FILE" + struct.pack(">i", 2))
    with pytest.raises(LogFileError, match="version 2"):
        list(LogReader(tmp_path / "v.log"))


@pytest.mark.slow
def test_convert_a_match_log_to_a_league_log_and_back(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["play", "--seconds", "0.3", "--no-progress", "--out", str(tmp_path / "run")]) == 0
    mcap = tmp_path / "run" / "run.mcap"
    league = tmp_path / "match.log.gz"
    assert main(["log", "convert", str(mcap), str(league)]) == 0
    assert main(["log", "info", str(league)]) == 0
    back = tmp_path / "back.mcap"
    assert main(["log", "convert", str(league), str(back)]) == 0
    out = capsys.readouterr().out
    assert "VISION_2014" in out and "REFBOX_2013" in out and "indexed" in out
    ours = [(t, m) for topic, t, m in read_log(mcap) if topic.startswith("/detections/")]
    theirs = [(t, m) for topic, t, m in read_log(back) if topic.startswith("/ssl/vision/")]
    assert len(ours) == len(theirs) == 2 * 18
    key = [(round(t, 9), m.camera_id, m.frame_number) for t, m in ours]
    assert sorted(key) == sorted((round(t, 9), m.camera_id, m.frame_number) for t, m in theirs)
    by = {(m.camera_id, m.frame_number): m for _, m in theirs}
    # the same detections, their times to the microsecond (they crossed as Unix time)
    for _, m in ours:
        back_m, want = by[(m.camera_id, m.frame_number)], wire.canonical(m)
        assert dataclasses.replace(back_m, t_capture=want.t_capture, t_sent=want.t_sent) == want
        assert (back_m.t_capture, back_m.t_sent) == pytest.approx((want.t_capture, want.t_sent), abs=1e-6)
    assert "geometry 1," in out  # SSL-Vision's geometry packet, once a second of log time
    first = next(r for r in LogReader(league) if r.type == MessageType.VISION_2014)  # before any detections
    _, geo = decode_wrapper(first.payload)
    assert geo is not None and (geo.field_length_m, geo.field_width_m) == (9.0, 6.0) and len(geo.cameras) == 2
    assert first.receive_time_ns > 1_700_000_000 * 10**9  # Unix time in the league's log
    games = [m for topic, _, m in read_log(mcap) if topic == "/referee"]
    back_games = [m for topic, _, m in read_log(back) if topic == "/referee/gc"]
    assert [(g.command, g.for_team, g.ready, g.score_blue) for g in games] == \
        [(g.command, g.for_team, g.ready, g.score_blue) for g in back_games]


def test_log_info_of_a_cut_log_says_so_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "cut.log"
    write_log(path, RECORDS)
    path.write_bytes(path.read_bytes()[:100])
    assert main(["log", "info", str(path)]) == 0
    out, err = capsys.readouterr()
    ends = [16 + sum(16 + len(r.payload) for r in RECORDS[: k + 1]) for k in range(len(RECORDS))]
    whole = sum(e <= 100 for e in ends)
    assert whole >= 1 and out.startswith(f"{path}: {whole} records")
    assert len(err.strip().splitlines()) == 1 and "cut short" in err
    assert main(["log", "info", str(tmp_path / "none.log")]) == 2
    assert main(["log", "convert", str(path)]) == 2
