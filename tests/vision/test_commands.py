"""``cmdragons vision SOURCE...``, ``vision tune`` and ``vision calibrate`` end to end, and the
calibration fit on synthetic correspondences."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from cmdragons.camera import CameraModel, CameraParams
from cmdragons.cli import main
from cmdragons.geometry import Field
from cmdragons.runtime.settings import load_settings
from vision.calibrate import calibrate

from .conftest import LEAGUE

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A short PNG recording with truth from `cmdragons sim`, three frames made bad."""
    out = tmp_path_factory.mktemp("rec")
    assert main(["sim", "--config", str(CONFIGS), "--seconds", "0.1", "--record", "--format", "png",
                 "--out", str(out), "--no-progress"]) == 0
    frames = sorted((out / "camera_0").glob("*.png"))
    frames[1].write_bytes(b"not a png")  # corrupt
    frames[2].write_bytes(b"")  # empty
    import cv2

    cv2.imwrite(str(frames[3]), np.zeros((100, 120, 3), np.uint8))  # wrong size
    return out


Capture = pytest.CaptureFixture[str]


@pytest.mark.slow
def test_vision_on_a_recording_counts_bad_frames_and_scores_truth(recording: Path, tmp_path: Path,
                                                                  capsys: Capture) -> None:
    out = tmp_path / "out"
    assert main(["vision", str(recording), "--config", str(CONFIGS), "--out", str(out), "--no-progress",
                 "--video"]) == 0
    text = capsys.readouterr().out
    assert "1 unreadable frame(s): rec0/camera_0#1" in text.replace(recording.name, "rec0")
    assert "1 empty frame(s)" in text and "1 wrong size frame(s)" in text
    lines = [json.loads(s) for s in (out / "detections.jsonl").read_text().splitlines()]
    assert len(lines) == 2 * 6 - 3
    assert {"camera_id", "frame_number", "t_capture", "balls", "robots"} <= set(lines[0])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frames"] == 12 and summary["score"]["robot_detection_rate"] == 1.0
    assert summary["score"]["id_accuracy"] == 1.0 and summary["score"]["false_per_frame"] == 0.0
    assert (out / "annotated_camera_0.mp4").stat().st_size > 0


