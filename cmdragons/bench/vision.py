"""``cmdragons bench vision``: detection quality against the simulator's truth at three noise and
lighting levels, on compressed video and at 1920x1200, and the time per camera frame next to an
OpenCV baseline on the same frames.

Frames are rendered in-process (lossless) from a scripted Division B game, both default cameras.
The default level's frames are also encoded as H.264 in 4:2:0 (what ``cmdragons sim --record``
writes by default, at configs/cameras.yaml ``recording.crf``, and at crf 23, x264's default and
what most camera software writes) through :mod:`cmdragons.videoio`, decoded and scored on the
same truth, with the same configs. The 1920x1200 row renders the automatic camera layout at that
resolution (one camera over the whole field). Levels (RenderParams):

=========  ===========  ============  ==========  ==========
level      noise grey   vignetting    gradient    exposure
=========  ===========  ============  ==========  ==========
low        1.0          0.05          0.03        1 ms
default    configs/sim.yaml render (2.5, 0.12, 0.08, 2 ms)
high       6.0          0.25          0.15        4 ms
=========  ===========  ============  ==========  ==========

``ball_height_bias_mm``: how far above the height vision projects the ball's blobs at the truth
says they sit (:func:`vision.score.ball_height_bias_m`); the default level's value, added to
``ball.blob_height_above_centre_m`` in configs/vision.yaml, calibrates vision to the renderer.

Then a lab's camera (:mod:`cmdragons.bench.vision_lab`): the realistic preset under four lighting
conditions and the real lab frame, each calibrated and coloured automatically.

Baseline: ``cv2.cvtColor`` to YUV, then per colour class one ``cv2.inRange`` and one
``cv2.connectedComponentsWithStats`` -- the segmentation alone, with no pattern matching.
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, cameras_from_config
from cmdragons.geometry import Field
from cmdragons.messages import GroundTruth
from cmdragons.runtime.settings import Settings
from cmdragons.videoio import VideoWriter, read_video
from sim.render import RenderParams
from sim.script import ScriptedPlay
from sim.simulator import Simulator
from vision.pipeline import VisionPipeline
from vision.score import Score, ball_height_bias_m

__all__ = ["BIG_RESOLUTION", "LEVELS", "opencv_baseline", "run"]

Row = dict[str, Any]


def _levels(default: RenderParams) -> dict[str, RenderParams]:
    return {
        "low": dataclasses.replace(
            default, noise_sigma_grey=1.0, vignetting_fraction=0.05, gradient_fraction=0.03, exposure_s=0.001
        ),
        "default": default,
        "high": dataclasses.replace(
            default, noise_sigma_grey=6.0, vignetting_fraction=0.25, gradient_fraction=0.15, exposure_s=0.004
        ),
    }


LEVELS = ("low", "default", "high")
BIG_RESOLUTION = (1920, 1200)  # px, what the league's cameras deliver today


def opencv_baseline(image: NDArray[np.uint8], boxes: list[tuple[NDArray[np.uint8], NDArray[np.uint8]]]) -> int:
    """The segmentation an OpenCV user would write: YUV conversion, then per colour a mask and its
    connected components with statistics. Returns the number of components (to use the result)."""
    yuv = cv2.cvtColor(image, cv2.COLOR_BGR2YCrCb)
    n = 0
    for lo, hi in boxes:
        mask = cv2.inRange(yuv, lo, hi)
        count, _, _, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        n += count - 1
    return n


def _render(settings: Settings, models: list[CameraModel], render: RenderParams,
            frames: int) -> Iterator[tuple[int, dict[int, NDArray[np.uint8]], GroundTruth]]:
    """The scripted game's first ``frames`` frames through ``models``: (index, images, truth)."""
    sim_params = dataclasses.replace(settings.sim, render=render)
    sim = Simulator(settings.field, models, sim_params, seed=settings.sim.seed)
    script = ScriptedPlay(Field(settings.field), settings.field.robot.radius_m, sim_params.script, sim.rng)
    for i in range(frames):
        frame = sim.capture()
        yield i, frame.images, frame.truth
        sim.advance(script.commands(sim.world.snapshot()))


def _quality(name: str, settings: Settings, models: list[CameraModel], score: Score) -> Row:
    """The score's row; the ball height bias only with two cameras or more (one camera straight
    over the field's centre sees most balls near its nadir, where the fit has no lever)."""
    row: Row = {"name": name, **score.summary()}
    if len(models) > 1:
        bias = ball_height_bias_m(score, {m.id: m.center for m in models},
                                  settings.vision.ball.blob_height_above_centre_m)
        row["ball_height_bias_mm"] = bias * 1e3
    return row


