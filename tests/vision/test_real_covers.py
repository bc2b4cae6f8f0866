"""Detection on what real covers and fields show, made on the simulator's renders: a cover's light
segment touching a dot, a hidden dot, a dot smaller than expected, a lab's large ball, things
outside the field.

Tolerances as in test_pipeline: robot centre within 3 mm (5 mm with three dots), ball within 3 mm.
"""

from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.geometry import TEAMS, BallShape, LeagueParams
from sim.render import CameraRenderer, RenderParams
from vision import _kernels as kern
from vision.cmvision import Segmenter, SplitRule, split_region
from vision.pipeline import VisionParams, VisionPipeline

from .conftest import LEAGUE, render, snapshot

Z = LEAGUE.robot.height_m


def _robots(model: CameraModel, ids: list[int], team: int = 0) -> list[list[float]]:
    """One robot of each id on a row across the image's middle, headings varied: (team, id, x, y, theta)."""
    xy = model.unproject(np.array([[260.0, 330.0]]), Z)[0]
    return [[team, rid, xy[0] + 0.3 * (k % 4), xy[1] - 0.3 * (k // 4), 0.4 + 1.1 * k] for k, rid in enumerate(ids)]


def _to_image(model: CameraModel, robot: list[float], pts: NDArray[np.float64]) -> NDArray[np.int32]:
    """Robot-frame points (n, 2) on the robot's top as pixel polygon points (n, 2) for OpenCV."""
    _, _, x, y, th = robot
    c, s = math.cos(th), math.sin(th)
    field = np.column_stack([x + c * pts[:, 0] - s * pts[:, 1], y + s * pts[:, 0] + c * pts[:, 1]])
    return np.round(model.project_xy(field, Z)).astype(np.int32)


def _field_of(robot: list[float], p: tuple[float, float]) -> NDArray[np.float64]:
    _, _, x, y, th = robot
    c, s = math.cos(th), math.sin(th)
    return np.array([x + c * p[0] - s * p[1], y + s * p[0] + c * p[1]])


def test_split_region_keeps_the_disc_of_a_disc_joined_to_a_band() -> None:
    # a disc of radius 6 px touching a band 3 px wide: one region of one class, split into the disc
    mask = np.zeros((40, 60), np.uint8)
    cv2.circle(mask, (20, 20), 6, 1, -1)
    mask[12:15, 20:55] = 1  # the band runs from the disc's top edge to the right
    flat = np.array([(r, a, b, 2) for r in range(mask.shape[0])
                     for a, b in _runs(mask[r])], dtype=np.int32)
    rows = split_region(flat, SplitRule(np.array([0.0, 0.0, 50.0]), open_radius_px=3.6))
    assert rows.shape[0] == 1 and rows[0, kern.R_CLASS] == 2
    disc = np.count_nonzero(cv2.circle(np.zeros_like(mask), (20, 20), 6, 1, -1))
    assert abs(rows[0, kern.R_AREA] - disc) <= 0.1 * disc
    assert abs(rows[0, kern.R_SUM_U] / rows[0, kern.R_AREA] - 20.0) < 0.3
    assert abs(rows[0, kern.R_SUM_V] / rows[0, kern.R_AREA] - 20.0) < 0.3


def _runs(row: NDArray[np.uint8]) -> list[tuple[int, int]]:
    edges = np.flatnonzero(np.diff(np.concatenate([[0], row, [0]])))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]


@pytest.mark.parametrize("radius", [1, 3, 5])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_disc_fits_equals_opencv_erosion(radius: int, seed: int) -> None:
    """The kernel's test of whether the disc fits a region agrees with OpenCV's erosion being non-empty
    on random regions: thin arcs, blobs of every size, bands, and single rows."""
    rng = np.random.default_rng(seed)
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
    half = np.array([radius - int(np.flatnonzero(row)[0]) for row in disc], dtype=np.int64)  # rows centred
    verdicts = set()
    for _ in range(60):
        mask = np.zeros((50, 70), np.uint8)
        kind = rng.integers(4)
        cx, cy = int(rng.integers(15, 55)), int(rng.integers(15, 35))
        if kind == 0:
            cv2.circle(mask, (cx, cy), int(rng.integers(1, 12)), 1, -1)
        elif kind == 1:
            axes = (int(rng.integers(3, 14)), int(rng.integers(3, 14)))
            cv2.ellipse(mask, (cx, cy), axes, float(rng.uniform(0, 180)), 0.0, float(rng.uniform(60, 360)), 1,
                        int(rng.integers(1, 2 * radius + 3)))
        elif kind == 2:
            mask[cy : cy + int(rng.integers(1, 2 * radius + 3)), 5 : 5 + int(rng.integers(1, 40))] = 1
        else:
            mask[rng.random(mask.shape) < 0.35] = 1
        flat = np.array([(r, a, b, 0) for r in range(mask.shape[0]) for a, b in _runs(mask[r])], dtype=np.int32)
        if flat.size == 0:
            continue
        padded = cv2.copyMakeBorder(mask, radius, radius, radius, radius, cv2.BORDER_CONSTANT, value=0)
        want = bool(cv2.erode(padded, disc).any())
        assert kern.disc_fits(flat, half) == want
        verdicts.add(want)
    assert verdicts == {True, False}


def test_a_light_segment_touching_a_dot_is_split_from_it(cameras: list[CameraModel]) -> None:
    """Robot 1 (GPGP) with the flat front's segment of its cover printed in a light green of the
    green class, reaching 2 mm into its green front-left dot (the flat front is cut at 0.055 m):
    one region of a dot and a segment, too large for a dot; split, the cover is found with the
    right id, pose within 3 mm."""
    model = cameras[0]
    robots = _robots(model, [1, 3, 6, 12])
    image, _ = render(model, snapshot(robots))
    robot = robots[0]
    r, front = 0.085, 0.053
    a = math.acos(front / r)
    arc = np.array([(r * math.cos(t), r * math.sin(t)) for t in np.linspace(-a, a, 24)])
    segment = _to_image(model, robot, arc)
    centre = _to_image(model, robot, np.array([LEAGUE.pattern.dot_positions_m[0]]))[0]
    light = image[centre[1], centre[0]].astype(np.float64) * 0.9 + 20.0  # lighter than the dot, still green
    cv2.fillPoly(image, [segment.reshape(-1, 1, 2)], tuple(float(v) for v in light))
    pipe = VisionPipeline(VisionParams(), LEAGUE, model)
    det = pipe.process(image, 0, 0.0)
    assert sorted(rb.id for rb in det.robots) == [1, 3, 6, 12]
    one = next(rb for rb in det.robots if rb.id == 1)
    assert math.hypot(one.x - robot[2], one.y - robot[3]) < 0.003 and one.team == TEAMS[0]
    # the mechanism: without the split the joined region is no dot, and the cover is missed where
    # four dots are needed (with three it is read without that dot)
    params = VisionParams(patterns=dataclasses.replace(VisionParams().patterns, min_dots=4))
    unsplit = VisionPipeline(params, LEAGUE, model)
    unsplit.segmenter = Segmenter(params.colours, params.colour_space, params.regions, None)
    assert sorted(rb.id for rb in unsplit.process(image, 0, 0.0).robots) == [3, 6, 12]


def _hide_dot(image: NDArray[np.uint8], model: CameraModel, robot: list[float], slot: int) -> None:
    """A white blob (a tissue) over one id dot."""
    u, v = model.project_xy(_field_of(robot, LEAGUE.pattern.dot_positions_m[slot]), Z)
    radius = 1.4 * LEAGUE.pattern.id_dot_diameter_m / 2 * model.pixels_per_metre((robot[2], robot[3]), Z)
    cv2.circle(image, (int(round(u)), int(round(v))), int(math.ceil(radius)), (235, 235, 235), -1)


@pytest.mark.parametrize(("ids_in_play", "found"), [((), False), (tuple(range(8)), True)])
def test_a_hidden_dot_is_read_from_the_ids_in_play(cameras: list[CameraModel], ids_in_play: tuple[int, ...],
                                                   found: bool) -> None:
    """Robot 0 (PPGP) with its back-left dot under a white blob: its three dots fit ids 0 (PPGP)
    and 9 (PPPP); with ids 0-7 in play only 0 fits and it is found, its confidence at most the
    three-dot half times table_confidence; with every id in play it is ambiguous and nothing is
    reported for it (never a wrong id)."""
    model = cameras[0]
    robots = _robots(model, [0, 2, 5, 7])
    image, _ = render(model, snapshot(robots))
    _hide_dot(image, model, robots[0], 2)
    base = VisionParams().patterns
    params = VisionParams(patterns=dataclasses.replace(base, min_dots=3, ids_in_play=ids_in_play))
    det = VisionPipeline(params, LEAGUE, model).process(image, 0, 0.0)
    assert sorted(r.id for r in det.robots) == ([0, 2, 5, 7] if found else [2, 5, 7])
    if found:
        zero = next(r for r in det.robots if r.id == 0)
        assert math.hypot(zero.x - robots[0][2], zero.y - robots[0][3]) < 0.005
        assert zero.confidence <= 0.5 * base.table_confidence + 1e-9
        assert all(r.confidence > 0.5 for r in det.robots if r.id != 0)
    # four dots needed (the default): the cover is not reported
    strict = VisionPipeline(dataclasses.replace(params, patterns=dataclasses.replace(params.patterns, min_dots=4)),
                            LEAGUE, model).process(image, 0, 0.0)
    assert sorted(r.id for r in strict.robots) == [2, 5, 7]


def _lab_league(diameter_m: float) -> LeagueParams:
    return dataclasses.replace(LEAGUE, ball=dataclasses.replace(BallShape(), radius_m=diameter_m / 2))


@pytest.mark.parametrize("diameter_m", [0.043, 0.084, 0.065])
def test_the_ball_size_comes_from_the_field_config(cameras: list[CameraModel], diameter_m: float) -> None:
    """A lab's ball (84 mm orange, 65 mm tennis-ball size) or the league's: found within 3 mm
    with field.yaml's ball size; a ball twice the configured diameter is refused."""
    model = cameras[0]
    league = _lab_league(diameter_m)
    r = diameter_m / 2
    ball = model.unproject(np.array([[600.0, 420.0]]), r)[0]
    renderer = CameraRenderer(model, league, RenderParams(), seed=3)
    image, _ = renderer.render(snapshot(_robots(model, [4]), ball=(ball[0], ball[1], r)))
    (got,) = VisionPipeline(VisionParams(), league, model).process(image.copy(), 0, 0.0).balls
    assert math.hypot(got.x - ball[0], got.y - ball[1]) < 0.003
    assert got.confidence > 0.5
    half = _lab_league(diameter_m / 2)
    assert VisionPipeline(VisionParams(), half, model).process(image.copy(), 0, 0.0).balls == ()


def test_the_field_mask_drops_what_lies_outside(cameras: list[CameraModel]) -> None:
    """Camera 0 sees 0.25 m past the goal line. With a mask 0.1 m past the lines: a robot and an
    orange thing on the floor past it are not reported, while the ball on the field is, though the
    orange thing is larger and rounder; with no mask both outside things are reported."""
    model = cameras[0]
    hl = LEAGUE.dims.length_m / 2
    x_out = -hl - 0.2
    inside = _robots(model, [3])[0]
    outside = [1, 5, -hl - 0.14, 0.5, 0.3]  # its whole top in the image
    r = LEAGUE.ball.radius_m
    ball = model.unproject(np.array([[600.0, 420.0]]), r)[0]
    image, _ = render(model, snapshot([inside, outside], ball=(ball[0], ball[1], r)))
    u, v = model.project_xy(np.array([x_out + 0.02, -0.8]), 0.0)
    radius = r * model.pixels_per_metre((x_out, -0.8), 0.0)
    cv2.circle(image, (int(u), int(v)), int(round(radius)), (20, 115, 250), -1, cv2.LINE_AA)
    masked = VisionPipeline(VisionParams(field_margin_m=0.1), LEAGUE, model).process(image, 0, 0.0)
    assert [(r_.team, r_.id) for r_ in masked.robots] == [(TEAMS[0], 3)]
    assert len(masked.balls) == 1 and math.hypot(masked.balls[0].x - ball[0], masked.balls[0].y - ball[1]) < 0.003
    base = VisionParams()
    loose = VisionParams(field_margin_m=-1.0, ball=dataclasses.replace(base.ball, max_balls=2))
    free = VisionPipeline(loose, LEAGUE, model).process(image, 0, 0.0)
    assert sorted((r_.team, r_.id) for r_ in free.robots) == [(TEAMS[0], 3), (TEAMS[1], 5)]
    assert len(free.balls) == 2 and min(b.x for b in free.balls) < -hl - 0.1
    # the default mask (the boundary width, 0.3 m) keeps all that lies inside the walls
    default = VisionPipeline(VisionParams(), LEAGUE, model).process(image, 0, 0.0)
    assert sorted((r_.team, r_.id) for r_ in default.robots) == [(TEAMS[0], 3), (TEAMS[1], 5)]


@pytest.mark.parametrize("area", [0.3, 0.45, 0.7, 0.9, 1.5])
def test_the_confidence_follows_the_dot_area_the_matcher_accepts(area: float) -> None:
    """A perfect fit whose smallest dot shows ``area`` of its expected area: the confidence is that
    share of 90% (the blurred rim lost counts whole), so a dot at the smallest accepted area (0.3)
    still gives a robot, at a third of the confidence."""
    import itertools

    from vision.patterns import PatternMatcher

    params = VisionParams().patterns
    matcher = PatternMatcher(LEAGUE.pattern, params)
    slots = np.array(LEAGUE.pattern.dot_positions_m)
    theta = 0.7
    c, s = math.cos(theta), math.sin(theta)
    dots = slots @ np.array([[c, s], [-s, c]]) + [1.0, -0.5]
    weights = np.array([1.0, area, 1.0, 1.0])
    assign = np.array(list(itertools.permutations(range(4))), dtype=np.int64)
    table = kern.match_patterns(np.array([[1.0, -0.5]]), np.ones(1), dots, weights, np.array([True, True, False, True]),
                                weights >= params.min_area_fraction, slots, assign, params.search_radius_m,
                                params.min_dots, matcher.id_of_code, params.max_residual_m, params.residual_scale_m,
                                params.min_confidence)
    row = table[0]
    assert row[kern.M_VERDICT] == kern.V_ROBOT and row[kern.M_ID] == 0  # PPGP
    assert row[kern.M_CONF] == pytest.approx(min(1.0, area / 0.9), rel=1e-6)


def test_a_fifth_candidate_on_the_ring_does_not_displace_a_dot() -> None:
    """Four dots 1 mm off their places and a fifth dot-sized region exactly on the pattern's ring
    between the front dots (what a light segment's remnant on a real cover is): every choice of
    four among the candidates is fitted, and the true four give the id and pose (the four
    nearest the ring would have taken the decoy)."""
    import itertools

    from vision.patterns import PatternMatcher

    params = VisionParams().patterns
    matcher = PatternMatcher(LEAGUE.pattern, params)
    slots = np.array(LEAGUE.pattern.dot_positions_m)
    ring = float(np.mean(np.hypot(slots[:, 0], slots[:, 1])))
    radial = slots / np.hypot(slots[:, 0], slots[:, 1])[:, None]
    dots = np.vstack([slots + 0.001 * radial, [[ring, 0.0]]])  # in the robot frame, heading 0
    pink = np.array([False, True, False, True, False])  # GPGP: id 1; the decoy green
    weights = np.ones(5)
    assign = np.array(list(itertools.permutations(range(4))), dtype=np.int64)
    table = kern.match_patterns(np.zeros((1, 2)), np.ones(1), dots, weights, pink, weights > 0, slots, assign,
                                params.search_radius_m, params.min_dots, matcher.id_of_code, params.max_residual_m,
                                params.residual_scale_m, params.min_confidence)
    row = table[0]
    assert row[kern.M_VERDICT] == kern.V_ROBOT and row[kern.M_ID] == 1
    assert math.hypot(row[kern.M_X], row[kern.M_Y]) < 0.001 and abs(row[kern.M_THETA]) < 0.01
