"""Frames of any size: a camera model scaled to frames of the same aspect ratio, and frames of
another aspect ratio refused at the first frame (one line: the size found, the size expected, the
command that fixes it; exit 2, before any other frame is decoded)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from cmdragons.camera import CameraModel, CameraParams, scaled_to
from cmdragons.cli import main
from cmdragons.geometry import TEAMS
from cmdragons.runtime.vision_command import run_vision
from vision.pipeline import VisionParams
from vision.sources import FrameSizeError, open_sources

from .conftest import LEAGUE, grid_of_robots, render, snapshot

CAMERA = CameraParams(id=0, position_m=(-2.3, 0.1, 4.0), yaw_rad=0.03, tilt_x_rad=0.02, tilt_y_rad=-0.01,
                      focal_px=610.0, principal_point_px=(515.0, 380.0), k1=-0.05, k2=0.01)


@pytest.mark.parametrize("size", [(1024, 768), (1280, 960), (640, 480), (2048, 1536), (1366, 1025)])
def test_scaled_model_projects_every_point_to_the_scaled_pixel(size: tuple[int, int]) -> None:
    base = CameraModel(CAMERA)
    scaled = scaled_to(CAMERA, *size)
    assert scaled is not None and scaled.resolution_px == size
    rng = np.random.default_rng(1)
    pts = np.column_stack([rng.uniform(-4.5, 0.0, 200), rng.uniform(-3.0, 3.0, 200), rng.uniform(0.0, 0.2, 200)])
    sx, sy = size[0] / 1024, size[1] / 768
    # the same point lands on the same place of the picture (within 0.3% of a pixel's scale for
    # 1366 x 1025, whose aspect differs by 0.1%; exactly otherwise)
    got = CameraModel(scaled).project(pts)
    want = base.project(pts) * [sx, sy]
    np.testing.assert_allclose(got, want, atol=0.003 * size[0])
    if sx == sy:
        np.testing.assert_allclose(got, want, atol=1e-9)
    assert (scaled.k1, scaled.k2) == (CAMERA.k1, CAMERA.k2)


@pytest.mark.parametrize("size", [(1920, 1080), (1280, 720), (768, 1024), (1024, 700)])
def test_another_aspect_ratio_is_not_scaled(size: tuple[int, int]) -> None:
    assert scaled_to(CAMERA, *size) is None


def test_frames_at_twice_the_calibrated_size_are_detected_through_the_scaled_model(tmp_path: Path) -> None:
    """The camera delivers 2048 x 1536 frames (rendered through the scaled model); vision is
    configured with the 1024 x 768 calibration: every robot and the ball found, within 3 mm."""
    big = CameraModel(scaled_to(CAMERA, 2048, 1536))  # type: ignore[arg-type]
    robots = grid_of_robots(big, [0.4], margin_px=120.0)[:20]
    ball = big.unproject(np.array([[900.0, 1300.0]]), LEAGUE.ball.radius_m)[0]
    image, _ = render(big, snapshot(robots, ball=(ball[0], ball[1], LEAGUE.ball.radius_m)))
    cv2.imwrite(str(tmp_path / "0.png"), image)
    sources, _ = open_sources([str(tmp_path / "0.png")])
    # no field mask: the view reaches 0.9 m past the goal line, and so do the robots on its grid
    params = VisionParams(field_margin_m=-1.0)
    summary = run_vision(sources, {0: CameraModel(CAMERA)}, params, LEAGUE, tmp_path / "out", False, 60.0)
    assert summary.frames == 1 and summary.wrong_size == []
    import json

    det = json.loads((tmp_path / "out" / "detections.jsonl").read_text().splitlines()[0])
    expected = {(TEAMS[int(r[0])], int(r[1])): r for r in robots}
    assert sorted((r["team"], r["id"]) for r in det["robots"]) == sorted(expected)
    for r in det["robots"]:
        x, y = expected[(r["team"], r["id"])][2:4]
        assert math.hypot(r["x"] - x, r["y"] - y) < 0.003
    (b,) = det["balls"]
    assert math.hypot(b["x"] - ball[0], b["y"] - ball[1]) < 0.003


def _frames(folder: Path, sizes: list[tuple[int, int]]) -> None:
    folder.mkdir()
    for k, (w, h) in enumerate(sizes):
        cv2.imwrite(str(folder / f"{k}.png"), np.full((h, w, 3), 60, np.uint8))


def test_another_aspect_ratio_stops_before_any_frame_is_processed(tmp_path: Path) -> None:
    _frames(tmp_path / "frames", [(1920, 1080), (1920, 1080), (1920, 1080)])
    sources, _ = open_sources([str(tmp_path / "frames")])
    decoded: list[int] = []
    with pytest.raises(FrameSizeError) as err:
        run_vision(sources, {0: CameraModel(CAMERA)}, VisionParams(), LEAGUE, tmp_path / "out", False, 60.0,
                   progress=decoded.append)
    assert decoded == []  # no frame processed, and only the first read
    text = str(err.value)
    assert "1920x1080" in text and "1024x768" in text and "cmdragons vision calibrate --lines" in text
    assert "0.png" in text


def test_the_cli_refuses_another_aspect_ratio_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _frames(tmp_path / "frames", [(1280, 720), (1280, 720)])
    code = main(["vision", str(tmp_path / "frames"), "--out", str(tmp_path / "out"), "--no-progress"])
    _, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in err
    assert "frames are 1280x720" in lines[0] and "1024x768" in lines[0]
    assert f"cmdragons vision calibrate --lines {tmp_path / 'frames' / '0.png'} --camera 0" in lines[0]
    jsonl = tmp_path / "out" / "detections.jsonl"
    assert not jsonl.exists() or not jsonl.read_text()


def test_a_later_frame_of_another_size_is_counted_not_fatal(tmp_path: Path) -> None:
    _frames(tmp_path / "frames", [(2048, 1536), (1920, 1080), (2048, 1536)])
    sources, _ = open_sources([str(tmp_path / "frames")])
    summary = run_vision(sources, {0: CameraModel(dataclasses.replace(CAMERA))}, VisionParams(), LEAGUE,
                         tmp_path / "out", False, 60.0)
    assert summary.frames == 3 and len(summary.wrong_size) == 1 and summary.wrong_size[0].endswith("#1")