def run(settings: Settings, quick: bool, frames: int | None = None, lab: bool = True) -> list[Row]:
    """Quality rows per level, per compressed input and at 1920x1200, then timing rows; ``frames``
    per input (default 40 quick, 300 full; 1920x1200: a quarter of that); then, with ``lab``, a
    lab's camera (:func:`cmdragons.bench.vision_lab.lab_rows`)."""
    frames = frames or (40 if quick else 300)
    models = settings.camera_models()
    rows: list[Row] = []
    samples: list[tuple[int, NDArray[np.uint8]]] = []
    crf = settings.cameras.recording.crf
    compressed = {f"h264 crf {crf} (sim --record default)": crf, "h264 crf 23 (4:2:0, x264 default)": 23}
    with tempfile.TemporaryDirectory(prefix="bench-vision-") as tmp:
        truths: list[GroundTruth] = []
        writers: dict[tuple[int, int], VideoWriter] = {}
        for level in LEVELS:
            pipes = {m.id: VisionPipeline(settings.vision, settings.field, m) for m in models}
            score = Score()
            for i, images, truth in _render(settings, models, _levels(settings.sim.render)[level], frames):
                for cam, image in images.items():
                    score.add(pipes[cam].process(image, i, 0.0), truth)
                    if level != "default":
                        continue
                    if i % max(1, frames // 20) == 0:
                        samples.append((cam, image.copy()))
                    for q in compressed.values():
                        if (q, cam) not in writers:
                            h, w = image.shape[:2]
                            writers[q, cam] = VideoWriter(Path(tmp) / f"{q}_{cam}.mp4", w, h, 60.0, "h264", q)
                        writers[q, cam].write(image)
                if level == "default":
                    truths.append(truth)
            rows.append(_quality(f"vision {level}", settings, models, score))
        for writer in writers.values():
            writer.close()
        for name, q in compressed.items():
            pipes = {m.id: VisionPipeline(settings.vision, settings.field, m) for m in models}
            score = Score()
            for m in models:
                for i, image in read_video(Path(tmp) / f"{q}_{m.id}.mp4"):
                    score.add(pipes[m.id].process(image, i, 0.0), truths[i])
            rows.append(_quality(f"vision default, {name}", settings, models, score))
    big_models = _big_cameras(settings)
    big_pipes = {m.id: VisionPipeline(settings.vision, settings.field, m) for m in big_models}
    big_samples: list[tuple[int, NDArray[np.uint8]]] = []
    big_score = Score()
    big_frames = max(2, frames // 4)
    for i, images, truth in _render(settings, big_models, settings.sim.render, big_frames):
        for cam, image in images.items():
            big_score.add(big_pipes[cam].process(image, i, 0.0), truth)
            if i % max(1, big_frames // 10) == 0:
                big_samples.append((cam, image.copy()))
    w, h = big_models[0].width, big_models[0].height
    rows.append(_quality(f"vision default, {w}x{h} ({len(big_models)} camera{'s' * (len(big_models) > 1)})",
                         settings, big_models, big_score))
    reps = 3 if quick else 10
    rows += _timing(settings, {m.id: VisionPipeline(settings.vision, settings.field, m) for m in models}, samples,
                    reps)
    rows += _timing(settings, big_pipes, big_samples, reps)
    if lab:
        from cmdragons.bench.vision_lab import lab_rows  # a lab's camera: the realistic preset, the real frame

        rows += lab_rows(settings, quick)
    return rows


def _big_cameras(settings: Settings) -> list[CameraModel]:
    """The automatic layout with today's league resolution, 1920x1200 (over a Division B field: one
    camera at the configured height sees it all, the ball still 6 px across)."""
    auto = dataclasses.replace(settings.cameras.auto, resolution_px=BIG_RESOLUTION)
    return cameras_from_config(dataclasses.replace(settings.cameras, layout="auto", auto=auto), settings.field)


def _timing(settings: Settings, pipes: dict[int, VisionPipeline], samples: list[tuple[int, NDArray[np.uint8]]],
            reps: int) -> list[Row]:
    """Median and 95th percentile of the time per camera frame, all methods on the same frames: each
    method over all the frames in turn, round after round, so that a busy machine slows them alike.
    Each frame is first delivered into the input buffer, untimed, as a camera's capture, a video
    decoder or the simulator's renderer writes it just before vision reads it (neither left cold by
    the other frames nor by another method's temporaries)."""
    vis = settings.vision
    if vis.colour_space != "yuv":
        raise ValueError("the OpenCV baseline uses YUV boxes: run the bench with colour_space yuv")
    # OpenCV's YCrCb holds V before U
    boxes = [(np.array([c.lo[0], c.lo[2], c.lo[1]], np.uint8), np.array([c.hi[0], c.hi[2], c.hi[1]], np.uint8))
             for c in vis.colours.values()]
    methods: dict[str, Callable[[int, NDArray[np.uint8]], object]] = {
        "cmvision + patterns": lambda cam, image: pipes[cam].process(image, 0, 0.0),
        "cmvision regions": lambda cam, image: pipes[cam].segmenter.regions(image),
        "opencv baseline": lambda _cam, image: opencv_baseline(image, boxes),
    }
    times: dict[str, list[float]] = {name: [] for name in methods}
    for cam, image in samples:  # warm-up: numba compilation or cache load
        pipes[cam].process(image, 0, 0.0)
    frame = np.empty_like(samples[0][1])
    for _ in range(reps):
        for name, method in methods.items():
            for cam, image in samples:
                np.copyto(frame, image)
                t0 = time.perf_counter()
                method(cam, frame)
                times[name].append((time.perf_counter() - t0) * 1e3)
    base = float(np.median(times["opencv baseline"]))
    h, w = samples[0][1].shape[:2]
    return [
        {"name": f"{name} ({w}x{h})", "median_ms": float(np.median(v)), "p95_ms": float(np.percentile(v, 95)),
         "ratio_to_opencv": float(np.median(v)) / base, "speedup_vs_opencv": base / float(np.median(v))}
        for name, v in times.items()
    ]
