"""The overhead camera renderer against projected ground truth, and its kernels against numpy.

Tolerances: pattern-dot and ball centroids within 1 px of the exact projection (the camera model
the vision stage inverts); kernels within one grey level of their numpy references.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, CameraParams, CamerasParams, cameras_from_config
from cmdragons.geometry import LeagueParams, rotate
from sim import _kernels as kern
from sim.render import CameraRenderer, RenderParams
from sim.snapshot import Snapshot

LEAGUE = LeagueParams()
ROBOT = LEAGUE.robot
PATTERN = LEAGUE.pattern
CLEAN = RenderParams(noise_sigma_grey=0.0, vignetting_fraction=0.0, gradient_fraction=0.0, exposure_s=0.0)
FAR_AWAY = np.array([50.0, 50.0, LEAGUE.ball.radius_m, 0.0, 0.0, 0.0])  # out of every camera's view


def snapshot(robots: Sequence[Sequence[float]], ball: NDArray[np.float64] = FAR_AWAY, frame: int = 0) -> Snapshot:
    """Robots as (team, id, x, y, theta[, vx, vy, omega]) in the field frame, SI units."""
    rows = np.zeros((len(robots), 8))
    for k, r in enumerate(robots):
        rows[k, : len(r)] = r
    return Snapshot(t=frame / 60.0, frame_number=frame, ball=np.asarray(ball, dtype=np.float64), robots=rows)


@pytest.fixture(scope="module")
def cameras() -> list[CameraModel]:
    return cameras_from_config(CamerasParams(), LEAGUE)


@pytest.fixture(scope="module")
def clean_all(cameras: list[CameraModel]) -> list[CameraRenderer]:
    """The default cameras (distorted, k1 = -0.02) with noise, lighting and motion blur off."""
    return [CameraRenderer(model, LEAGUE, CLEAN, seed=0) for model in cameras]


@pytest.fixture(scope="module")
def clean(clean_all: list[CameraRenderer]) -> CameraRenderer:
    return clean_all[0]


@pytest.fixture(scope="module")
def small_camera() -> CameraModel:
    """A small distorted view of a 1 m patch, so the numpy references stay quick."""
    return CameraModel(CameraParams(id=7, position_m=(0.3, -0.2, 4.0), yaw_rad=0.3, tilt_x_rad=0.02,
                                    focal_px=560.0, principal_point_px=(80.0, 60.0), k1=-0.05, k2=0.01,
                                    resolution_px=(160, 120)))


def classify(pixels: NDArray[np.uint8], colours: dict[str, tuple[int, int, int]]) -> NDArray[np.str_]:
    """Each pixel's nearest colour name (BGR distance): a 50 % coverage threshold between two."""
    names = list(colours)
    ref = np.array([colours[n] for n in names], dtype=np.float64)
    dist = np.linalg.norm(pixels[..., None, :].astype(np.float64) - ref, axis=-1)
    out: NDArray[np.str_] = np.array(names)[np.argmin(dist, axis=-1)]
    return out


def centroids(mask: NDArray[np.bool_], offset: tuple[int, int], min_area: int = 3) -> NDArray[np.float64]:
    """Centroids (u, v) in image pixels of the connected components of ``mask`` (a window whose
    top-left pixel is ``offset`` = (row, column)); pixel centres at +0.5."""
    n, _, stats, cents = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    keep = [k for k in range(1, n) if stats[k, cv2.CC_STAT_AREA] >= min_area]
    return np.array([[cents[k, 0] + offset[1] + 0.5, cents[k, 1] + offset[0] + 0.5] for k in keep]).reshape(-1, 2)


