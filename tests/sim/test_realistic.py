"""The realistic camera preset (cameras.yaml ``preset: realistic``): deterministic per seed, the
lab's light drifting and followed by auto exposure, a dot taped over, the floor past the field with
orange-ish things on it, and the strong barrel distortion of the camera model.

Small frames (640x400) keep it quick; tolerances are stated where a figure is compared."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from cmdragons.camera import AutoLayout, CamerasParams, RealisticParams, cameras_from_config
from cmdragons.geometry import Field, LeagueParams
from sim.render import CameraRenderer, Lighting, RenderParams
from sim.snapshot import Snapshot

LEAGUE = LeagueParams()
LOOK = RealisticParams(resolution_px=(640, 400))
CAMERAS = CamerasParams(auto=AutoLayout(grid=(1, 1)), preset="realistic", realistic=LOOK)  # one camera


def snap(t: float, robots: list[tuple[float, ...]]) -> Snapshot:
    rows = np.zeros((len(robots), 8))
    for k, r in enumerate(robots):
        rows[k, : len(r)] = r
    return Snapshot(t=t, frame_number=round(t * 60), ball=np.array([0.5, 0.3, LEAGUE.ball.radius_m, 0, 0, 0]),
                    robots=rows)


ROBOTS = [(0, 2, -1.0, 0.5, 0.3), (1, 4, 1.2, -0.8, -1.0)]


def renderer(seed: int, look: RealisticParams = LOOK) -> CameraRenderer:
    model = cameras_from_config(dataclasses.replace(CAMERAS, realistic=look), LEAGUE)[0]
    return CameraRenderer(model, LEAGUE, RenderParams(), seed=seed, lighting=Lighting(LEAGUE, look, seed))


def test_preset_takes_the_strong_distortion_and_resolution() -> None:
    (model,) = cameras_from_config(CAMERAS, LEAGUE)
    assert (model.width, model.height) == (640, 400)
    assert (model.k1, model.k2) == (LOOK.k1, LOOK.k2)
    plain = cameras_from_config(CamerasParams(), LEAGUE)
    assert all(m.k1 == CamerasParams().auto.k1 for m in plain)


@pytest.mark.parametrize("codec", ["jpeg", "h264"])
def test_same_seed_same_frames(codec: str) -> None:
    look = dataclasses.replace(LOOK, codec=codec)
    frames = []
    for _ in range(2):
        r = renderer(5, look)
        frames.append([r.render(snap(k / 60.0, ROBOTS))[0].copy() for k in range(3)])
    assert all(np.array_equal(a, b) for a, b in zip(*frames, strict=True))
    other = renderer(6, look).render(snap(0.0, ROBOTS))[0]
    assert not np.array_equal(frames[0][0], other)


def test_light_drifts_and_auto_exposure_follows() -> None:
    """With the lamps and daylight wandering by half, the carpet's brightness in the middle moves
    less than the light does: auto exposure steers the mean back (within 15% of its target)."""
    look = dataclasses.replace(LOOK, lamp_drift_fraction=0.5, daylight_drift_fraction=0.5, lamp_drift_period_s=4.0,
                               daylight_drift_period_s=4.0, codec="none")
    r = renderer(3, look)
    lighting = r.look.lighting if r.look is not None else None
    assert lighting is not None
    levels, lumas = [], []
    for k in range(0, 240, 4):
        t = k / 60.0
        lamps, day = lighting.weights(t)
        levels.append(float(lamps.sum() + day))
        img = r.render(snap(t, ROBOTS))[0].astype(np.float64)
        lumas.append(float(np.mean(0.114 * img[..., 0] + 0.587 * img[..., 1] + 0.299 * img[..., 2])))
    assert (max(levels) - min(levels)) / np.mean(levels) > 0.3
    assert all(abs(v - look.exposure_target_grey) < 0.15 * look.exposure_target_grey for v in lumas[5:])


def test_hidden_dot_and_floor_clutter() -> None:
    look = dataclasses.replace(LOOK, codec="none", specular_grey=0.0)
    r = renderer(2, look)
    img = r.render(snap(0.0, ROBOTS))[0]
    model = r.model
    # the taped-over dot is as dark as the cover; the others are bright
    x, y, th = ROBOTS[0][2:5]
    c, s = np.cos(th), np.sin(th)
    dots = LEAGUE.pattern.dot_positions_m
    lumas = []
    for k in range(4):
        dx, dy = dots[k]
        px = model.project_xy(np.array([x + c * dx - s * dy, y + s * dx + c * dy]), LEAGUE.robot.height_m)
        lumas.append(float(np.mean(img[int(px[1]), int(px[0])])))
    team, rid, dot = look.hidden_dot
    assert ROBOTS[0][:2] == (team, rid)
    hidden = lumas.pop(dot)
    assert hidden < 70.0 and min(lumas) > hidden + 60.0, (hidden, lumas)  # the cover: about 45 here
    # past the boundary: the wooden floor, and orange-ish things on it (red above blue by far)
    f = Field(LEAGUE)
    ground = model.center[:2] + model.center[2] * model.pixel_rays_grid().astype(np.float64)
    outside = (np.abs(ground[..., 0]) > f.boundary_half_length + 0.05) | (
        np.abs(ground[..., 1]) > f.boundary_half_width + 0.05
    )
    assert outside.mean() > 0.05
    b, g, red = (img[..., k][outside].astype(int) for k in range(3))
    assert np.mean(red > b + 20) > 0.8  # the floor is wood, warm
    clutter = (red > 1.6 * g) & (red > 120)
    assert clutter.sum() > 20
