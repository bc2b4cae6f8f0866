"""``cmdragons bench vision``: detection quality against the simulator's truth at three noise and
lighting levels, and the time per camera frame next to an OpenCV baseline on the same frames.

Frames are rendered in-process (lossless; a video codec would smear the colours) from a scripted
Division B game, both default cameras. Levels (RenderParams):

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

Baseline: ``cv2.cvtColor`` to YUV, then per colour class one ``cv2.inRange`` and one
``cv2.connectedComponentsWithStats`` -- the segmentation alone, with no pattern matching.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.geometry import Field
from cmdragons.runtime.settings import Settings
from sim.render import RenderParams
from sim.script import ScriptedPlay
from sim.simulator import Simulator
from vision.pipeline import VisionPipeline
from vision.score import Score, ball_height_bias_m

__all__ = ["LEVELS", "opencv_baseline", "run"]

Row = dict[str, Any]


def _levels(default: RenderParams) -> dict[str, RenderParams]:
    return {
        "low": dataclasses.replace(
            default, noise_sigma_grey=1.0, vignetting_fraction=0.05, gradient_fraction=0.03, exposure_s=0.001
        ),  # fmt: skip
        "default": default,
        "high": dataclasses.replace(
            default, noise_sigma_grey=6.0, vignetting_fraction=0.25, gradient_fraction=0.15, exposure_s=0.004
        ),  # fmt: skip
    }


LEVELS = ("low", "default", "high")


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


def run(settings: Settings, quick: bool, frames: int | None = None) -> list[Row]:
    """Quality rows per level, then timing rows; ``frames`` per level (default 40 quick, 300 full)."""
    frames = frames or (40 if quick else 300)
    models = settings.camera_models()
    rows: list[Row] = []
    samples: list[tuple[int, NDArray[np.uint8]]] = []
    for level in LEVELS:
        sim_params = dataclasses.replace(settings.sim, render=_levels(settings.sim.render)[level])
        sim = Simulator(settings.field, models, sim_params, seed=settings.sim.seed)
        script = ScriptedPlay(Field(settings.field), settings.field.robot.radius_m, sim_params.script, sim.rng)
        pipes = {m.id: VisionPipeline(settings.vision, settings.field, m) for m in models}
        score = Score()
        for i in range(frames):
            frame = sim.capture()
            for cam, image in frame.images.items():
                score.add(pipes[cam].process(image, frame.frame_number, frame.t_capture), frame.truth)
                if level == "default" and i % max(1, frames // 20) == 0:
                    samples.append((cam, image.copy()))
            sim.advance(script.commands(sim.world.snapshot()))
        bias = ball_height_bias_m(score, {m.id: m.center for m in models},
                                  settings.vision.ball.blob_height_above_centre_m)  # fmt: skip
        rows.append({"name": f"vision {level}", **score.summary(), "ball_height_bias_mm": bias * 1e3})
    rows += _timing(settings, {m.id: VisionPipeline(settings.vision, settings.field, m) for m in models}, samples,
                    reps=3 if quick else 10)  # fmt: skip
    return rows


def _timing(settings: Settings, pipes: dict[int, VisionPipeline], samples: list[tuple[int, NDArray[np.uint8]]],
            reps: int) -> list[Row]:  # fmt: skip
    """Median and 95th percentile of the time per camera frame, all methods on the same frames,
    interleaved so that a busy machine slows them alike."""
    vis = settings.vision
    if vis.colour_space != "yuv":
        raise ValueError("the OpenCV baseline uses YUV boxes: run the bench with colour_space yuv")
    # OpenCV's YCrCb holds V before U
    boxes = [(np.array([c.lo[0], c.lo[2], c.lo[1]], np.uint8), np.array([c.hi[0], c.hi[2], c.hi[1]], np.uint8))
             for c in vis.colours.values()]  # fmt: skip
    times: dict[str, list[float]] = {"cmvision + patterns": [], "cmvision regions": [], "opencv baseline": []}
    for cam, image in samples:  # warm-up: numba compilation or cache load
        pipes[cam].process(image, 0, 0.0)
    for _ in range(reps):
        for cam, image in samples:
            t0 = time.perf_counter()
            pipes[cam].process(image, 0, 0.0)
            t1 = time.perf_counter()
            pipes[cam].segmenter.regions(image)
            t2 = time.perf_counter()
            opencv_baseline(image, boxes)
            t3 = time.perf_counter()
            times["cmvision + patterns"].append((t1 - t0) * 1e3)
            times["cmvision regions"].append((t2 - t1) * 1e3)
            times["opencv baseline"].append((t3 - t2) * 1e3)
    base = float(np.median(times["opencv baseline"]))
    h, w = samples[0][1].shape[:2]
    return [
        {"name": f"{name} ({w}x{h})", "median_ms": float(np.median(v)), "p95_ms": float(np.percentile(v, 95)),
         "ratio_to_opencv": float(np.median(v)) / base, "speedup_vs_opencv": base / float(np.median(v))}
        for name, v in times.items()
    ]  # fmt: skip
