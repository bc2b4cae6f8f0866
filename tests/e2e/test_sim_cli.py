"""`cmdragons sim` end to end: a recording that reads back frame by frame, matching its truth."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from cmdragons.cli import main
from cmdragons.recording import RecordingReader


# h264 over two key-frame groups (one a second); the lossless formats have none, and half a second
# reads back the same way as two
@pytest.mark.slow
@pytest.mark.parametrize(("fmt", "seconds"), [("h264", 2.0), ("ffv1", 0.5), ("png", 0.5)])
def test_sim_record_reads_back(tmp_path: Path, fmt: str, seconds: float) -> None:
    out = tmp_path / "run"
    snap = tmp_path / "snap.png"
    assert main(["sim", "--seconds", str(seconds), "--record", "--format", fmt, "--out", str(out), "--snapshot",
                 str(snap), "--no-progress"]) == 0
    n = round(seconds * 60)
    rec = RecordingReader(out)
    truth = list(rec.truth())
    assert len(truth) == n
    assert [t.frame_number for t in truth] == list(range(n))
    assert rec.camera_ids == [0, 1]
    for cam in rec.camera_ids:
        model = rec.camera_model(cam)
        frames = list(rec.frames(cam))
        assert len(frames) == n
        assert frames[0].shape == (model.height, model.width, 3) and frames[0].dtype == np.uint8
        # every robot the truth says this camera sees projects where the truth puts its pixel
        for t in truth[:: n // 4]:
            for r in t.robots:
                if cam in r.pixels:
                    px = model.project_xy(np.array([r.x, r.y]), 0.15)
                    assert np.allclose(px, r.pixels[cam], atol=1e-6)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frames"] == n and summary["seconds"] == pytest.approx(seconds)
    assert set(summary["command_faults"]) == {"non_finite", "clamped", "unknown_robot", "timed_out"}
    assert snap.stat().st_size > 10_000
    with open(out / "run.mcap", "rb") as f:
        topics = {ch.topic for _, ch, _ in make_reader(f).iter_messages()}
    assert {"/truth", "/referee", "/commands/blue", "/commands/yellow", "/events"} <= topics


@pytest.mark.slow
def test_same_seed_same_run(tmp_path: Path) -> None:
    for name in ("a", "b"):
        assert main(["sim", "--seconds", "0.5", "--record", "--format", "png", "--out", str(tmp_path / name),
                     "--no-progress", "--seed", "5"]) == 0
    a, b = RecordingReader(tmp_path / "a"), RecordingReader(tmp_path / "b")
    assert (tmp_path / "a" / "truth.jsonl").read_bytes() == (tmp_path / "b" / "truth.jsonl").read_bytes()
    assert (tmp_path / "a" / "run.mcap").read_bytes() == (tmp_path / "b" / "run.mcap").read_bytes()
    for cam in a.camera_ids:
        for fa, fb in zip(a.frames(cam), b.frames(cam), strict=True):
            assert np.array_equal(fa, fb)
    assert main(["sim", "--seconds", "0.5", "--record", "--format", "png", "--out", str(tmp_path / "c"),
                 "--no-progress", "--seed", "6"]) == 0
    c = RecordingReader(tmp_path / "c")
    assert not np.array_equal(next(a.frames(0)), next(c.frames(0)))


def test_bad_arguments(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "--seconds", "-1", "--no-progress"]) == 2
    assert "--seconds: -1 must be a positive number" in capsys.readouterr().err
    assert main(["bench", "nosuch"]) == 2
    assert "unknown suite" in capsys.readouterr().err