def layout(model: CameraModel, margin_px: float) -> list[tuple[float, float]]:
    """16 field positions whose robot tops project on a 4 x 4 grid spanning the image, the outer
    ones ``margin_px`` (plus the top's radius) from the image edges."""
    rad = ROBOT.radius_m * model.f / (model.center[2] - ROBOT.height_m)
    us = np.linspace(margin_px + rad, model.width - margin_px - rad, 4)
    vs = np.linspace(margin_px + rad, model.height - margin_px - rad, 4)
    pix = np.array([(u, v) for v in vs for u in us])
    return [tuple(p) for p in model.unproject(pix, ROBOT.height_m)]


# --- patterns and ball against the projection ----------------------------------------------------


@pytest.mark.parametrize(
    ("camera", "theta", "margin_px"),
    [(0, 0.0, 3.0), (0, 0.7, 60.0), (0, 2.0, 3.0), (0, -2.6, 60.0), (1, 1.1, 3.0), (1, -0.4, 100.0)],
)
def test_pattern_dots_project_to_the_truth(
    clean_all: list[CameraRenderer], camera: int, theta: float, margin_px: float
) -> None:
    """16 robots (ids 0..15, headings theta + 0.37 id) spread over the image, the outer ones
    ``margin_px`` from its edges: each dot's centroid within 1 px of its projection."""
    clean = clean_all[camera]
    model = clean.model
    positions = layout(model, margin_px)
    robots = [(rid % 2, rid, x, y, theta + 0.37 * rid) for rid, (x, y) in enumerate(positions)]
    image, truth = clean.render(snapshot(robots))
    p = clean.params
    colours = {"cover": p.cover_bgr, "side": p.side_bgr, "carpet": p.carpet_bgr, "line": p.line_bgr,
               "pink": p.pink_bgr, "green": p.green_bgr, "blue": p.blue_bgr, "yellow": p.yellow_bgr,
               "boundary": p.boundary_bgr}
    for team, rid, x, y, th in robots:
        assert (team, rid) in truth.robots, "every top of the layout lies inside the image"
        top = model.project_xy(np.array([x, y]), ROBOT.height_m)
        np.testing.assert_allclose(truth.robots[(team, rid)], top, atol=1e-6)
        half = int(ROBOT.radius_m * model.f / (model.center[2] - ROBOT.height_m) * 1.6)
        i0, j0 = max(int(top[1]) - half, 0), max(int(top[0]) - half, 0)
        window = classify(image[i0 : int(top[1]) + half, j0 : int(top[0]) + half], colours)

        dots_xy = np.array([x, y]) + rotate(np.array(PATTERN.dot_positions_m), th)
        expected = model.project_xy(dots_xy, ROBOT.height_m)
        found = np.concatenate([centroids(window == "pink", (i0, j0)), centroids(window == "green", (i0, j0))])
        assert len(found) == 4, f"id {rid}: {len(found)} id dots segmented"
        for dot_px in expected:
            err = np.min(np.linalg.norm(found - dot_px, axis=1))
            assert err < 1.0, f"id {rid} theta {th:.2f}: dot centroid {err:.2f} px from its projection"
        centre = centroids(window == ("blue" if team == 0 else "yellow"), (i0, j0))
        assert len(centre) == 1
        assert np.linalg.norm(centre[0] - top) < 1.0

        # reading the id back: the colour under each projected dot centre
        code = "".join("P" if image[int(v), int(u)].tolist() == list(p.pink_bgr) else "G" for u, v in expected)
        assert code == PATTERN.ids[rid]


