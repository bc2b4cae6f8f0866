"""Calibration from the field lines (vision.field_lines, `vision calibrate --lines`): a known
camera recovered from rendered frames, on any field size, and the command's output."""

from __future__ import annotations

import dataclasses
import math
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, CameraParams, CamerasParams, cameras_from_config
from cmdragons.cli import main
from cmdragons.geometry import FieldDims, LeagueParams
from sim.render import CameraRenderer, RenderParams
from vision.field_lines import CalibrationRefused, LineFitParams, calibrate_from_lines, rough_start, true_error_px

from .conftest import LEAGUE, render, snapshot

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
ROBOTS = [[0, 1, -2.0, 0.5, 0.3], [1, 4, -3.0, -1.0, 2.0], [0, 7, -1.0, -1.5, 1.0], [1, 9, 2.0, 0.2, 0.0],
          [0, 3, 3.1, -1.2, 1.0], [1, 2, 0.2, 1.1, 2.5]]


def pose_errors(got: CameraParams, true: CameraParams) -> tuple[float, float]:
    """Position error (m) and the angle (degrees) of the rotation between the two orientations."""
    r = CameraModel(got).R_cam_to_field.T @ CameraModel(true).R_cam_to_field
    angle = math.degrees(math.acos(min(1.0, (float(np.trace(r)) - 1.0) / 2.0)))
    return float(np.linalg.norm(np.subtract(got.position_m, true.position_m))), angle


def off_start(true: CameraParams, dx: float, dy: float) -> CameraParams:
    """The rough start a user gives: the true height, the field rectangle the camera sees moved by
    (dx, dy) m and cut to whole decimetres."""
    m = CameraModel(true)
    c = m.unproject(np.array([[0.0, 0.0], [m.width, m.height]]), 0.0)
    sees = (round(c[:, 0].min() + dx, 1), round(c[:, 1].min() + dy, 1), round(c[:, 0].max() + dx, 1),
            round(c[:, 1].max() + dy, 1))
    return rough_start(true, true.position_m[2], sees)


@pytest.mark.slow
@pytest.mark.parametrize("cam", [0, 1])
def test_lines_recover_the_simulators_cameras(cameras: list[CameraModel], cam: int) -> None:
    true = cameras[cam].params
    image, _ = render(cameras[cam], snapshot(ROBOTS, ball=(-2.5, 0.3, 0.0215)), seed=cam)
    fit = calibrate_from_lines(image, LEAGUE, off_start(true, 0.3, -0.25))
    dist, angle = pose_errors(fit.params, true)
    assert dist < 0.01 and angle < 0.5  # the targets (seen: 0.2 mm, 0.002 degrees)
    assert fit.rms_px <= 0.5 and fit.points > 1000
    assert fit.params.focal_px == pytest.approx(true.focal_px, rel=1e-3)
    assert fit.params.k1 == pytest.approx(true.k1, abs=2e-3)


@pytest.mark.slow
def test_lines_on_a_frame_of_other_colours_tilt_and_distortion(cameras: list[CameraModel]) -> None:
    base = cameras[0].params
    true = dataclasses.replace(base, k1=-0.07, k2=0.01, tilt_x_rad=0.03, tilt_y_rad=-0.02, yaw_rad=base.yaw_rad + 0.02,
                               position_m=(base.position_m[0] + 0.1, base.position_m[1] - 0.15, 3.7))
    look = RenderParams(carpet_bgr=(60, 95, 20), line_bgr=(200, 225, 230), noise_sigma_grey=4.0,
                        vignetting_fraction=0.2, gradient_fraction=0.15)
    image, _ = render(CameraModel(true), snapshot(ROBOTS, ball=(-2.5, 0.3, 0.0215)), look, seed=5)
    rough = off_start(base, -0.2, 0.2)
    start = dataclasses.replace(rough, position_m=(*rough.position_m[:2], 3.7))  # the height measured
    fit = calibrate_from_lines(image, LEAGUE, start)
    dist, angle = pose_errors(fit.params, true)
    assert fit.rms_px <= 1.5  # the target for a frame the pipeline never produced
    assert dist < 0.01 and angle < 0.5
    assert (fit.params.k1, fit.params.k2) == pytest.approx((-0.07, 0.01), abs=5e-3)


