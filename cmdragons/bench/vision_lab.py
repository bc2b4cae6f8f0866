"""``cmdragons bench vision``, a lab's camera: the realistic preset (configs/cameras.yaml ``realistic``)
and the real lab frame of ``../shared/realdata``, each calibrated and coloured automatically with
nothing labelled.

Realistic rows: a scripted Division B game seen by the realistic camera (one 1920x1200 camera over
the whole field, strong barrel distortion, JPEG) over a lab's field.yaml (84 mm balls, 45 mm tape)
under four lighting conditions (:data:`CONDITIONS`). The camera is calibrated from the lines of the
first condition's first frame (from a rough start: the height and the rectangle it roughly sees),
its colours learnt by ``tune --auto`` from that condition's first seconds; then each condition is
scored against the truth with that camera and those colours, unchanged, and again with colours
learnt on the condition's own first seconds. A lab's vision.yaml knows its covers: three dots of
four read, ``patterns.ids_in_play`` the ids on the field; the classes follow the light
(``light.follow``).

Calibration row: the line fit's reported error beside its error against the true line centres,
the pose error, and the wrong fields and the wrong frame size refused.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, CameraParams, RealisticParams
from cmdragons.geometry import BallShape, Field, FieldDims, LeagueParams
from cmdragons.messages import GroundTruth
from cmdragons.runtime.settings import Settings
from sim.script import ScriptedPlay
from sim.simulator import Simulator
from vision.field_lines import CalibrationRefused, LineCalibration, calibrate_from_lines, rough_start, true_error_px
from vision.pipeline import VisionParams, VisionPipeline
from vision.score import Score
from vision.tune import auto_samples, learn_boxes

__all__ = ["CONDITIONS", "LAB_BALL_RADIUS_M", "LAB_LINE_WIDTH_M", "REALDATA", "lab_rows"]

Row = dict[str, Any]

LAB_BALL_RADIUS_M = 0.042  # a common lab ball, 84 mm
LAB_LINE_WIDTH_M = 0.045  # tape
REALDATA = Path(__file__).resolve().parents[3] / "shared" / "realdata"
LEARN_S = 2.0  # the first seconds colours are learnt from
LEARN_FRAMES = 10  # frames spread over them

# name -> what changes from configs/cameras.yaml realistic
CONDITIONS: dict[str, dict[str, Any]] = {
    "lamps": {},
    "daylight": {"lamp_level": 0.3, "daylight_level": 1.2},
    "dim": {"lamp_level": 0.45, "daylight_level": 0.0},
    "drifting": {"lamp_drift_fraction": 0.4, "lamp_drift_period_s": 6.0, "daylight_level": 0.8,
                 "daylight_drift_fraction": 0.5, "daylight_drift_period_s": 4.0},
}  # fmt: skip


def _lab_settings(settings: Settings) -> Settings:
    """The settings with the realistic camera over a lab's field.yaml (its ball and tape), and a
    lab's vision.yaml: three dots of four read among the ids on the field, classes following the light."""
    league = settings.field
    dims = dataclasses.replace(league.dims, line_width_m=LAB_LINE_WIDTH_M)
    league = dataclasses.replace(league, divisions={**league.divisions, league.division: dims},
                                 ball=dataclasses.replace(league.ball, radius_m=LAB_BALL_RADIUS_M))
    ids = tuple(range(dims.robots_per_team))
    pat = dataclasses.replace(settings.vision.patterns, min_dots=3, ids_in_play=ids)
    light = dataclasses.replace(settings.vision.light, follow=True)
    cameras = dataclasses.replace(settings.cameras, preset="realistic")
    return dataclasses.replace(settings, field=league, cameras=cameras,
                               vision=dataclasses.replace(settings.vision, patterns=pat, light=light))


def _frames(settings: Settings, look: RealisticParams, n: int) -> Iterator[tuple[NDArray[np.uint8], GroundTruth]]:
    """The scripted game's first ``n`` frames through the realistic camera ``look``."""
    cams = dataclasses.replace(settings.cameras, realistic=look)
    models = dataclasses.replace(settings, cameras=cams).camera_models()
    sim = Simulator(settings.field, models[:1], settings.sim, seed=settings.sim.seed, look=look)
    script = ScriptedPlay(Field(settings.field), settings.field.robot.radius_m, settings.sim.script, sim.rng)
    for _ in range(n):
        frame = sim.capture()
        yield frame.images[models[0].id], frame.truth
        sim.advance(script.commands(sim.world.snapshot()))


def _rough_start(width: int, height: int, league: LeagueParams, height_m: float) -> CameraParams:
    """What a user tells the line fit: the camera's height and that it sees the field and its boundary."""
    f = Field(league)
    base = CameraParams(id=0, resolution_px=(width, height), principal_point_px=(width / 2.0, height / 2.0))
    hx, hy = f.boundary_half_length + 0.3, f.boundary_half_width + 0.3
    return rough_start(base, height_m, (-hx, -hy, hx, hy))