@pytest.mark.parametrize(
    ("pixel", "z_m"),
    [((512.0, 384.0), LEAGUE.ball.radius_m), ((30.0, 700.0), LEAGUE.ball.radius_m), ((990.0, 25.0), 0.0215),
     ((700.0, 200.0), 0.35), ((150.0, 400.0), 0.8)],
)
def test_ball_centroid_projects_to_the_truth(clean: CameraRenderer, pixel: tuple[float, float], z_m: float) -> None:
    model = clean.model
    x, y = model.unproject(np.array(pixel), z_m)
    image, truth = clean.render(snapshot([], np.array([x, y, z_m, 0.0, 0.0, 0.0])))
    assert truth.ball is not None
    centre = model.project(np.array([x, y, z_m]))
    np.testing.assert_allclose(truth.ball[:2], centre, atol=1e-6)
    assert truth.ball[2] == pytest.approx(1.0, abs=1e-9)
    i0, j0 = int(centre[1]) - 15, int(centre[0]) - 15
    win = image[max(i0, 0) : i0 + 30, max(j0, 0) : j0 + 30].astype(np.int16)
    orange = win[..., 2] - win[..., 1] > 0  # the ball's red exceeds its green, the carpet's does not
    found = centroids(orange, (max(i0, 0), max(j0, 0)))
    assert len(found) == 1
    assert np.linalg.norm(found[0] - centre) < 1.0


