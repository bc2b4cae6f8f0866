"""The whole camera pipeline on the simulator's realistic camera (cameras.yaml ``preset: realistic``)
with nothing labelled: the camera calibrated from the lines of one frame, every colour learnt by
``tune --auto`` from the first second, then a scripted game read with three dots of four among the
ids in play and classes following the light.

A lab's field.yaml: a 5.54 x 3.77 m field, 45 mm tape, 84 mm balls; one 1280x800 camera sees it all
(the dots about as many pixels across as at 1920x1200 over the league's Division B field); the
kickoff formation moved onto it.
Tolerances: the issue's -- pose within 1 cm and 0.5 deg, the reported line error within 0.3 px of
the error against the true line centres; robots found 99% with every id right (here 99.5%: the
light followed on the carpet measured 99.9%, on the markers 99.5%), the ball 99%, no false
detection; the cover with its dot taped over found in 95% of the frames.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, CameraParams
from cmdragons.geometry import Field
from cmdragons.messages import GroundTruth
from cmdragons.runtime.settings import Settings, load_settings
from sim.script import ScriptedPlay
from sim.simulator import Simulator
from vision.field_lines import calibrate_from_lines, rough_start, true_error_px
from vision.pipeline import VisionPipeline
from vision.score import Score
from vision.tune import auto_samples, learn_boxes

LAB = ["cameras.preset=realistic", "cameras.realistic.resolution_px=[1280,800]", "cameras.realistic.view_margin_m=0.4",
       "field.divisions.B.length_m=5.54", "field.divisions.B.width_m=3.77", "field.divisions.B.line_width_m=0.045",
       "field.divisions.B.center_circle_radius_m=0.4", "field.divisions.B.defense_width_m=1.6",
       "field.divisions.B.defense_depth_m=0.7", "field.ball.radius_m=0.042", "vision.patterns.min_dots=3",
       "vision.patterns.ids_in_play=[0,1,2,3,4,5]", "vision.light.follow=true",
       "sim.referee.formations.B=[[-2.3,0,0],[-1.8,0.8,0],[-1.8,-0.8,0],[-1.2,0,0],[-0.6,1.1,0],[-0.6,-1.1,0]]"]


def pose_errors(got: CameraParams, true: CameraParams) -> tuple[float, float]:
    r = CameraModel(got).R_cam_to_field.T @ CameraModel(true).R_cam_to_field
    angle = float(np.degrees(np.arccos(min(1.0, (float(np.trace(r)) - 1.0) / 2.0))))
    return float(np.linalg.norm(np.subtract(got.position_m, true.position_m))), angle


Lab = tuple[Settings, CameraModel, list[tuple[NDArray[np.uint8], GroundTruth]]]


@pytest.fixture(scope="module")
def lab() -> Lab:
    """The lab's settings, the true camera and the scripted game's 150 frames through it."""
    s = load_settings(None, LAB)
    (true,) = s.camera_models()
    sim = Simulator(s.field, [true], s.sim, seed=4, look=s.cameras.look())
    script = ScriptedPlay(Field(s.field), s.field.robot.radius_m, s.sim.script, sim.rng)
    frames = []
    for _ in range(150):
        frame = sim.capture()
        frames.append((frame.images[true.id], frame.truth))
        sim.advance(script.commands(sim.world.snapshot()))
    return s, true, frames


@pytest.mark.slow
def test_calibration_colours_and_detection_with_nothing_labelled(lab: Lab) -> None:
    s, true, frames = lab

    f = Field(s.field)
    hx, hy = f.boundary_half_length + 0.3, f.boundary_half_width + 0.3
    guess = CameraParams(id=0, resolution_px=(1280, 800), principal_point_px=(640.0, 400.0))
    fit = calibrate_from_lines(frames[0][0], s.field, rough_start(guess, float(true.center[2]), (-hx, -hy, hx, hy)))
    dist, angle = pose_errors(fit.params, true.params)
    assert dist < 0.01 and angle < 0.5
    assert abs(fit.rms_px - true_error_px(fit.params, true.params, s.field)) < 0.3
    model = CameraModel(fit.params)

    rep = auto_samples([frames[k][0] for k in range(0, 60, 6)], model, s.field, "yuv", s.vision.auto_tune)
    assert set(rep.samples) == {"ball", "blue", "yellow", "pink", "green"}
    boxes, _ = learn_boxes({getattr(s.vision.roles, r): v for r, v in rep.samples.items()}, rep.background,
                           {getattr(s.vision.roles, r): v for r, v in rep.light.items()}, s.vision.colours, "yuv",
                           saturation_reach=s.vision.light.saturation_reach)
    pipe = VisionPipeline(dataclasses.replace(s.vision, colours=boxes), s.field, model)
    score = Score()
    hidden_seen = hidden_found = 0
    team, rid, _ = s.cameras.realistic.hidden_dot
    for k, (image, truth) in enumerate(frames[60:]):
        det = pipe.process(image, k, 0.0)
        score.add(det, truth)
        if any(r.team == ("blue", "yellow")[team] and r.id == rid and model.id in r.pixels for r in truth.robots):
            hidden_seen += 1
            hidden_found += any(r.team == ("blue", "yellow")[team] and r.id == rid for r in det.robots)
    got = score.summary()
    assert got["robot_detection_rate"] >= 0.995 and got["id_accuracy"] == 1.0, got
    assert got["ball_detection_rate"] >= 0.99 and got["false_per_frame"] == 0.0, got
    assert hidden_seen > 0 and hidden_found >= 0.95 * hidden_seen


@pytest.mark.slow
def test_auto_samples_keep_each_class_on_its_hue(lab: Lab) -> None:
    """``tune --auto`` on the game's first second: a pink dot whose U is above grey's, taken for a
    blue centre dot (its ring of dots found round it), and an orange blob taken for a pink dot are
    left out by their hue, so no class's samples reach into another's side of grey. (Kept in,
    they stretched the blue box over V 38-218 and pink's down to U 27; cut apart, blue kept
    pink's fringe, V 146-164, and the carpet light follower lost blue robots: 97.8% found.)"""
    s, true, frames = lab
    rep = auto_samples([frames[k][0] for k in range(0, 60, 6)], true, s.field, "yuv", s.vision.auto_tune)
    pooled = {role: np.concatenate(parts) for role, parts in rep.samples.items()}
    # (role, channel, above grey): blue is U above and V below grey, yellow U below, the ball U below and
    # V above, pink V above, green both below (yellow's V and pink's U lie near grey's)
    sides = [("blue", 1, True), ("blue", 2, False), ("yellow", 1, False), ("ball", 1, False), ("ball", 2, True),
             ("pink", 2, True), ("green", 1, False), ("green", 2, False)]
    for role, c, above in sides:
        px = pooled[role][:, c]
        assert np.all(px > 128) if above else np.all(px < 128), (role, c, np.percentile(px, [0, 100]))
    assert sum(rep.left_out.values()) >= 1