@pytest.mark.slow
def test_lines_on_a_small_custom_field() -> None:
    """A 6.05 x 4.05 m field (an older size, as a custom division in field.yaml)."""
    small = FieldDims(length_m=6.05, width_m=4.05, goal_width_m=0.7, defense_width_m=1.4, defense_depth_m=0.8,
                      center_circle_radius_m=0.5)
    league = dataclasses.replace(LEAGUE, divisions={"B": small, "A": LEAGUE.divisions["A"]})
    models = cameras_from_config(CamerasParams(), league)
    true = models[-1].params
    image, _ = CameraRenderer(models[-1], league, RenderParams(), seed=2).render(
        snapshot(ROBOTS[:2], ball=(1.0, 0.3, 0.0215)))
    fit = calibrate_from_lines(image.copy(), league, off_start(true, 0.2, 0.2))
    dist, angle = pose_errors(fit.params, true)
    assert dist < 0.01 and angle < 0.5 and fit.rms_px <= 0.5


@pytest.mark.slow
def test_calibrate_lines_command_keeps_comments_and_draws_the_overlay(cameras: list[CameraModel],
                                                                      tmp_path: Path) -> None:
    config = tmp_path / "configs"
    shutil.copytree(CONFIGS, config)
    before = (config / "cameras.yaml").read_text()
    true = cameras[1].params
    image, _ = render(cameras[1], snapshot(ROBOTS), seed=4)
    frame = tmp_path / "cam1.png"
    cv2.imwrite(str(frame), image)
    m = CameraModel(true)
    c = m.unproject(np.array([[0.0, 0.0], [m.width, m.height]]), 0.0)
    sees = [str(round(v, 1)) for v in (c[:, 0].min() - 0.2, c[:, 1].min(), c[:, 0].max() - 0.2, c[:, 1].max())]
    argv = ["vision", "calibrate", "--lines", str(frame), "--camera", "1", "--height", "4.0", "--sees", *sees,
            "--config", str(config)]
    assert main(argv) == 0
    after = (config / "cameras.yaml").read_text()
    comments = [line for line in before.splitlines() if line.lstrip().startswith("#")]
    assert comments and all(line in after.splitlines() for line in comments)  # every comment line stays
    data = yaml.safe_load(after)
    assert data["layout"] == "list" and [c["id"] for c in data["cameras"]] == [0, 1]
    got = CameraParams(**{k: tuple(v) if isinstance(v, list) else v for k, v in data["cameras"][1].items()})
    dist, angle = pose_errors(got, true)
    assert dist < 0.01 and angle < 0.5
    assert data["cameras"][0]["position_m"] == pytest.approx(list(cameras[0].params.position_m))  # kept
    overlay = cv2.imread(str(tmp_path / "cam1_calibration.png"))
    assert overlay.shape == image.shape and np.count_nonzero(np.any(overlay != image, axis=-1)) > 2000
    # a second run updates the entry in place: still two cameras, still every comment
    assert main(argv) == 0
    again = yaml.safe_load((config / "cameras.yaml").read_text())
    assert [c["id"] for c in again["cameras"]] == [0, 1]
    # bad input: one line on stderr, exit code 2
    assert main(["vision", "calibrate", "--lines", str(tmp_path / "none.png"), "--config", str(config)]) == 2
    assert main(["vision", "calibrate", "--config", str(config)]) == 2


LAB = FieldDims(length_m=5.54, width_m=3.77, boundary_width_m=0.3, goal_width_m=1.0, defense_width_m=2.0,
                defense_depth_m=1.0, line_width_m=0.045, center_circle=False, goal_to_goal_line=False)


def _league(dims: FieldDims) -> LeagueParams:
    return dataclasses.replace(LEAGUE, divisions={"B": dims, "A": LEAGUE.divisions["A"]})


@pytest.fixture(scope="module")
def lab_render() -> tuple[NDArray[np.uint8], CameraParams]:
    """A lab field (5.54 x 3.77 m, 45 mm tape, no centre circle, no line from goal to goal) seen
    whole by one slightly tilted, distorted 1280x720 camera at 3.2 m."""
    true = CameraParams(id=0, position_m=(0.05, -0.04, 3.2), yaw_rad=0.01, tilt_x_rad=0.01, tilt_y_rad=-0.015,
                        focal_px=700.0, principal_point_px=(640.0, 360.0), k1=-0.03, k2=0.0,
                        resolution_px=(1280, 720))
    image, _ = CameraRenderer(CameraModel(true), _league(LAB), RenderParams(noise_sigma_grey=2.0), seed=3).render(
        snapshot(ROBOTS[:3], ball=(1.0, 0.3, 0.0215)))
    return image.copy(), true


