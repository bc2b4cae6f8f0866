"""The collision world: field obstacles, clearance as robot radius, time windows, nearest free point."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.geometry import Field
from cmdragons.planning import CollisionParams, CollisionWorld, field_world
from cmdragons.planning import collision_reference as PR

R = 0.09


def test_field_world_blocks_defense_areas_goal_walls_and_boundary(field: Field) -> None:
    cw = field_world(field).compile(R)
    assert cw.point_free(0.0, 0.0)
    assert not cw.point_free(4.0, 0.0)  # inside the defense area at +x
    assert not cw.point_free(-3.5 + 0.05, 0.9)  # within a robot radius of the -x defense area
    assert cw.point_free(-3.5 + 0.1, 0.9)
    assert not cw.point_free(4.71, 0.0)  # the back wall of the goal
    assert not cw.point_free(4.8 - 0.05, 2.0)  # the disc would cross the boundary wall
    assert cw.point_free(4.8 - 0.1, 2.0)  # robots may leave the field lines, not the walls
    assert cw.segment_free((-3.0, 0.0), (3.0, 0.2))  # the open field
    assert not cw.segment_free((3.45, -2.0), (3.45, 2.0))  # grazes the defense area's front
    assert cw.segment_free((3.4, -2.0), (3.4, 2.0))


@pytest.mark.parametrize(
    ("defense_areas", "blocked_plus_x", "blocked_minus_x"),
    [(True, True, True), (False, False, False), (1, True, False), (-1, False, True)],
)
def test_defense_areas_on_one_side_only(
    field: Field, defense_areas: bool, blocked_plus_x: bool, blocked_minus_x: bool
) -> None:
    # a goalie at -x may enter its own defense area but never the opponent's at +x
    cw = field_world(field, defense_areas=defense_areas).compile(R)  # type: ignore[arg-type]
    assert cw.point_free(4.0, 0.5) is not blocked_plus_x
    assert cw.point_free(-4.0, -0.5) is not blocked_minus_x
    assert not cw.point_free(4.71, 0.0) and not cw.point_free(-4.71, 0.0)  # goal walls stay
    assert cw.point_free(0.0, 0.0)


@pytest.mark.parametrize("bad", [0, 2, -2, 0.5])
def test_defense_areas_refuses_other_values(field: Field, bad: object) -> None:
    with pytest.raises(ValueError, match="defense_areas"):
        field_world(field, defense_areas=bad)  # type: ignore[arg-type]


def test_robot_radius_is_the_clearance(field: Field) -> None:
    world = field_world(field, [[0.0, 0.0]])
    cw = world.compile(R)
    assert cw.point_free(0.1801, 0.0) and not cw.point_free(0.1799, 0.0)
    # a segment passing at 0.17 m from the robot's centre is blocked, at 0.19 m it is free
    assert not cw.segment_free((-1.0, 0.17), (1.0, 0.17))
    assert cw.segment_free((-1.0, 0.19), (1.0, 0.19))
    assert world.compile(0.0).point_free(0.1, 0.0)
    assert cw.clearance(0.5, 0.0) == pytest.approx(0.5 - 0.18)


def test_moving_robots_are_swept_over_the_time_window(field: Field) -> None:
    world = field_world(field, [[0.0, -1.0]], velocities=[[0.0, 2.0]])
    now, later = world.compile(R), world.compile(R, 0.0, 0.5)
    seg = ((-1.0, 0.0), (1.0, 0.0))
    assert now.segment_free(*seg)  # the robot is still a metre away
    assert not later.segment_free(*seg)  # within half a second it crosses the line
    assert world.compile(R, 0.6, 1.0).segment_free(*seg)  # and by then it has passed
    assert world.compile(R) is now  # compiled worlds are shared per radius and window


def test_nearest_free_point_leaves_by_the_shortest_way(field: Field) -> None:
    cw = field_world(field, [[0.0, 0.0]]).compile(R)
    x, y = cw.nearest_free(0.05, 0.0)  # type: ignore[misc]
    assert (x, y) == pytest.approx((0.18, 0.0), abs=1e-4)
    x, y = cw.nearest_free(3.9, 0.2)  # type: ignore[misc]  # deep in the defense area: out of its front
    assert (x, y) == pytest.approx((3.5 - R, 0.2), abs=1e-4)
    x, y = cw.nearest_free(0.0, 3.25)  # type: ignore[misc]  # against the wall: back inside
    assert (x, y) == pytest.approx((0.0, 3.3 - R), abs=1e-4)


def test_nearest_free_point_between_two_robots(field: Field) -> None:
    # pushed out of one robot straight into the other: the ring search finds the way out
    cw = field_world(field, [[0.0, 0.0], [0.3, 0.0]]).compile(R)
    x, y = cw.nearest_free(0.15, 0.0)  # type: ignore[misc]
    assert cw.point_free(x, y)
    assert np.hypot(x - 0.15, y) < 0.2


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"bounds": (1.0, 0.0, 0.0, 1.0)}, "bounds"),
        ({"circles": [[0.0, 0.0, -1.0]]}, "radii"),
        ({"circles": [[0.0, 0.0, 0.1]], "velocities": [[0.0, 0.0], [1.0, 1.0]]}, "velocities"),
        ({"boxes": [[1.0, 0.0, 0.0, 1.0]]}, "boxes"),
        ({"circles": [[np.nan, 0.0, 0.1]]}, "finite"),
    ],
)
def test_bad_worlds_are_refused(kwargs: dict[str, object], fragment: str) -> None:
    args = {"bounds": (-1.0, -1.0, 1.0, 1.0), **kwargs}
    with pytest.raises(ValueError, match=fragment):
        CollisionWorld(**args)  # type: ignore[arg-type]


def _moving_world(field: Field) -> CollisionWorld:
    rng = np.random.default_rng(11)
    xy = rng.uniform((-4.0, -2.5), (4.0, 2.5), (12, 2))
    return field_world(field, xy, rng.normal(0.0, 1.0, (12, 2)), extra_circles=[[0.5, 0.5, 0.07]])


@pytest.mark.parametrize("window_s", [0.0, 0.3])
def test_clearance_grid_matches_brute_force_distances(field: Field, window_s: float) -> None:
    # every cell centre against a plain-numpy distance to every grown obstacle and the walls
    cw = _moving_world(field).compile(R, 0.0, window_s)
    grid = cw.clearance_grid(0.1)
    xs, ys = grid.centres()
    x0, y0, x1, y1 = field_world(field).bounds
    assert grid.values.shape == (len(ys), len(xs)) == (int(np.ceil((y1 - y0) / 0.1 - 1e-9)),
                                                       int(np.ceil((x1 - x0) / 0.1 - 1e-9)))
    assert xs[0] == pytest.approx(x0 + 0.05) and ys[0] == pytest.approx(y0 + 0.05)
    pts = np.array([(x, y) for y in ys for x in xs])
    inner = cw.inner
    walls = np.minimum.reduce([pts[:, 0] - inner[0], inner[2] - pts[:, 0], pts[:, 1] - inner[1], inner[3] - pts[:, 1]])
    brute = np.minimum(walls, np.min(PR.obstacle_dist(cw.obs, pts) - cw.obs[:, 5:6], axis=0))
    np.testing.assert_allclose(grid.values.ravel(), brute, atol=1e-12)
    # the point query is the same function
    for k in range(0, len(pts), 97):
        assert cw.clearance(*pts[k]) == pytest.approx(brute[k], abs=1e-12)
    # the default resolution comes from the params (configs/planner.yaml collision.grid_resolution_m)
    assert cw.clearance_grid().resolution_m == CollisionParams().grid_resolution_m


def test_clearance_gradient_points_away_from_the_nearest_obstacle(field: Field) -> None:
    cw = _moving_world(field).compile(R, 0.0, 0.2)
    rng = np.random.default_rng(12)
    h = 1e-6
    checked = 0
    for x, y in rng.uniform((-4.7, -3.2), (4.7, 3.2), (400, 2)):
        c, gx, gy = cw.clearance_gradient(x, y)
        assert c == pytest.approx(cw.clearance(x, y), abs=1e-12)
        fx = (cw.clearance(x + h, y) - cw.clearance(x - h, y)) / (2 * h)
        fy = (cw.clearance(x, y + h) - cw.clearance(x, y - h)) / (2 * h)
        if abs(np.hypot(fx, fy) - 1.0) > 1e-4:
            continue  # a ridge between two nearest obstacles (or inside a box's core): no gradient
        assert np.hypot(gx, gy) == pytest.approx(1.0)
        np.testing.assert_allclose((gx, gy), (fx, fy), atol=1e-4)
        checked += 1
    assert checked > 350
    # inside a box's core: out through the nearest face; on a still circle's centre: undefined
    box = CollisionWorld((-5.0, -5.0, 5.0, 5.0), boxes=np.array([[0.0, 0.0, 1.0, 2.0]])).compile(R)
    assert box.clearance_gradient(0.2, 1.0)[1:] == (-1.0, 0.0)
    disc = CollisionWorld((-5.0, -5.0, 5.0, 5.0), np.array([[1.0, 1.0, 0.2]])).compile(R)
    assert disc.clearance_gradient(1.0, 1.0) == (pytest.approx(-0.29), 0.0, 0.0)
