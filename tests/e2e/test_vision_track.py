"""`cmdragons vision RECORDING --track`: tracks.jsonl holds the filtered estimate at each frame's
capture time, closer to the truth than the raw detections; `--track-ahead` the live loop's prediction."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from cmdragons.cli import main
from cmdragons.messages import DetectionFrame, GroundTruth, WorldState


def _rms(v: list[float]) -> float:
    return float(np.sqrt(np.mean(np.square(v))))


@pytest.mark.slow
def test_offline_tracks_are_estimates_at_capture_time_that_beat_raw_detections(tmp_path: Path) -> None:
    rec = tmp_path / "rec"
    assert main(["sim", "--seconds", "2", "--record", "--format", "png", "--out", str(rec), "--no-progress"]) == 0
    truth = {t.frame_number: t for t in (GroundTruth.from_dict(json.loads(line))
                                         for line in (rec / "truth.jsonl").read_text().splitlines())}
    errors: dict[str, dict[str, list[float]]] = {}
    for name, extra in (("capture", []), ("ahead", ["--track-ahead"])):
        out = tmp_path / name
        assert main(["vision", str(rec), "--out", str(out), "--track", "--no-progress", *extra]) == 0
        lines = [json.loads(line) for line in (out / "tracks.jsonl").read_text().splitlines()]
        assert len(lines) == len(truth) == 120
        ahead = 0.0 if name == "capture" else 0.03  # configs/tracker.yaml latency_s
        assert all(d["ahead_s"] == ahead and math.isclose(d["t"], d["t_capture"] + ahead) for d in lines)
        assert [round(d["t_capture"] * 60) for d in lines] == sorted(truth)  # one line per frame, at its time
        assert [d["frame_number"] for d in lines] == sorted(truth)  # numbered as the frames it follows
        err: dict[str, list[float]] = {"ball": [], "robot": []}
        for k, d in enumerate(lines[10:], start=10):  # past the filters' start
            world, t = WorldState.from_dict(d), truth[k]
            if world.ball is not None and t.ball.z < 0.03:
                err["ball"].append(math.hypot(world.ball.x - t.ball.x, world.ball.y - t.ball.y))
            true = {(r.team, r.id): r for r in t.robots}
            err["robot"] += [math.hypot(r.x - true[(r.team, r.id)].x, r.y - true[(r.team, r.id)].y)
                             for r in world.robots]
        errors[name] = err
        if name == "capture":
            raw: dict[str, list[float]] = {"ball": [], "robot": []}
            for line in (out / "detections.jsonl").read_text().splitlines():
                det = DetectionFrame.from_dict(json.loads(line))
                t = truth[det.frame_number]
                if det.frame_number < 10:
                    continue
                if t.ball.z < 0.03:
                    raw["ball"] += [math.hypot(b.x - t.ball.x, b.y - t.ball.y) for b in det.balls]
                true = {(r.team, r.id): r for r in t.robots}
                raw["robot"] += [math.hypot(r.x - true[(r.team, r.id)].x, r.y - true[(r.team, r.id)].y)
                                 for r in det.robots]
    cap, ahead, raw_rms = errors["capture"], errors["ahead"], {k: _rms(v) for k, v in raw.items()}
    assert len(cap["ball"]) > 90 and len(cap["robot"]) > 1000
    # the estimate at capture time beats the raw detections against the truth of that instant
    assert _rms(cap["ball"]) < 0.8 * raw_rms["ball"], (_rms(cap["ball"]), raw_rms["ball"])
    assert _rms(cap["robot"]) < raw_rms["robot"], (_rms(cap["robot"]), raw_rms["robot"])
    assert max(cap["robot"]) < 0.01  # every tracked robot within 1 cm of where it is
    # the live loop's prediction is 30 ms later: against this frame's truth it is off by the motion
    assert _rms(ahead["robot"]) > 2.0 * _rms(cap["robot"])