def ball_moments(
    image: NDArray[np.uint8], centre: NDArray[np.float64], carpet: tuple[int, int, int], half: int = 14
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centroid (u, v) px and covariance (px^2) of the ball's "red over green" above the carpet's,
    a weight linear in the pixel colour, so motion blur adds its own variance to the static one."""
    i0, j0 = int(centre[1]) - half, int(centre[0]) - half
    win = image[i0 : i0 + 2 * half, j0 : j0 + 2 * half].astype(np.float64)
    w = np.clip(win[..., 2] - win[..., 1] - (carpet[2] - carpet[1]), 0.0, None)
    v, u = np.mgrid[i0 : i0 + 2 * half, j0 : j0 + 2 * half] + 0.5
    pts = np.stack([u.ravel(), v.ravel()], 1)
    mean = (w.ravel() @ pts) / w.sum()
    d = pts - mean
    return mean, (d * w.ravel()[:, None]).T @ d / w.sum()


def test_motion_blur_streaks_the_ball_symmetrically_about_the_truth(cameras: list[CameraModel]) -> None:
    params = dataclasses.replace(CLEAN, exposure_s=0.004)
    renderer = CameraRenderer(cameras[0], LEAGUE, params, seed=0)
    model = renderer.model
    x, y = model.unproject(np.array([400.0, 300.0]), 0.0215)  # on plain carpet
    rest = np.array([x, y, 0.0215, 0.0, 0.0, 0.0])
    moving = rest + np.array([0.0, 0.0, 0.0, 6.0, 2.0, 0.0])
    c_rest, cov_rest = ball_moments(renderer.render(snapshot([], rest))[0], model.project(rest[:3]), params.carpet_bgr)
    image, truth = renderer.render(snapshot([], moving))
    c_move, cov_move = ball_moments(image, model.project(moving[:3]), params.carpet_bgr)
    assert truth.ball is not None
    assert np.linalg.norm(c_move - truth.ball[:2]) < 0.1, "the exposure is centred on the snapshot"
    assert np.linalg.norm(c_rest - truth.ball[:2]) < 0.1
    # the streak, in the image: its length L and K samples add L^2 (1 - 1/K^2) / 12 along it
    step = model.project(moving[:3] + moving[3:] * params.exposure_s / 2) - model.project(
        moving[:3] - moving[3:] * params.exposure_s / 2
    )
    length = float(np.linalg.norm(step))
    k = min(params.max_blur_samples, math.ceil(length / params.blur_step_px) + 1)
    along, across = step / length, np.array([-step[1], step[0]]) / length
    added = cov_move - cov_rest
    assert along @ added @ along == pytest.approx(length**2 * (1 - 1 / k**2) / 12, rel=0.1)
    assert abs(across @ added @ across) < 0.05


# --- parallax and occlusion ----------------------------------------------------------------------


def test_ball_behind_a_robot_is_partly_hidden_and_in_the_open_is_not(clean: CameraRenderer) -> None:
    model = clean.model
    nadir = model.center[:2]
    away = np.array([0.6, 0.8])  # from the point under the camera
    touch = ROBOT.radius_m + LEAGUE.ball.radius_m + 0.002

    def seen(distance_m: float, offset_m: float, ball_z_m: float = LEAGUE.ball.radius_m) -> float:
        """Visible fraction of a ball ``offset_m`` beyond a robot ``distance_m`` from the nadir."""
        robot_xy = nadir + distance_m * away
        robot = [(0, 3, robot_xy[0], robot_xy[1], math.atan2(away[0], -away[1]))]  # round back outward
        ball = np.array([*(robot_xy + offset_m * away), ball_z_m, 0.0, 0.0, 0.0])
        _, truth = clean.render(snapshot(robot, ball))
        assert truth.ball is not None
        return truth.ball[2]

    # the top (0.15 m) overhangs by distance * (0.15 - z) / (4 - z) along the line of sight:
    # about 3.3 cm at 1 m (the ball's near half), 6.5 cm at 2 m (all of it)
    assert 0.1 < seen(1.0, touch) < 0.8, "a ball behind the robot is partly under the top's overhang"
    assert seen(2.0, touch) < 0.02
    assert seen(2.0, -touch) == pytest.approx(1.0, abs=1e-3), "a ball on the near side is in front"
    assert seen(2.0, 0.4) == pytest.approx(1.0, abs=1e-9), "a ball in the open"
    assert seen(2.0, 0.02, ball_z_m=0.4) == pytest.approx(1.0, abs=1e-9), "a chip above the robot is in front"


def test_truth_lists_only_what_is_inside_the_image(clean: CameraRenderer) -> None:
    model = clean.model
    rad = ROBOT.radius_m * model.f / (model.center[2] - ROBOT.height_m)
    inside = model.unproject(np.array([rad + 4.0, 300.0]), ROBOT.height_m)
    cut = model.unproject(np.array([rad - 4.0, 500.0]), ROBOT.height_m)
    ball_out = model.unproject(np.array([-3.0, 200.0]), 0.0215)
    _, truth = clean.render(snapshot([(0, 1, *inside, 0.0), (1, 2, *cut, 0.0)], np.array([*ball_out, 0.0215, 0, 0, 0])))
    assert set(truth.robots) == {(0, 1)}
    assert truth.ball is None


# --- determinism ---------------------------------------------------------------------------------


def test_same_seed_same_bytes_other_seed_other_noise(small_camera: CameraModel) -> None:
    params = RenderParams()
    frames = [snapshot([(0, 5, 0.3, -0.2, 0.4, 1.0, -0.5, 4.0)], np.array([0.5, -0.1, 0.0215, 3.0, 1.0, 0.0]), k)
              for k in range(3)]
    a, b = CameraRenderer(small_camera, LEAGUE, params, 11), CameraRenderer(small_camera, LEAGUE, params, 11)
    other = CameraRenderer(small_camera, LEAGUE, params, 12)
    for snap in frames:
        img_a, truth_a = a.render(snap)
        img_b, truth_b = b.render(snap)
        assert img_a.tobytes() == img_b.tobytes()
        assert truth_a == truth_b
        img_o, _ = other.render(snap)
        assert (img_o != img_a).mean() > 0.3
    # consecutive frames of one renderer get different noise; an image handed out stays as it is
    kept, _ = a.render(frames[0])
    copy = kept.copy()
    again, _ = a.render(frames[0])
    assert again is not kept and again.tobytes() != kept.tobytes()
    assert kept.tobytes() == copy.tobytes()


def test_sensor_noise_is_fresh_every_frame(small_camera: CameraModel) -> None:
    """A pixel's noise in one frame says nothing of its noise in the next: consecutive and distant
    frames are uncorrelated, and each frame's noise is N(0, sigma) rounded to grey levels."""
    sigma = 6.0
    r = CameraRenderer(small_camera, LEAGUE, RenderParams(noise_sigma_grey=sigma), seed=4)
    empty = snapshot([])
    # away from saturation the noise is the image minus the clean background
    mid = (r.background > 5 * sigma) & (r.background < 255 - 5 * sigma)
    assert mid.sum() > 30000
    noise = np.array([(r.render(empty)[0].astype(np.int16) - r.background)[mid] for _ in range(12)], dtype=float)
    flat = noise.reshape(12, -1)
    assert abs(flat.mean()) < 0.05
    assert flat.std() == pytest.approx(np.sqrt(sigma**2 + 1.0 / 12.0), rel=0.02)
    corr = np.corrcoef(flat)
    off_diagonal = corr[~np.eye(12, dtype=bool)]
    assert np.abs(off_diagonal).max() < 0.02, "no frame repeats another's noise"
    # neighbouring values (channels, pixels) are independent too
    assert abs(np.corrcoef(flat[0, :-1], flat[0, 1:])[0, 1]) < 0.02


def test_params_are_validated() -> None:
    with pytest.raises(ValueError, match="noise_sigma_grey"):
        RenderParams(noise_sigma_grey=-1.0)
    with pytest.raises(ValueError, match="pink_bgr"):
        RenderParams(pink_bgr=(200, 80, 256))
    # a colour of the wrong length is the config loader's to catch (the type says three)
    from cmdragons.config import ConfigError, parse

    with pytest.raises(ConfigError, match="carpet_bgr: expected a list of 3 values"):
        parse(RenderParams, {"carpet_bgr": [40, 110]}, file="sim.yaml", key="render")


# --- kernels against their numpy references ------------------------------------------------------


def test_project_points_matches_the_camera_model(small_camera: CameraModel, cameras: list[CameraModel]) -> None:
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-5, 5, 200), rng.uniform(-3.5, 3.5, 200), rng.uniform(0, 1, 200)])
    for model in [small_camera, *cameras]:
        np.testing.assert_allclose(kern.project_points(kern.camera_vector(model), pts), model.project(pts),
                                   rtol=0, atol=1e-9)