def _colours(settings: Settings, images: Sequence[NDArray[np.uint8]], model: CameraModel) -> VisionParams:
    """vision.yaml with every colour learnt by ``tune --auto`` from ``images``."""
    vis = settings.vision
    rep = auto_samples(images, model, settings.field, vis.colour_space, vis.auto_tune)
    names = {role: getattr(vis.roles, role) for role in ("ball", "blue", "yellow", "pink", "green")}
    boxes, _ = learn_boxes({names[r]: v for r, v in rep.samples.items()}, rep.background,
                           {names[r]: v for r, v in rep.light.items()}, vis.colours, vis.colour_space,
                           saturation_reach=vis.light.saturation_reach, max_overlap=vis.auto_tune.max_overlap)
    return dataclasses.replace(vis, colours=boxes)


def _pose_errors(got: CameraParams, true: CameraParams) -> tuple[float, float]:
    """Position error (m) and the angle (degrees) of the rotation between the two orientations."""
    r = CameraModel(got).R_cam_to_field.T @ CameraModel(true).R_cam_to_field
    angle = math.degrees(math.acos(min(1.0, (float(np.trace(r)) - 1.0) / 2.0)))
    return float(np.linalg.norm(np.subtract(got.position_m, true.position_m))), angle


def _refused(image: NDArray[np.uint8], league: LeagueParams, height_m: float) -> tuple[int, int]:
    """(refused, tried): the line fit on ``image`` with a field 12% too long, one 12% too wide,
    one whose centre circle is 20% too big, and on the frame cut to another aspect ratio. (A
    field.yaml that leaves out a line the image shows, its centre circle say, is no wrong field:
    the fit to the lines it names is right, and taken.)"""
    dims = league.dims
    wrong = [dataclasses.replace(dims, length_m=dims.length_m * 1.12),
             dataclasses.replace(dims, width_m=dims.width_m * 1.12),
             dataclasses.replace(dims, center_circle_radius_m=dims.center_circle_radius_m * 1.2)]
    refused = 0
    h, w = image.shape[:2]
    for d in wrong:
        lg = dataclasses.replace(league, divisions={**league.divisions, league.division: d})
        try:
            calibrate_from_lines(image, lg, _rough_start(w, h, lg, height_m))
        except (CalibrationRefused, ValueError):
            refused += 1
    cut = np.ascontiguousarray(image[:, : w - w // 5])  # another aspect than the camera's
    try:
        calibrate_from_lines(cut, league, _rough_start(w, h, league, height_m))
    except (CalibrationRefused, ValueError):
        refused += 1
    return refused, len(wrong) + 1


def _score(vis: VisionParams, league: LeagueParams, model: CameraModel,
           frames: Sequence[tuple[NDArray[np.uint8], GroundTruth]]) -> Score:
    pipe = VisionPipeline(vis, league, model)
    score = Score()
    for k, (image, truth) in enumerate(frames):
        score.add(pipe.process(image, k, 0.0), truth)
    return score


def _quality(name: str, score: Score) -> Row:
    s = score.summary()
    keys = ("robot_detection_rate", "id_accuracy", "ball_detection_rate", "false_per_frame", "robot_rms_mm",
            "ball_rms_mm", "camera_frames")
    return {"name": name, **{k: s[k] for k in keys}}


def lab_rows(settings: Settings, quick: bool) -> list[Row]:
    """The realistic preset's rows (four lighting conditions, calibration, time per frame) and the
    real lab frame's."""
    lab = _lab_settings(settings)
    fps = settings.sim.physics.frame_rate_hz
    n = 90 if quick else 360
    learn = [int(k) for k in np.linspace(0, min(n, int(LEARN_S * fps)) - 1, LEARN_FRAMES)]
    base = lab.cameras.realistic
    rendered = {name: list(_frames(lab, dataclasses.replace(base, **change), n)) for name, change in CONDITIONS.items()}
    first = rendered[next(iter(CONDITIONS))]
    true_model = lab.camera_models()[0]
    image = first[0][0]
    h, w = image.shape[:2]
    height_m = float(true_model.center[2])
    fit: LineCalibration = calibrate_from_lines(image, lab.field, _rough_start(w, h, lab.field, height_m))
    model = CameraModel(fit.params)
    dist, angle = _pose_errors(fit.params, true_model.params)
    refused, tried = _refused(image, lab.field, height_m)
    rows: list[Row] = [{"name": "realistic calibration from the lines", "reported_rms_px": fit.rms_px,
                        "true_rms_px": true_error_px(fit.params, true_model.params, lab.field),
                        "position_error_mm": dist * 1e3, "angle_error_deg": angle, "wrong_refused": refused,
                        "wrong_tried": tried}]
    fixed = _colours(lab, [first[k][0] for k in learn], model)
    for name, frames in rendered.items():
        rows.append(_quality(f"realistic {name}, all from lamps' first {LEARN_S:g} s", _score(fixed, lab.field, model,
                                                                                               frames)))
    for name, frames in rendered.items():
        own = _colours(lab, [frames[k][0] for k in learn], model)
        rows.append(_quality(f"realistic {name}, colours learnt on it", _score(own, lab.field, model, frames)))
    rows.append(_timing(fixed, lab.field, model, [f for f, _ in first[:: max(1, n // 30)]], 3 if quick else 10))
    rows.append(_real_frame_row(settings))
    return rows


def _timing(vis: VisionParams, league: LeagueParams, model: CameraModel, images: Sequence[NDArray[np.uint8]],
            reps: int) -> Row:
    """Wall time per frame, and the CPU time of the process per frame (all its threads: the
    classification's bands run on ``regions.threads``), which a machine shared with other jobs
    stretches less than the wall time."""
    pipe = VisionPipeline(vis, league, model)
    pipe.process(images[0], 0, 0.0)  # numba compilation or cache load
    frame = np.empty_like(images[0])
    times, cpu = [], []
    for _ in range(reps):
        for image in images:
            np.copyto(frame, image)
            t0, c0 = time.perf_counter(), time.process_time()
            pipe.process(frame, 0, 0.0)
            times.append((time.perf_counter() - t0) * 1e3)
            cpu.append((time.process_time() - c0) * 1e3)
    return {"name": f"realistic cmvision + patterns ({model.width}x{model.height})",
            "median_ms": float(np.median(times)),
            "p95_ms": float(np.percentile(times, 95)),
            "cpu_median_ms": float(np.median(cpu))}


def _real_frame_row(settings: Settings) -> Row:
    """The real lab frame calibrated from its lines and coloured by ``tune --auto``, nothing labelled,
    scored against its hand-checked truth: covers with the right id (of six), balls found on the
    field (of the two on the carpet or in the goal; the third, tan one, is also counted when found),
    and detections with no true object near them (within 10 px). Skipped with its reason when the
    frame is not there."""
    frame = REALDATA / "lab_frame_lights_on.jpg"
    name = "real lab frame (../shared/realdata), nothing labelled"
    if not frame.exists():
        return {"name": name, "skipped": f"the real lab frame is not here ({frame})"}
    image = np.asarray(cv2.imread(str(frame), cv2.IMREAD_COLOR), dtype=np.uint8)
    truth = json.loads((REALDATA / "ground_truth.json").read_text())[frame.name]
    # the lab's field.yaml: a 5.54 x 3.77 m field between walls, no centre circle, 84 mm balls; its
    # vision.yaml: the covers' ids 0-7, three dots of four read, several balls
    lab = FieldDims(length_m=5.54, width_m=3.77, boundary_width_m=0.0, goal_width_m=1.0, defense_width_m=2.0,
                    defense_depth_m=1.0, center_circle=False, goal_to_goal_line=False, outer_lines="walls")
    league = dataclasses.replace(settings.field, divisions={**settings.field.divisions, "B": lab}, division="B",
                                 ball=BallShape(radius_m=LAB_BALL_RADIUS_M))
    h, w = image.shape[:2]
    start = rough_start(CameraParams(id=0, resolution_px=(w, h), principal_point_px=(w / 2, h / 2)), 4.0,
                        (-3.45, -1.94, 3.45, 1.94))
    model = CameraModel(calibrate_from_lines(image, league, start).params)
    vis = settings.vision
    vis = dataclasses.replace(vis, patterns=dataclasses.replace(vis.patterns, min_dots=3, ids_in_play=tuple(range(8))),
                              ball=dataclasses.replace(vis.ball, max_balls=4))
    vis = _colours(dataclasses.replace(settings, field=league, vision=vis), [image], model)
    det = VisionPipeline(vis, league, model).process(image, 0, 0.0)
    near = 10.0

    def close(a: Sequence[float], b: Sequence[float]) -> bool:
        return math.hypot(a[0] - b[0], a[1] - b[1]) < near

    right = sum(any(r.id == t["id"] and close(r.pixel, t["pixel"]) for r in det.robots) for t in truth["robots"])
    false_robots = sum(not any(close(r.pixel, t["pixel"]) for t in truth["robots"]) for r in det.robots)
    balls = truth["balls"]
    found = sum(any(close(b.pixel, t["pixel"]) for b in det.balls) for t in balls)
    false_balls = sum(not any(close(b.pixel, t["pixel"]) for t in balls) for b in det.balls)
    return {"name": name, "covers_right": right, "covers": len(truth["robots"]), "balls_found": found,
            "balls": len(balls), "false_robots": false_robots, "false_balls": false_balls}

