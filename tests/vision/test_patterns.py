"""Pattern kernels against their numpy references, and pattern matching corner cases."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest

from cmdragons.camera import CameraModel
from cmdragons.geometry import TEAMS
from vision import _kernels as kern
from vision.patterns import fit_reference
from vision.pipeline import VisionParams, VisionPipeline

from .conftest import LEAGUE, render, snapshot


@pytest.mark.parametrize("z", [0.0, 0.0215, 0.15])
def test_region_rays_equal_camera_unproject(cameras: list[CameraModel], z: float) -> None:
    model = cameras[0]
    rng = np.random.default_rng(0)
    px = rng.uniform([1.0, 1.0], [model.width - 1.0, model.height - 1.0], size=(200, 2))
    rays, area = kern.region_rays(model.pixel_rays_grid(), px)
    xy = model.center[:2] + (model.center[2] - z) * rays
    np.testing.assert_allclose(xy, model.unproject(px, z), atol=2e-6)  # metres
    # one pixel's field area against the unprojected pixel square
    du = model.unproject(px + [0.5, 0.0], z) - model.unproject(px - [0.5, 0.0], z)
    dv = model.unproject(px + [0.0, 0.5], z) - model.unproject(px - [0.0, 0.5], z)
    np.testing.assert_allclose(area * (model.center[2] - z) ** 2, np.abs(du[:, 0] * dv[:, 1] - du[:, 1] * dv[:, 0]),
                               rtol=2e-3)  # fmt: skip


@pytest.mark.parametrize("seed", range(4))
def test_fit_kernel_equals_numpy_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    slots = np.array(LEAGUE.pattern.dot_positions_m)
    theta, x, y = rng.uniform(-math.pi, math.pi), *rng.uniform(-3, 3, 2)
    c, s = math.cos(theta), math.sin(theta)
    obs = slots @ np.array([[c, s], [-s, c]]) + [x, y] + rng.normal(0, 0.002, (4, 2))
    centre = np.array([x, y]) + rng.normal(0, 0.002, 2)
    w = rng.uniform(0.5, 1.5, 4)
    perms = np.array(list(itertools.permutations(range(4))))
    t_ref, p_ref, r_ref = fit_reference(centre, 1.2, obs, w, slots[perms])
    for a in range(len(perms)):
        got = kern.fit_pattern(centre, 1.2, obs, w, slots[perms[a]])
        np.testing.assert_allclose(got, (t_ref[a], p_ref[a, 0], p_ref[a, 1], r_ref[a]), atol=1e-12)
    best = int(np.argmin(r_ref))
    assert best == 0  # the identity assignment fits
    assert abs(math.remainder(t_ref[best] - theta, 2 * math.pi)) < 0.1
    assert math.hypot(p_ref[best, 0] - x, p_ref[best, 1] - y) < 0.005


def test_a_missed_dot_is_read_from_the_image_with_three_dots(cameras: list[CameraModel]) -> None:
    model = cameras[0]
    xy = model.unproject(np.array([[500.0, 400.0]]), LEAGUE.robot.height_m)[0]
    robots = [[1, rid, xy[0] + 0.3 * (rid % 4), xy[1] + 0.3 * (rid // 4), 0.5 + rid] for rid in range(16)]
    image, _ = render(model, snapshot(robots))
    # shrink robot 5's front-left dot to its central 3 x 3 pixels: too small for a region
    _, _, x, y, th = robots[5]
    sx, sy = LEAGUE.pattern.dot_positions_m[0]
    u, v = model.project_xy(np.array([x + math.cos(th) * sx - math.sin(th) * sy,
                                      y + math.sin(th) * sx + math.cos(th) * sy]), LEAGUE.robot.height_m)  # fmt: skip
    i, j = int(v), int(u)
    keep = image[i - 1 : i + 2, j - 1 : j + 2].copy()
    image[i - 5 : i + 6, j - 5 : j + 6] = (28, 28, 28)  # the matte-black cover
    image[i - 1 : i + 2, j - 1 : j + 2] = keep
    strict = VisionPipeline(VisionParams(), LEAGUE, model).process(image, 0, 0.0)
    assert sorted(r.id for r in strict.robots) == [k for k in range(16) if k != 5]
    params = VisionParams(patterns=dataclasses.replace(VisionParams().patterns, min_dots=3))
    loose = VisionPipeline(params, LEAGUE, model).process(image, 0, 0.0)
    assert sorted(r.id for r in loose.robots) == list(range(16))
    five = next(r for r in loose.robots if r.id == 5)
    assert math.hypot(five.x - x, five.y - y) < 0.005 and five.team == TEAMS[1]
    assert five.confidence <= 0.5