def test_the_summary_counts_the_whole_field_per_capture(tmp_path: Path, capsys: Capture) -> None:
    """Each camera sees part of the field: the summary's robots and ball are those any camera saw in a
    capture (the frames of one number), not counts per camera frame (a ball in one camera's half read
    as 0.5 balls per frame); the ball lies at the centre spot, in both cameras' views, and counts once."""
    rec, out = tmp_path / "rec", tmp_path / "out"
    assert main(["sim", "--config", str(CONFIGS), "--seconds", "0.1", "--record", "--format", "png",
                 "--out", str(rec), "--no-progress"]) == 0
    truth = [json.loads(s) for s in (rec / "truth.jsonl").read_text().splitlines()]
    capsys.readouterr()
    assert main(["vision", str(rec), "--config", str(CONFIGS), "--out", str(out), "--no-progress"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frames"] == 2 * len(truth) and summary["captures"] == len(truth) == 6
    assert summary["robots_per_capture"] == len(truth[0]["robots"])  # every robot, once, whichever camera saw it
    assert summary["ball_seen_share"] == 1.0  # the ball on the field, in some camera's view, every capture
    assert "the ball in 100 %" in capsys.readouterr().out


def test_vision_on_a_glob_and_a_video(recording: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import cv2

    video = tmp_path / "cam1.mp4"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter.fourcc(*"mp4v"), 60.0, (1024, 768))
    for p in sorted((recording / "camera_1").glob("*.png")):
        writer.write(cv2.imread(str(p)))
    writer.release()
    out = tmp_path / "out"
    glob = str(recording / "camera_0" / "00000[4-5].png")
    assert main(["vision", glob, str(video), "--config", str(CONFIGS), "--out", str(out), "--no-progress"]) == 0
    lines = [json.loads(s) for s in (out / "detections.jsonl").read_text().splitlines()]
    # capture by capture: each source's next frame, camera 0's two images beside the video's first two
    assert [d["camera_id"] for d in lines] == [0, 1, 0, 1] + [1] * 4
    assert all(len(d["robots"]) >= 1 for d in lines)  # mp4v smears colours, but the patterns survive
    assert main(["vision", str(tmp_path / "nothing*.png"), "--config", str(CONFIGS), "--out", str(out)]) == 2


@pytest.mark.slow
def test_vision_on_a_cut_off_video_processes_every_frame_before_the_break(tmp_path: Path, capsys: Capture) -> None:
    rec = tmp_path / "rec"
    assert main(["sim", "--config", str(CONFIGS), "--seconds", "0.5", "--record", "--out", str(rec),
                 "--no-progress"]) == 0
    meta = yaml.safe_load((rec / "cameras.yaml").read_text())
    assert meta["recording"] == {"codec": "h264", "crf": 18}  # the recording says what it holds
    video = rec / "camera_0.mp4"
    data = video.read_bytes()
    video.write_bytes(data[: len(data) * 3 // 4])
    capsys.readouterr()
    out = tmp_path / "vision"
    assert main(["vision", str(rec), "--config", str(CONFIGS), "--out", str(out), "--no-progress"]) == 0
    err = capsys.readouterr().err
    lines = [json.loads(line) for line in (out / "detections.jsonl").read_text().splitlines()]
    cam0 = [d["frame_number"] for d in lines if d["camera_id"] == 0]
    assert [d["frame_number"] for d in lines if d["camera_id"] == 1] == list(range(30))
    assert 5 <= len(cam0) < 30 and cam0 == list(range(len(cam0)))
    assert f"camera_0.mp4: frame {len(cam0)} " in err and "the frames before it were processed" in err
    assert json.loads((out / "summary.json").read_text())["broken_off"][0].startswith(str(video))


def test_tune_from_truth_and_from_labels(recording: Path, tmp_path: Path, capsys: Capture) -> None:
    config = tmp_path / "configs"
    shutil.copytree(CONFIGS, config)
    before = (config / "vision.yaml").read_text()
    capsys.readouterr()
    assert main(["vision", "tune", str(recording), "--config", str(config)]) == 0
    # every line but the colour boxes' stays as it was, comments and all
    after = (config / "vision.yaml").read_text()
    box_lines = [k for k, line in enumerate(before.splitlines()) if line.lstrip().startswith(
        ("orange:", "blue:", "yellow:", "pink:", "green:")) and "lo:" in line]
    assert len(box_lines) == 5 and len(after.splitlines()) == len(before.splitlines())
    for k, (a, b) in enumerate(zip(before.splitlines(), after.splitlines(), strict=True)):
        if k in box_lines:
            assert a.split("{")[0] == b.split("{")[0] and "min_area_px: 6}" in b  # the key and min area stay
        else:
            assert a == b, (k, a, b)
    assert after != before
    printed = capsys.readouterr().out
    assert "tune: blue" in printed and "labelled pixels: lo [63, 155, 45]" in printed and " -> lo [" in printed
    tuned = load_settings(config).vision
    assert set(tuned.colours) == {"orange", "blue", "yellow", "pink", "green"}
    # the tuned boxes hold the shipped colours' centres: blue's U is high, yellow's Y is high
    assert tuned.colours["blue"].lo[1] > 150 and tuned.colours["yellow"].lo[0] > 150
    frame = recording / "camera_0" / "000000.png"
    labels = tmp_path / "labels.yaml"
    t0 = json.loads((recording / "truth.jsonl").read_text().splitlines()[0])
    ball = t0["ball"]["cameras"]["0"]["pixel"]
    labels.write_text(yaml.safe_dump([{"colour": "orange", "pixel": ball, "radius": 2.5},
                                      {"colour": "carpet", "pixel": [30, 30], "radius": 10}]))
    assert main(["vision", "tune", str(frame), "--labels", str(labels), "--config", str(config),
                 "--out", str(tmp_path / "v.yaml")]) == 0
    data = yaml.safe_load((tmp_path / "v.yaml").read_text())
    assert data["colours"]["carpet"]["lo"][0] < 90 < data["colours"]["carpet"]["hi"][0]


def _field_points() -> np.ndarray:
    """Field-line corners and intersections (z = 0) and a few goal-post tops."""
    f = Field(LEAGUE)
    pts = {seg.a for seg in f.line_segments()} | {seg.b for seg in f.line_segments()}
    xyz = [(x, y, 0.0) for x, y in pts]
    xyz += [(s * f.half_length, g * f.goal_half_width, LEAGUE.dims.goal_height_m) for s in (-1, 1) for g in (-1, 1)]
    return np.array(xyz)


@pytest.mark.parametrize("fit_principal", [False, True])
def test_calibration_recovers_known_parameters(fit_principal: bool) -> None:
    truth = CameraParams(id=2, position_m=(-2.2, 0.15, 4.05), yaw_rad=-1.55, tilt_x_rad=0.03, tilt_y_rad=-0.04,
                         focal_px=640.0, principal_point_px=(512.0, 384.0), k1=-0.03, k2=0.005)
    model = CameraModel(truth)
    xyz = _field_points()
    px = model.project(xyz)
    keep = model.in_image(px, margin=2.0)
    rng = np.random.default_rng(1)
    noisy = px[keep] + rng.normal(0.0, 0.2, (int(keep.sum()), 2))
    # the height is measured (points on one plane cannot tell it from the focal length), within 1 cm
    guess = dataclasses.replace(truth, position_m=(0.0, 0.0, 4.06), yaw_rad=0.0, tilt_x_rad=0.0, tilt_y_rad=0.0,
                                focal_px=600.0, k1=0.0, k2=0.0)
    result = calibrate(noisy, xyz[keep], guess, fit_principal)
    assert result.rms_px < 0.4
    p = result.params
    assert abs(math.remainder(p.yaw_rad - truth.yaw_rad, 2 * math.pi)) < 0.005
    if not fit_principal:  # a free principal point trades off against the position and tilts
        np.testing.assert_allclose(p.position_m, truth.position_m, atol=0.02)
        assert abs(p.focal_px - truth.focal_px) < 8.0 and abs(p.k1 - truth.k1) < 0.01
    # what matters: field points at robot height land where the true camera puts them
    grid = np.array([[x, y] for x in np.linspace(-4, -0.5, 8) for y in np.linspace(-2.5, 2.5, 6)])
    err = CameraModel(p).unproject(model.project_xy(grid, 0.15), 0.15) - grid
    # m RMS, from 0.2 px noise on about 13 points (two more free parameters with the principal point)
    assert float(np.sqrt(np.mean(np.sum(err**2, axis=1)))) < (0.006 if fit_principal else 0.004)


def test_calibrate_command_writes_a_camera_list(tmp_path: Path) -> None:
    config = tmp_path / "configs"
    shutil.copytree(CONFIGS, config)
    model = load_settings(config).camera_models()[0]
    xyz = _field_points()
    px = model.project(xyz)
    keep = model.in_image(px, margin=2.0)
    pairs = zip(px[keep], xyz[keep], strict=True)
    pts = [{"pixel": [float(u), float(v)], "field": [float(x) for x in p]} for (u, v), p in pairs]
    (tmp_path / "points.yaml").write_text(yaml.safe_dump(pts))
    assert main(["vision", "calibrate", str(tmp_path / "points.yaml"), "--camera", "0", "--config", str(config)]) == 0
    s = load_settings(config)
    assert s.cameras.layout == "list" and [c.id for c in s.cameras.cameras] == [0, 1]
    np.testing.assert_allclose(s.cameras.cameras[0].position_m, model.params.position_m, atol=1e-3)
