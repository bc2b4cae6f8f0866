"""Scoring detections against truth, and ``cmdragons bench vision`` end to end on a tiny run."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cmdragons.bench import SUITES
from cmdragons.messages import BallDetection, BallTruth, DetectionFrame, GroundTruth, RobotDetection, RobotTruth
from cmdragons.runtime.settings import load_settings

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


def test_score_counts_found_false_and_wrong_ids() -> None:
    from vision.score import Score

    truth = GroundTruth(
        3, 0.05, BallTruth(1.0, 1.0, 0.02, 0.0, 0.0, pixels={0: (10.0, 10.0, 0.9)}),
        (RobotTruth("blue", 1, 0.0, 0.0, 0.5, 0, 0, 0, pixels={0: (1.0, 1.0)}),
         RobotTruth("yellow", 2, 2.0, 0.0, 0.0, 0, 0, 0, pixels={0: (2.0, 2.0)}),
         RobotTruth("yellow", 3, 3.0, 0.0, 0.0, 0, 0, 0, pixels={1: (2.0, 2.0)})),
    )
    det = DetectionFrame(
        0, 3, 0.05, 0.05, (BallDetection(1.003, 1.004, 1.0, (0, 0)), BallDetection(-2.0, 0.0, 0.5, (0, 0))),
        (RobotDetection("blue", 1, 0.002, 0.0, 0.5 + math.radians(1.0), 1.0, (0, 0)),
         RobotDetection("yellow", 7, 2.0, 0.01, 0.0, 1.0, (0, 0)),
         RobotDetection("blue", 4, -1.0, -1.0, 0.0, 1.0, (0, 0))),
    )
    score = Score()
    score.add(det, truth)
    s = score.summary()
    assert s["robot_detection_rate"] == 1.0  # both robots camera 0 sees are found (one with a wrong id)
    assert s["id_accuracy"] == 0.5
    assert math.isclose(s["robot_rms_mm"], 2.0) and math.isclose(s["heading_rms_deg"], 1.0)
    assert math.isclose(s["ball_rms_mm"], 5.0) and s["ball_detection_rate"] == 1.0
    assert s["false_per_frame"] == 2.0  # the blue robot at (-1, -1) and the second ball


@pytest.mark.slow
def test_tiny_vision_bench_meets_the_quality_targets() -> None:
    from cmdragons.bench.vision import run

    assert "vision" in SUITES
    # the lab camera's rows run the realistic pipeline test_realistic_pipeline.py holds to its targets
    rows = {r["name"]: r for r in run(load_settings(CONFIGS), True, frames=3, lab=False)}
    quality = ["vision low", "vision default", "vision high", "vision default, h264 crf 18 (sim --record default)",
               "vision default, h264 crf 23 (4:2:0, x264 default)", "vision default, 1920x1200 (1 camera)"]
    for name in quality:
        row = rows[name]
        assert row["camera_frames"] == (2 if "1920" in name else 6)
        assert row["robot_rms_mm"] <= 5.0 and row["heading_rms_deg"] <= 2.0
        assert row["id_accuracy"] == 1.0 and row["robot_detection_rate"] == 1.0
        assert row["false_per_frame"] == 0.0
    timing = [r for r in rows.values() if "median_ms" in r]
    assert len(timing) == 6 and all(r["median_ms"] > 0 for r in timing)
    assert {r["name"].split("(")[1] for r in timing} == {"1024x768)", "1920x1200)"}


def test_ball_height_bias_recovers_a_known_blob_height() -> None:
    """Detections made as if the blob sat 3 mm above the ball centre, projected at 1 mm above it:
    the fit finds the 2 mm still missing, from two cameras at different heights."""
    import numpy as np

    from vision.score import Score, ball_height_bias_m

    centres = {0: np.array([-2.0, 0.5, 4.0]), 1: np.array([2.5, -0.3, 3.8])}
    rng = np.random.default_rng(8)
    score = Score()
    for k in range(40):
        cam = k % 2
        c = centres[cam]
        ball = np.array([rng.uniform(-4.0, 4.0), rng.uniform(-3.0, 3.0), 0.0215 + (0.3 if k == 5 else 0.0)])
        ray = (ball[:2] - c[:2]) / (c[2] - ball[2] - 0.003)  # the blob's ray: 3 mm above the centre
        det = c[:2] + (c[2] - ball[2] - 0.001) * ray + rng.normal(0.0, 1e-5, 2)
        truth = GroundTruth(k, 0.0, BallTruth(*ball, 0.0, 0.0, pixels={cam: (0.0, 0.0, 1.0)}))
        score.add(DetectionFrame(cam, k, 0.0, 0.0, (BallDetection(*det, 1.0, (0, 0)),), ()), truth)
    assert ball_height_bias_m(score, centres, 0.001) * 1e3 == pytest.approx(2.0, abs=0.05)
    assert math.isnan(ball_height_bias_m(Score(), centres, 0.0))
