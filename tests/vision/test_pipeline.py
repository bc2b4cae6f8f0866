"""The vision pipeline against the renderer's truth: every id of both teams at several headings,
the ball, and bad input.

Tolerances (default noise, lighting and blur of configs/sim.yaml): robot centre within 3 mm,
heading within 1.5 degrees, ball within 3 mm; ids exact; nothing reported that is not there.
"""

from __future__ import annotations

import dataclasses
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from cmdragons.camera import CameraModel
from cmdragons.config import ConfigError
from cmdragons.geometry import TEAMS
from cmdragons.messages import BallTruth, GroundTruth
from cmdragons.runtime.settings import load_settings
from sim.render import RenderParams
from vision.pipeline import VisionParams, VisionPipeline

from .conftest import LEAGUE, grid_of_robots, render, snapshot

REPO_CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.mark.parametrize("camera_index", [0, 1])
@pytest.mark.parametrize("heading", [0.0, 2.9, -1.3])
def test_every_id_and_pose_match_truth(cameras: list[CameraModel], camera_index: int, heading: float) -> None:
    model = cameras[camera_index]
    robots = grid_of_robots(model, [heading])  # each (team, id) once, headings heading + 0.37 id
    ball = model.unproject(np.array([[model.width * 0.31, model.height * 0.93]]), LEAGUE.ball.radius_m)[0]
    image, truth = render(model, snapshot(robots, ball=(ball[0], ball[1], LEAGUE.ball.radius_m)), seed=camera_index)
    det = VisionPipeline(VisionParams(), LEAGUE, model).process(image, 7, 0.25)
    assert (det.camera_id, det.frame_number, det.t_capture) == (model.id, 7, 0.25)
    assert len(truth.robots) == 32
    expected = {(TEAMS[int(r[0])], int(r[1])): r for r in robots}
    assert sorted((r.team, r.id) for r in det.robots) == sorted(expected)
    for r in det.robots:
        _, _, x, y, theta = expected[(r.team, r.id)]
        assert math.hypot(r.x - x, r.y - y) < 0.003, (r, x, y)
        assert abs(math.degrees(math.remainder(r.theta - theta, 2 * math.pi))) < 1.5, (r, theta)
        assert 0.5 < r.confidence <= 1.0
        np.testing.assert_allclose(r.pixel, truth.robots[(TEAMS.index(r.team), r.id)], atol=1.0)
    assert len(det.balls) == 1
    assert math.hypot(det.balls[0].x - ball[0], det.balls[0].y - ball[1]) < 0.003


def test_empty_field_gives_no_detections(cameras: list[CameraModel]) -> None:
    image, _ = render(cameras[0], snapshot([]), RenderParams(noise_sigma_grey=6.0))
    det = VisionPipeline(VisionParams(), LEAGUE, cameras[0]).process(image, 0, 0.0)
    assert det.robots == () and det.balls == ()


@pytest.mark.parametrize("shape", [(100, 100, 3), (768, 1024), (768, 1024, 4)])
def test_wrong_size_frame_is_a_clear_error(cameras: list[CameraModel], shape: tuple[int, ...]) -> None:
    with pytest.raises(ValueError, match="expected a uint8 image of shape"):
        VisionPipeline(VisionParams(), LEAGUE, cameras[0]).process(np.zeros(shape, np.uint8), 0, 0.0)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("roles:\n  ball: red\n", "roles.ball: unknown colour 'red'; colours defined: orange, blue"),
        ("colours:\n  orange: {lo: [0, 0, 0], hi: [255, 255, 300]}\n", "colours.orange.hi[2]"),
        ("colours:\n  orange: {lo: [10, 0, 0], hi: [5, 255, 255]}\n", "must not exceed hi"),
        ("colour_space: hsv\n", "allowed: 'yuv', 'bgr'"),
        ("regions:\n  connectivity: 6\n", "allowed: 4, 8"),
    ],
)
def test_bad_vision_config_names_the_problem(tmp_path: Path, text: str, fragment: str) -> None:
    folder = tmp_path / "configs"
    shutil.copytree(REPO_CONFIGS, folder)
    (folder / "vision.yaml").write_text(text)
    with pytest.raises(ConfigError) as err:
        load_settings(folder)
    assert err.value.file.endswith("vision.yaml")
    assert fragment in str(err.value)


