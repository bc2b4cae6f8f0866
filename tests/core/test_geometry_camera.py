"""Field geometry presets and the camera model against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons import angles as kern
from cmdragons.camera import (
    AutoLayout,
    CameraModel,
    CameraParams,
    CamerasParams,
    cameras_from_config,
    smallest_ball_px,
)
from cmdragons.geometry import Field, LeagueParams, wrap_angle


def test_the_angle_wrap_is_in_range_and_the_kernels_is_the_same_to_the_bit() -> None:
    edges = [0.0, -0.0, math.pi, -math.pi, 2.0 * math.pi, -2.0 * math.pi, 3.0 * math.pi, 1e-300, 1e6]
    a = np.concatenate([np.random.default_rng(3).uniform(-50.0, 50.0, 2000), np.nextafter(edges, np.inf),
                        np.nextafter(edges, -np.inf), edges])
    w = wrap_angle(a)
    assert np.all(np.abs(w) <= math.pi)  # [-pi, pi): rounding may give pi itself for an angle just under -pi
    np.testing.assert_allclose(np.cos(w), np.cos(a), atol=1e-9)  # the same direction (the 1e6 loses ~1e-10)
    np.testing.assert_allclose(np.sin(w), np.sin(a), atol=1e-9)
    # each element alone, through the array and through the compiled kernel: one formula, one result
    assert [wrap_angle(float(x)) for x in a] == w.tolist() == [kern.wrap_angle(float(x)) for x in a]


@pytest.mark.parametrize(
    ("division", "length", "width", "goal", "defense"),
    [("B", 9.0, 6.0, 1.0, (2.0, 1.0)), ("A", 12.0, 9.0, 1.8, (3.6, 1.8))],
)
def test_division_presets(
    division: str, length: float, width: float, goal: float, defense: tuple[float, float]
) -> None:
    league = LeagueParams(division=division)  # type: ignore[arg-type]
    f = Field(league)
    assert (f.dims.length_m, f.dims.width_m, f.dims.goal_width_m) == (length, width, goal)
    assert (f.dims.defense_width_m, f.dims.defense_depth_m) == defense
    assert f.dims.goal_depth_m == 0.18 and f.dims.line_width_m == 0.01
    assert f.in_goal(length / 2 + 0.1, 0.0) == 1 and f.in_goal(-length / 2 - 0.1, 0.0) == -1
    assert f.in_defense_area(-length / 2 + 0.5, 0.0) == -1
    # goal walls: back wall behind the goal, side walls along the posts
    back = f.goal_walls(1.0)[0]
    assert back[0] == pytest.approx(length / 2 + 0.18)


@pytest.mark.parametrize("point", [(4.5, 3.0), (3.0, 2.9), (-4.4, 0.1), (0.0, -3.3), (-4.6, -3.4)])
def test_free_kick_spot_is_legal(point: tuple[float, float]) -> None:
    f = Field(LeagueParams())
    x, y = f.free_kick_spot(*point)
    assert f.in_field(x, y, margin=0.2 - 1e-9)
    assert f.in_defense_area(x, y, margin=0.2 - 1e-9) == 0


def test_projection_round_trip_with_distortion() -> None:
    cam = CameraModel(CameraParams(position_m=(1.0, -0.5, 4.0), yaw_rad=0.3, tilt_x_rad=0.05, tilt_y_rad=-0.03,
                                   focal_px=600.0, k1=-0.08, k2=0.01))
    rng = np.random.default_rng(0)
    pts = rng.uniform([-2, -2.5], [4, 1.5], size=(200, 2))
    for z in (0.0, 0.0215, 0.15):
        px = cam.project_xy(pts, z)
        back = cam.unproject(px, z)
        assert np.max(np.abs(back - pts)) < 1e-9


def test_pinhole_closed_form() -> None:
    # looking straight down, no distortion: u = cx + f * dx / dz along the image axes
    cam = CameraModel(CameraParams(position_m=(0.0, 0.0, 4.0), yaw_rad=0.0, focal_px=500.0,
                                   principal_point_px=(320.0, 240.0), resolution_px=(640, 480)))
    u, v = cam.project_xy(np.array([1.0, 0.5]), 0.0)
    assert u == pytest.approx(320.0 + 500.0 * 1.0 / 4.0)
    assert v == pytest.approx(240.0 - 500.0 * 0.5 / 4.0)  # v runs along field -y
    u, v = cam.project_xy(np.array([1.0, 0.5]), 0.15)
    assert u == pytest.approx(320.0 + 500.0 * 1.0 / 3.85)  # parallax: higher objects look farther out


def test_default_cameras_cover_the_field_with_overlap_and_ball_size() -> None:
    league = LeagueParams()
    cams = cameras_from_config(CamerasParams(), league)
    assert len(cams) == 2
    f = Field(league)
    # every point of the field at robot-top height is seen by some camera, whole robot included
    xs, ys = np.meshgrid(np.linspace(-f.half_length, f.half_length, 61), np.linspace(-f.half_width, f.half_width, 41))
    pts = np.stack([xs.ravel(), ys.ravel()], axis=1)
    seen = np.zeros(len(pts), dtype=bool)
    for c in cams:
        seen |= c.in_image(c.project_xy(pts, league.robot.height_m), margin=1.0)
    assert seen.all()
    # the overlap at robot-top height is at least 0.3 m wide along x
    strip = np.stack([np.full(41, 0.0), np.linspace(-3, 3, 41)], axis=1)
    for dx in (-0.15, 0.15):
        s = strip + [dx, 0.0]
        assert all(c.in_image(c.project_xy(s, league.robot.height_m)).all() for c in cams)
    # the ball is at least 6 px across anywhere on the field in the camera that sees it best
    assert smallest_ball_px(cams, league, samples=31) >= 6.0


def test_auto_grid_gives_division_a_enough_cameras() -> None:
    league = LeagueParams(division="A")
    cams = cameras_from_config(CamerasParams(), league)
    assert len(cams) == 4
    assert smallest_ball_px(cams, league, samples=31) >= 6.0
    # a fixed grid is taken as given
    fixed = cameras_from_config(CamerasParams(auto=AutoLayout(grid=(2, 1))), league)
    assert len(fixed) == 2 and smallest_ball_px(fixed, league) < 6.0


def test_camera_params_validation() -> None:
    with pytest.raises(ValueError, match="above the field"):
        CameraParams(position_m=(0.0, 0.0, 0.1))
    assert math.isfinite(CameraModel(CameraParams()).pixels_per_metre((0.0, 0.0), 0.0))
