"""The elastic band: clear while obstacles move, taut again when they leave."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.navigation.elastic_band import BandParams, ElasticBand, circles_clearance

R = 0.09  # robot radius


def test_a_band_through_free_space_contracts_to_the_straight_line() -> None:
    band = ElasticBand(BandParams())
    free = circles_clearance(np.zeros((0, 3)), R)
    # a detour: start and goal 3 m apart, the path bent 1 m aside
    band.set_path([(0.0, 0.0), (1.5, 1.0), (3.0, 0.0)], free)
    for _ in range(20):
        band.update(free)
    assert band.clear()
    assert band.length == pytest.approx(3.0, rel=0.01)
    assert np.max(np.abs(band.points[:, 1])) < 0.03


def test_the_band_stays_clear_while_an_obstacle_moves_into_it_and_straightens_when_it_leaves() -> None:
    band = ElasticBand(BandParams())
    path = [(0.0, 0.0), (3.0, 0.0)]
    band.set_path(path, circles_clearance(np.zeros((0, 3)), R))
    # a robot crosses the band from below, slowly enough for the band to give way
    for k in range(60):
        y = -0.6 + 0.012 * k
        world = circles_clearance([(1.5, y, R)], R)
        assert band.update(world), k
        d, _ = world(band.points)
        assert np.all(d > 0.0)
    # it leaves: the band pulls straight again
    away = circles_clearance([(1.5, 5.0, R)], R)
    for _ in range(40):
        band.update(away)
    assert band.clear()
    assert band.length == pytest.approx(3.0, rel=0.01)


def test_bubbles_are_added_where_the_band_is_tight_and_removed_where_it_is_open() -> None:
    band = ElasticBand(BandParams(max_bubble_m=0.5))
    narrow = circles_clearance([(1.5, 0.35, 0.1), (1.5, -0.35, 0.1)], R)
    band.set_path([(0.0, 0.0), (3.0, 0.0)], narrow)
    near = np.hypot(band.points[:, 0] - 1.5, band.points[:, 1])
    gaps = np.hypot(*np.diff(band.points, axis=0).T)
    # between the two obstacles the bubbles are small and close together
    assert band.clear()
    assert gaps[np.argmin(near[:-1])] < 0.2 < gaps.max()
    n_tight = len(band.points)
    band.update(circles_clearance(np.zeros((0, 3)), R))
    assert len(band.points) < n_tight


def test_a_blocked_band_is_not_clear() -> None:
    band = ElasticBand(BandParams())
    wall = circles_clearance([(1.5, 0.0, 0.5)], R)
    band.set_path([(0.0, 0.0), (3.0, 0.0)], wall)
    assert not band.clear()
    assert math.isfinite(band.length)