@pytest.mark.slow
def test_calibrated_blob_height_leaves_no_radial_ball_bias(cameras: list[CameraModel]) -> None:
    """Balls at rest across the whole image of each camera: with the configured blob height the
    detections lie neither outward nor inward of the truth (within 1 mm of height), and the
    coverage centre needs less than 1 mm of it, while the thresholded pixels' centroid projected at
    the ball centre lies outward (its shaded rim is not orange)."""
    from vision.score import Score, ball_height_bias_m

    calibrated = VisionParams()
    centroid = dataclasses.replace(calibrated.ball, centre="centroid", blob_height_above_centre_m=0.0)
    at_centre = VisionParams(ball=centroid)
    scores = {"calibrated": Score(), "at_centre": Score()}
    r = LEAGUE.ball.radius_m
    for model in cameras:
        pipes = {"calibrated": VisionPipeline(calibrated, LEAGUE, model),
                 "at_centre": VisionPipeline(at_centre, LEAGUE, model)}
        for k, (fu, fv) in enumerate([(fu, fv) for fu in (0.1, 0.3, 0.5, 0.7, 0.9) for fv in (0.1, 0.5, 0.9)]):
            ball = model.unproject(np.array([[model.width * fu, model.height * fv]]), r)[0]
            snap = snapshot([], ball=(ball[0], ball[1], r), frame=k)
            image, _ = render(model, snap, seed=k)
            truth = GroundTruth(k, 0.0, BallTruth(ball[0], ball[1], r, 0.0, 0.0, pixels={model.id: (0.0, 0.0, 1.0)}))
            for name, pipe in pipes.items():
                scores[name].add(pipe.process(image, k, 0.0), truth)
    centres = {m.id: m.center for m in cameras}
    for score in scores.values():
        assert len(score.ball_pairs) == 15 * len(cameras)
    height = calibrated.ball.blob_height_above_centre_m
    assert abs(ball_height_bias_m(scores["calibrated"], centres, height)) < 1e-3
    assert 0.0 <= ball_height_bias_m(scores["calibrated"], centres, height) + height < 1e-3
    assert ball_height_bias_m(scores["at_centre"], centres, 0.0) > 1.5e-3
    calibrated_rms = np.sqrt(np.mean(np.square(scores["calibrated"].ball_err_m)))
    assert calibrated_rms < np.sqrt(np.mean(np.square(scores["at_centre"].ball_err_m)))


def test_partly_hidden_or_cut_ball_carries_a_larger_sigma(cameras: list[CameraModel]) -> None:
    """Each ball detection carries its position's standard deviation: about the floor (0.2 mm) in
    the clear, several times more for a ball half behind a robot's body (seen obliquely, near the
    image's corner) or cut by the image's edge, whose centres are millimetres off; the error stays
    within a few of its sigma."""
    model = cameras[0]
    r = LEAGUE.ball.radius_m
    robot = model.unproject(np.array([[model.width * 0.8, model.height * 0.8]]), 0.0)[0]
    outward = math.atan2(robot[1] - model.center[1], robot[0] - model.center[0])
    # no field mask: the ball cut by the image's edge lies past the boundary wall (0.38 m off the line)
    pipe = VisionPipeline(VisionParams(field_margin_m=-1.0), LEAGUE, model)

    def seen(x: float, y: float, robots: list[list[float]]) -> tuple[float, float]:
        image, _ = render(model, snapshot(robots, ball=(x, y, r)), seed=1)
        (ball,) = pipe.process(image, 0, 0.0).balls
        return math.hypot(ball.x - x, ball.y - y), ball.sigma_m

    robots = [[0, 3, robot[0], robot[1], 0.0]]
    a = outward + math.radians(45.0)  # beside the robot, on the side it leans over in the image
    clear_err, clear_sigma = seen(robot[0] + 0.3 * math.cos(a), robot[1] + 0.3 * math.sin(a), robots)
    hidden_err, hidden_sigma = seen(robot[0] + 0.13 * math.cos(a), robot[1] + 0.13 * math.sin(a), robots)
    at_edge = model.unproject(np.array([[0.5, model.height * 0.5]]), r)[0]  # centre on the image's first column
    cut_err, cut_sigma = seen(at_edge[0], at_edge[1], [])
    assert clear_sigma < 0.5e-3 and clear_err < 3.0 * clear_sigma
    assert hidden_err > 2e-3 and hidden_sigma > 5.0 * clear_sigma and hidden_err < 3.0 * hidden_sigma
    assert cut_err > 2e-3 and cut_sigma > 5.0 * clear_sigma and cut_err < 3.0 * cut_sigma