@pytest.mark.slow
def test_wide_tape_centres_and_an_honest_error(lab_render: tuple[NDArray[np.uint8], CameraParams]) -> None:
    """field.yaml's line width at the league's 10 mm, the tape 45 mm: the width is measured, the
    fit runs along the tape's middle and the error it reports is its error against the truth."""
    image, true = lab_render
    told = _league(dataclasses.replace(LAB, line_width_m=0.01))
    rough = rough_start(true, 3.2, (-3.3, -1.7, 3.1, 1.9))
    fit = calibrate_from_lines(image, told, rough)
    dist, angle = pose_errors(fit.params, true)
    assert dist < 0.01 and angle < 0.5
    scale = true.focal_px / 3.2
    assert fit.line_width_px == pytest.approx(0.045 * scale, rel=0.15)  # 9.8 px
    truth = true_error_px(fit.params, true, told)
    assert truth < 0.5 and abs(fit.rms_px - truth) < 0.3
    assert fit.lines_seen >= 7 and fit.found > 0.9


BIGGER = {"length_m": 6.2, "width_m": 4.22, "defense_depth_m": 1.12, "defense_width_m": 2.24}  # all 12 % more


@pytest.mark.slow
@pytest.mark.parametrize(("field", "focal", "reason"), [
    (dataclasses.replace(LAB, length_m=6.2), 0.0, "not the one in the image"),  # 12 % too long
    (dataclasses.replace(LAB, **BIGGER), 700.0, "off the known 700 px"),  # all 12 % too big, the lens known
    (dataclasses.replace(LAB, center_circle=True), 0.0, "not the one in the image"),
    (FieldDims(), 0.0, "not the one in the image"),  # the league's 9 x 6 m field
])
def test_a_wrong_field_is_refused_with_its_reason(lab_render: tuple[NDArray[np.uint8], CameraParams],
                                                  field: FieldDims, focal: float, reason: str) -> None:
    image, true = lab_render
    with pytest.raises(CalibrationRefused, match=reason):
        calibrate_from_lines(image, _league(field), rough_start(true, 3.2, (-3.3, -1.7, 3.1, 1.9)),
                             LineFitParams(known_focal_px=focal))


REAL = Path(__file__).resolve().parents[3] / "shared" / "realdata" / "lab_frame_lights_on.jpg"


@pytest.mark.slow
@pytest.mark.skipif(not REAL.exists(), reason=f"the real lab frame is not here ({REAL})")
def test_the_real_lab_frame() -> None:
    """A webcam's frame of a hand-taped lab field: every line found, the tape's 45 mm measured,
    the residual about a pixel (hand-laid tape is not straight), a plausible webcam."""
    image = np.asarray(cv2.imread(str(REAL)), dtype=np.uint8)
    base = CameraParams(id=0, resolution_px=(1920, 1080), principal_point_px=(960.0, 540.0))
    fit = calibrate_from_lines(image, _league(dataclasses.replace(LAB, line_width_m=0.01, outer_lines="walls")),
                               rough_start(base, 4.0, (-3.45, -1.94, 3.45, 1.94)))
    mm = fit.line_width_px / CameraModel(fit.params).pixels_per_metre((0.0, 0.0), 0.0) * 1000
    assert 35 < mm < 55 and fit.lines_seen == 7 and fit.found > 0.9 and fit.rms_px < 1.6
    fov = math.degrees(2 * math.atan(960 / fit.params.focal_px))
    assert 60 < fov < 100  # the BRIO's 16:9 field of view: 65 to 90 degrees


@pytest.mark.slow
def test_calibrate_lines_command_refuses_the_default_field_on_a_lab_frame(
        lab_render: tuple[NDArray[np.uint8], CameraParams], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """No --config: the league's 9 x 6 m field against a 5.54 x 3.77 m lab field. Exit 2, the
    reason in one line, cameras.yaml untouched."""
    config = tmp_path / "configs"
    shutil.copytree(CONFIGS, config)
    before = (config / "cameras.yaml").read_text()
    frame = tmp_path / "lab.png"
    cv2.imwrite(str(frame), lab_render[0])
    assert main(["vision", "calibrate", "--lines", str(frame), "--config", str(config), "--height", "3.2",
                 "--sees", "-3.3", "-1.7", "3.1", "1.9"]) == 2
    err = capsys.readouterr().err
    assert "not the one in the image" in err and len(err.strip().splitlines()) == 1
    assert (config / "cameras.yaml").read_text() == before
