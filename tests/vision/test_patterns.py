"""Pattern kernels against their numpy references, and pattern matching corner cases."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.geometry import TEAMS
from vision import _kernels as kern
from vision.patterns import ball_centre_reference, fit_reference
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
                               rtol=2e-3)


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
        # the trigonometry-free score that ranks assignments: the squared residual sum less the
        # observations' spread about their weighted mean (the same for every assignment)
        w_all, o = np.concatenate([[1.2], w]), np.vstack([centre, obs])
        spread = float(w_all @ ((o - w_all @ o / w_all.sum()) ** 2).sum(axis=1))
        score = kern.fit_score(centre, 1.2, obs, w, slots[perms[a]])
        assert score + spread == pytest.approx(r_ref[a] ** 2 * w_all.sum(), abs=1e-12)
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
                                      y + math.sin(th) * sx + math.cos(th) * sy]), LEAGUE.robot.height_m)
    i, j = int(v), int(u)
    keep = image[i - 1 : i + 2, j - 1 : j + 2].copy()
    image[i - 5 : i + 6, j - 5 : j + 6] = (28, 28, 28)  # the matte-black cover
    image[i - 1 : i + 2, j - 1 : j + 2] = keep
    four = VisionParams(patterns=dataclasses.replace(VisionParams().patterns, min_dots=4))
    strict = VisionPipeline(four, LEAGUE, model).process(image, 0, 0.0)
    assert sorted(r.id for r in strict.robots) == [k for k in range(16) if k != 5]
    params = VisionParams(patterns=dataclasses.replace(VisionParams().patterns, min_dots=3))
    loose = VisionPipeline(params, LEAGUE, model).process(image, 0, 0.0)
    assert sorted(r.id for r in loose.robots) == list(range(16))
    five = next(r for r in loose.robots if r.id == 5)
    assert math.hypot(five.x - x, five.y - y) < 0.005 and five.team == TEAMS[1]
    assert five.confidence <= 0.5
    # through 4:2:0 (H.264's chroma), the missed dot's colour is still read right from its mean
    from cmdragons.videoio import bgr_to_i420, i420_to_bgr

    h, w = image.shape[:2]
    got = VisionPipeline(params, LEAGUE, model).process(i420_to_bgr(bgr_to_i420(image), h, w), 0, 0.0)
    assert next(r for r in got.robots if r.id == 5).confidence <= 0.5  # found with three dots
    assert sorted(r.id for r in got.robots) == list(range(16))


def _disc_image(centre: tuple[float, float], radius_px: float, rng: np.random.Generator,
                noise_grey: float) -> NDArray[np.uint8]:
    """A shaded orange disc on carpet, each pixel mixed by its coverage (16 x 16 samples)."""
    n = 16
    off = (np.arange(n) + 0.5) / n
    v, u = np.mgrid[0:24, 0:24]
    su = u[..., None, None] + off[None, None, None, :]
    sv = v[..., None, None] + off[None, None, :, None]
    r2 = ((su - centre[0]) ** 2 + (sv - centre[1]) ** 2) / radius_px**2
    inside = r2 <= 1.0
    shade = np.where(inside, 0.6 + 0.4 * np.sqrt(np.clip(1.0 - r2, 0.0, 1.0)), 0.0)  # the rim darker
    cover, lit = inside.mean(axis=(2, 3)), shade.mean(axis=(2, 3))
    ball, carpet = np.array([20.0, 115.0, 250.0]), np.array([40.0, 110.0, 40.0])
    img = lit[..., None] * ball + (1.0 - cover[..., None]) * carpet + rng.normal(0.0, noise_grey, (24, 24, 3))
    out: NDArray[np.uint8] = np.clip(np.rint(img), 0, 255).astype(np.uint8)
    return out


@pytest.mark.parametrize("seed", range(6))
def test_ball_centre_kernel_equals_numpy_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    image = _disc_image((float(rng.uniform(8, 16)), float(rng.uniform(8, 16))), 3.3, rng, 2.5)
    box = np.array([6.0, 7.0, 13.0, 14.0]) + rng.integers(-1, 2, 4)
    margin = int(rng.integers(1, 3))
    np.testing.assert_allclose(kern.ball_centre(image, box, margin), ball_centre_reference(image, box, margin),
                               atol=1e-9)
    # at the image's border (a window cut off) and on a flat image (no ball): the same answers
    for b in (np.array([0.0, 0.0, 4.0, 3.0]), np.array([19.0, 20.0, 23.0, 23.0])):
        np.testing.assert_allclose(kern.ball_centre(image, b, 1), ball_centre_reference(image, b, 1), atol=1e-9)
    flat = np.full((24, 24, 3), 90, dtype=np.uint8)
    assert np.isnan(kern.ball_centre(flat, box, 1)).all() and np.isnan(ball_centre_reference(flat, box, 1)).all()


@pytest.mark.parametrize("centre", [(11.5, 11.5), (11.23, 12.71), (12.9, 10.05), (10.6, 11.38)])
def test_ball_centre_follows_the_disc_between_pixels(centre: tuple[float, float]) -> None:
    # a 6.6 px ball with a shaded rim: the coverage centre is within 0.03 px of the truth at the
    # simulator's default sensor noise, where the thresholded pixels' centroid is off by up to ~0.1 px
    rng = np.random.default_rng(7)
    image = _disc_image(centre, 3.3, rng, 2.5)
    # the region's box: the pixels whose centre lies inside the disc
    grid = np.arange(24) + 0.5
    v, u = np.nonzero(np.hypot(grid[None, :] - centre[0], grid[:, None] - centre[1]) < 3.3)
    box = np.array([u.min(), v.min(), u.max(), v.max()], dtype=np.float64)
    got = np.array(kern.ball_centre(image, box, 1)[:2])
    assert np.hypot(*(got - centre)) < 0.03


def test_ball_centre_deviation_grows_with_noise_and_the_visible_area_shrinks_when_cut() -> None:
    # the same 6.6 px ball: clear at low and at high sensor noise, and cut by the image's left edge
    # through its middle; the coverage sum is the visible area (pi 3.3^2 = 34 px clear), the
    # deviation the centre's noise from the background's false coverage
    rng = np.random.default_rng(3)
    centre, radius = (11.4, 12.2), 3.3
    grid = np.arange(24) + 0.5
    v, u = np.nonzero(np.hypot(grid[None, :] - centre[0], grid[:, None] - centre[1]) < radius)
    box = np.array([u.min(), v.min(), u.max(), v.max()], dtype=np.float64)
    clear = kern.ball_centre(_disc_image(centre, radius, rng, 1.0), box, 1)
    noisy = kern.ball_centre(_disc_image(centre, radius, rng, 6.0), box, 1)
    cut = kern.ball_centre(_disc_image(centre, radius, rng, 1.0)[:, 11:], box - [11.0, 0.0, 11.0, 0.0], 1)
    assert abs(clear[2] - math.pi * radius**2) < 0.1 * math.pi * radius**2
    assert noisy[3] > 2.0 * clear[3] and clear[3] < 0.05
    assert abs(cut[2] - 0.5 * clear[2]) < 0.15 * clear[2]
    assert cut[0] - (centre[0] - 11.0) > 0.8  # the missing half pulls the centre away from it (1.4 px)