def scene(model: CameraModel, renderer: CameraRenderer) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Moving, spinning robots and a fast ball behind one of them, in the small camera's view."""
    cx, cy = model.center[:2]
    robots = np.array([
        [0, 4, cx - 0.25, cy + 0.05, 0.3, 1.5, -0.8, 6.0],
        [1, 13, cx + 0.18, cy - 0.12, -2.2, 0.0, 0.0, 0.0],
        [1, 0, cx + 0.05, cy + 0.3, 1.0, -0.3, 2.5, -9.0],
        [0, 9, cx + 3.0, cy + 3.0, 0.0, 0.0, 0.0, 0.0],  # out of view
    ])  # fmt: skip
    away = np.array([0.18, -0.12]) / np.hypot(0.18, -0.12)
    bxy = robots[1, 2:4] + (ROBOT.radius_m + LEAGUE.ball.radius_m + 0.003) * away
    return robots, np.array([bxy[0], bxy[1], 0.0215, 0.4, 3.5, 0.0])


def test_plan_objects_matches_reference(small_camera: CameraModel) -> None:
    r = CameraRenderer(small_camera, LEAGUE, RenderParams(exposure_s=0.004), seed=1)
    robots, ball = scene(small_camera, r)
    p = r.params
    plan = kern.ObjectPlan(len(robots), p.max_blur_samples)
    kern.plan_objects(plan, robots, ball, r.cam, r.shape, r.pink, r.dots, r.palette, p.exposure_s, p.blur_step_px)
    ref = kern.plan_objects_reference(small_camera, robots, ball, r.shape, r.pink, r.palette, p.exposure_s,
                                      p.max_blur_samples, p.blur_step_px)
    np.testing.assert_array_equal(plan.rob_k, ref.rob_k)
    assert plan.rob_k.max() > 1 and plan.ball_k > 1, "the scene exercises motion blur"
    for k in range(len(robots)):
        used = slice(0, plan.rob_k[k])
        np.testing.assert_allclose(plan.rob_samples[k, used], ref.rob_samples[k, used], atol=1e-12)
    np.testing.assert_array_equal(plan.rob_bbox, ref.rob_bbox)
    assert (plan.rob_bbox[3] == 0).all() and (plan.rob_bbox[:3, 1] > 0).all(), "out of view: an empty box"
    np.testing.assert_array_equal(plan.rob_colors, ref.rob_colors)
    np.testing.assert_allclose(plan.rob_truth, ref.rob_truth, atol=1e-9)
    assert plan.ball_k == ref.ball_k
    np.testing.assert_allclose(plan.ball_samples[: plan.ball_k], ref.ball_samples[: ref.ball_k], atol=1e-12)
    np.testing.assert_array_equal(plan.ball_bbox, ref.ball_bbox)
    np.testing.assert_allclose(plan.ball_truth, ref.ball_truth, atol=1e-9)


