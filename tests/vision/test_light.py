"""Colour classes that follow the light (vision.yaml ``light``): gains per cell learnt from
confident detections only, over a lighting change the shipped boxes do not hold.

The change: the frames of one scene under a colour cast that grows frame by frame, to red-warm
light at 0.55 / 0.8 / 1.3 of blue / green / red, with a cast twice as strong on the image's right
half (uneven light). Tolerances: following, every robot is found with the right id in every frame;
without, under the full cast, at most half are (measured: 3 of 6).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from vision.light import BAND_PX, LightParams, gain_table
from vision.pipeline import VisionParams, VisionPipeline

from .conftest import LEAGUE, render, snapshot

ROBOTS = [[team, rid, x, y, 0.4 * rid + team] for k, (team, rid, x, y) in enumerate(
    [(0, 0, -3.4, 1.2), (0, 1, -2.6, -1.0), (0, 2, -1.6, 0.6), (1, 0, -3.0, -0.2), (1, 3, -2.0, -1.6),
     (1, 5, -1.0, 1.5)])]
FULL = np.array([0.55, 0.8, 1.3])  # per BGR channel at the end of the change


def cast(image: NDArray[np.uint8], share: float) -> NDArray[np.uint8]:
    """``image`` under ``share`` (0..1) of the change, twice as far along on the right half."""
    out = image.astype(np.float64)
    w = image.shape[1]
    left = 1.0 + share * 0.5 * (FULL - 1.0)
    right = 1.0 + share * (FULL - 1.0)
    out[:, : w // 2] *= left
    out[:, w // 2 :] *= right
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


def run(params: VisionParams, model: CameraModel, image: NDArray[np.uint8], frames: int) -> list[int]:
    """Robots found with the right id in each frame of the change."""
    pipe = VisionPipeline(params, LEAGUE, model)
    right = {(0 if r[0] == 0 else 1, r[1]) for r in ROBOTS}
    out = []
    for k in range(frames):
        det = pipe.process(cast(image, k / (frames - 1)), k, 0.0)
        out.append(sum((0 if r.team == "blue" else 1, r.id) in right for r in det.robots))
    return out


@pytest.fixture(scope="module")
def scene(cameras: list[CameraModel]) -> tuple[CameraModel, NDArray[np.uint8]]:
    model = cameras[0]
    image, _ = render(model, snapshot(ROBOTS))
    return model, image.copy()


def test_classes_follow_a_lighting_change(scene: tuple[CameraModel, NDArray[np.uint8]]) -> None:
    model, image = scene
    light = LightParams(follow=True, grid=(4, 3), rate=0.2, every_frames=1)
    following = dataclasses.replace(VisionParams(), light=light)
    got = run(following, model, image, 40)
    assert got == [len(ROBOTS)] * 40
    still = run(VisionParams(), model, image, 40)
    assert still[0] == len(ROBOTS) and still[-1] <= len(ROBOTS) / 2, still


def test_low_confidence_detections_teach_nothing(scene: tuple[CameraModel, NDArray[np.uint8]]) -> None:
    """Every detection below min_confidence: the gains stay 1 and the classes where they were."""
    model, image = scene
    params = dataclasses.replace(VisionParams(), light=LightParams(follow=True, min_confidence=1.0))
    pipe = VisionPipeline(params, LEAGUE, model)
    for k in range(5):
        pipe.process(cast(image, 0.2 * k), k, 0.0)
    assert pipe.light is not None and np.all(pipe.light.gains == 1.0)


@pytest.mark.parametrize("axis", ["across", "down"])
def test_gains_are_each_cells_at_its_centre_linear_between(axis: str) -> None:
    """Two cells along one axis with gains 0.6 and 1.8 (per channel scaled by 1, 0.9, 1.1): the
    table the classifier uses holds the first cell's gain up to its centre, the second's from its
    centre on, and the straight line between (down the image: at each band of rows' middle), each
    within the fixed point's rounding (1/256 and a half)."""
    width, height = (160, 24) if axis == "across" else (24, 160)
    cells = np.array([0.6, 1.8])[:, None] * np.array([1.0, 0.9, 1.1])  # (2, 3)
    gains = cells[None, :, :] if axis == "across" else cells[:, None, :]  # (rows, columns, 3)
    table, band = gain_table(gains, width, height)
    per_px = table[band].reshape(height, width, 3) / 256.0
    size = width if axis == "across" else height
    centres = np.array([0.25, 0.75]) * size
    if axis == "across":
        at, got = np.arange(width) + 0.5, per_px[0]
    else:
        middles = (np.arange(height) // BAND_PX * BAND_PX + np.minimum(np.arange(height) // BAND_PX * BAND_PX + BAND_PX,
                                                                      height)) / 2.0
        at, got = middles, per_px[:, 0]
    share = np.clip((at - centres[0]) / (centres[1] - centres[0]), 0.0, 1.0)
    expected = cells[0] + share[:, None] * (cells[1] - cells[0])
    assert np.max(np.abs(got - expected)) <= 1.5 / 256.0
    # uniform gains: the same scale everywhere, as a gain per cell had it
    flat, _ = gain_table(np.full((3, 4, 3), 1.25), width, height)
    assert np.all(flat == 320)


def test_follower_keeps_the_starting_gains_under_steady_light(cameras: list[CameraModel]) -> None:
    """Light uneven over the field (strong vignetting, half the light toward the -x goal) that does
    not change: started from the gains ``tune --auto`` measured, the follower (every frame, rate
    0.2) keeps them within 8% over 30 frames (measured: 5.2%, the markers brought to one colour
    each; a follower taking each marker's needed gain for its cell's, though the gains between
    cells' centres are interpolated, moved them 13.8%) and every robot stays found with its id."""
    from sim.render import RenderParams
    from vision.tune import auto_samples, learn_boxes

    model = cameras[0]
    look = RenderParams(vignetting_fraction=0.5, gradient_fraction=0.9, noise_sigma_grey=2.0)
    image, _ = render(model, snapshot(ROBOTS), look, seed=3)
    rep = auto_samples([image], model, LEAGUE, "yuv", light=LightParams())
    assert rep.gains is not None and rep.gains.max() / rep.gains.min() > 1.5
    names = {"ball": "orange", "blue": "blue", "yellow": "yellow", "pink": "pink", "green": "green"}
    boxes, _ = learn_boxes({names[r]: v for r, v in rep.samples.items()}, rep.background,
                           {names[r]: v for r, v in rep.light.items()}, VisionParams().colours, "yuv")
    light = LightParams(follow=True, rate=0.2, every_frames=1).with_start(rep.gains)
    pipe = VisionPipeline(dataclasses.replace(VisionParams(), colours=boxes, light=light), LEAGUE, model)
    right = {(0 if r[0] == 0 else 1, r[1]) for r in ROBOTS}
    for k in range(30):
        det = pipe.process(image, k, 0.0)
        assert {(0 if r.team == "blue" else 1, r.id) for r in det.robots} == right
    assert pipe.light is not None
    assert np.max(np.abs(pipe.light.gains / pipe.light.start - 1.0)) < 0.08