def test_segment_distance_is_the_minimum_along_the_segment() -> None:
    """The kernel's closed-form candidates against a dense scan of the segment (robot frame, m)."""
    rng = np.random.default_rng(5)
    r, front = ROBOT.radius_m, ROBOT.front_distance_m
    t = np.linspace(0.0, 1.0, 4001)
    for _ in range(300):
        a, b = rng.uniform(-0.2, 0.2, 2), rng.uniform(-0.2, 0.2, 2)
        sd, t_min = kern._segment_sd(a[0], a[1], b[0], b[1], r, front)
        p = a + t[:, None] * (b - a)
        scan = np.maximum(np.hypot(p[:, 0], p[:, 1]) - r, p[:, 0] - front)
        assert scan.min() - 1e-4 <= sd <= scan.min() + 1e-12
        q = a + t_min * (b - a)
        assert max(math.hypot(*q) - r, q[0] - front) == pytest.approx(sd, abs=1e-12)


@pytest.mark.parametrize("noise", [True, False])
def test_render_frame_matches_reference(small_camera: CameraModel, noise: bool) -> None:
    r = CameraRenderer(small_camera, LEAGUE, RenderParams(noise_sigma_grey=6.0, exposure_s=0.004), seed=2)
    robots, ball = scene(small_camera, r)
    p = r.params
    plan = kern.ObjectPlan(len(robots), p.max_blur_samples)
    kern.plan_objects(plan, robots, ball, r.cam, r.shape, r.pink, r.dots, r.palette, p.exposure_s, p.blur_step_px)
    key: int | None = 2**64 - 1234 if noise else None
    out = np.empty_like(r.background)
    vis, sil = kern.render_frame(out, r.background, r.noise, key, r.rays, r.foot, r.gain, r.cam, r.shape, r.dots,
                                 r.palette, plan, np.zeros((out.shape[0], 2)), n_chunks=3)
    ref, vis_ref, sil_ref = kern.render_frame_reference(r.background, r.noise, key, r.rays, r.foot, r.gain, r.cam,
                                                        r.shape, r.dots, r.palette, plan)
    diff = np.abs(out.astype(np.int16) - ref)
    assert diff.max() <= 1, "float rounding may move a level by one, never more"
    assert (diff > 0).mean() < 0.002
    assert (out != r.background).mean() > 0.05, "the scene draws something"
    assert 0.0 < vis < sil, "the ball is partly hidden"
    assert vis == pytest.approx(vis_ref, rel=1e-4)
    assert sil == pytest.approx(sil_ref, rel=1e-4)
    if key is not None:  # away from the objects' boxes: the background plus saturated noise, exactly
        free = np.ones(out.shape[:2], dtype=bool)
        for i0, i1, j0, j1 in [*plan.rob_bbox, plan.ball_bbox]:
            free[i0:i1, j0:j1] = False
        assert free.mean() > 0.3
        np.testing.assert_array_equal(out[free], kern.add_noise_reference(r.background, r.noise, key)[free])
