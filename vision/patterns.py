"""Robot pattern and ball detection from colour regions (Bruce's thesis, appendix A.2).

Robots carry the league's standard pattern (:class:`cmdragons.geometry.PatternGeometry`): a
team-colour centre dot and four pink/green id dots. Each centre region is projected to the field
on the plane of the robot tops; the pink and green regions around it are gathered and the dot
arrangement is fitted to the template by weighted least squares over position and heading, for
every assignment of dots to template slots (A.2.2-A.2.3), and, where more candidates lie round
a centre than the pattern has dots (a light part of a real cover passing for a dot), for every
choice of four among them. The best fit gives the slots' colours, hence the id, the centre and the
heading; its residual and the regions' areas give a confidence. A cover with one dot not found is
read with three (``min_dots: 3``): the fourth dot's colour read where the fit puts it, or, where
neither colour is there (the dot hidden), the one id in play (``ids_in_play``) the three fit; its
confidence is halved, and lowered again for an id from the table.

The ball is the orange region of the right size and shape that is not inside a detected robot's
pattern; its centre in the image is the centroid of each pixel's ball coverage, read by unmixing
the pixel's colour into ball and background (:func:`ball_centre_reference`), not of the
thresholded pixels, so that it follows the ball between pixels and keeps the shaded rim; it is
projected on the plane of a calibrated height above the ball centre.

Field frame, metres, radians; pixels as in :mod:`vision.cmvision`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.config import Validated, setting
from cmdragons.geometry import TEAMS, PatternGeometry, Team
from cmdragons.messages import BallDetection, RobotDetection
from vision import _kernels as kern
from vision.cmvision import Regions

F64 = NDArray[np.float64]

__all__ = [
    "BallParams",
    "PatternMatcher",
    "PatternParams",
    "RegionGeometry",
    "ball_centre_reference",
    "detect_ball",
    "fit_reference",
]


@dataclass(frozen=True)
class PatternParams(Validated):
    """configs/vision.yaml ``patterns``: matching the standard robot pattern."""

    search_radius_m: float = setting(0.1, lo=0.02, hi=0.5)  # id dots this far from the centre dot, at most
    max_residual_m: float = setting(0.02, lo=0.001, hi=0.2)  # RMS fit residual above which no robot is reported
    residual_scale_m: float = setting(0.006, lo=0.0005, hi=0.1)  # confidence exp(-(res/scale)^2 / 2)
    min_area_fraction: float = setting(0.3, lo=0.0, hi=1.0)  # of a dot's expected area, for centre and id dots
    max_area_fraction: float = setting(2.5, lo=1.0, hi=20.0)
    # id dots needed; with 3 the missing slot's colour is read from the image, or, where nothing of
    # either colour is there (a dot hidden), taken from the ids in play when only one of them fits
    min_dots: int = setting(3, lo=3, hi=4)
    ids_in_play: tuple[int, ...] = setting((), lo=0, hi=15)  # ids of the covers in use; empty: every id
    table_confidence: float = setting(0.8, lo=0.0, hi=1.0)  # times the 3-dot confidence, for an id from the table
    duplicate_distance_m: float = setting(0.12, lo=0.0, hi=1.0)  # closer robots are one robot seen twice
    min_confidence: float = setting(0.1, lo=0.0, hi=1.0)


@dataclass(frozen=True)
class BallParams(Validated):
    """configs/vision.yaml ``ball``: which orange regions are balls."""

    min_area_fraction: float = setting(0.3, lo=0.0, hi=1.0)  # of the ball's expected area in the image
    max_area_fraction: float = setting(3.0, lo=1.0, hi=50.0)  # motion blur stretches a fast ball
    max_elongation: float = setting(3.0, lo=1.0, hi=50.0)  # ratio of the second moments' axes
    min_fill: float = setting(0.4, lo=0.0, hi=1.0)  # area / bounding-box area
    max_balls: int = setting(1, lo=0, hi=16)  # per camera frame, most confident first
    min_confidence: float = setting(0.1, lo=0.0, hi=1.0)
    # the ball's centre in the image: "coverage", the centroid of each pixel's unmixed ball coverage
    # over the region's box grown by centre_margin_px; "centroid", the region's thresholded pixels
    centre: str = setting("coverage", choices=("coverage", "centroid"))
    centre_margin_px: int = setting(1, lo=1, hi=4)
    # each detection's position standard deviation (coverage centre only): the centre's noise from
    # false coverage (vision._kernels.ball_centre), a hidden part's pull (the centre of a disc with
    # a share h cut off by a robot or the image's edge moves about h ball radii: 0.42 for half),
    # and this floor for what neither covers (the shading, the calibration)
    sigma_floor_m: float = setting(0.0002, lo=0.0, hi=0.1)
    hidden_shift_radii: float = setting(1.0, lo=0.0, hi=10.0)  # centre shift per hidden share of the disc, ball radii
    # the blob's centre sits this far above the ball's centre, as seen from the camera (the coverage
    # centre: the silhouette's; the thresholded centroid: higher, its shaded lower rim drops out of
    # the orange class); vision.score.ball_height_bias_m measures what is left
    blob_height_above_centre_m: float = setting(0.0006, lo=-0.05, hi=0.05)


class RegionGeometry:
    """Where the regions of one image lie on the field: each centroid's ray (dx, dy per metre of
    descent) from the camera's per-pixel ray grid, and the field area of one pixel per metre of
    descent squared. A plane at height z is then ``centre_xy + (centre_z - z) * ray``."""

    def __init__(self, regions: Regions, camera: CameraModel, grid: NDArray[np.float32]) -> None:
        self.regions = regions
        self.camera = camera
        self.grid = grid
        self.rays, self.pixel_area = kern.region_rays(grid, regions.centroid)

    def xy(self, idx: NDArray[np.int64], z: float) -> NDArray[np.float64]:
        """Field points (n, 2) of regions ``idx`` on the plane at height ``z`` (m)."""
        out: NDArray[np.float64] = self.camera.center[:2] + (self.camera.center[2] - z) * self.rays[idx]
        return out

    def pixel_xy(self, pixels: NDArray[np.float64], z: float) -> NDArray[np.float64]:
        """Field points (n, 2) of image points ``pixels`` (n, 2) (u, v) on the plane at height ``z`` (m)."""
        rays, _ = kern.region_rays(self.grid, np.ascontiguousarray(pixels, dtype=np.float64))
        out: NDArray[np.float64] = self.camera.center[:2] + (self.camera.center[2] - z) * rays
        return out

    def area_m2(self, idx: NDArray[np.int64], z: float) -> NDArray[np.float64]:
        """Field areas (n,) m^2 of regions ``idx`` on the plane at height ``z``."""
        out: NDArray[np.float64] = self.regions.area[idx] * self.pixel_area[idx] * (self.camera.center[2] - z) ** 2
        return out


def fit_reference(centre: F64, w_centre: float, obs: F64, w_obs: F64, slots: F64) -> tuple[F64, F64, F64]:
    """Weighted least-squares rigid fits (2D Procrustes) of the pattern to the observed dots, for
    every row of ``slots`` (m, k, 2): the template positions the k observed dots are assigned to;
    the centre dot sits at the template origin. Returns heading (m,), position (m, 2) and the
    weighted RMS residual (m,). The plain-numpy reference of :func:`vision._kernels.fit_pattern`."""
    m = slots.shape[0]
    w_all = np.concatenate([[w_centre], w_obs])
    wsum = w_all.sum()
    o = np.concatenate([centre[None], obs], axis=0)  # (k+1, 2)
    t = np.concatenate([np.zeros((m, 1, 2)), slots], axis=1)  # (m, k+1, 2)
    mo = (w_all[:, None] * o).sum(axis=0) / wsum
    mt = (w_all[None, :, None] * t).sum(axis=1) / wsum  # (m, 2)
    oc = o[None] - mo
    tc = t - mt[:, None]
    cross = (w_all * (tc[..., 0] * oc[..., 1] - tc[..., 1] * oc[..., 0])).sum(axis=1)
    dot = (w_all * (tc[..., 0] * oc[..., 0] + tc[..., 1] * oc[..., 1])).sum(axis=1)
    theta = np.arctan2(cross, dot)
    c, s = np.cos(theta), np.sin(theta)
    pos = mo - np.stack([c * mt[:, 0] - s * mt[:, 1], s * mt[:, 0] + c * mt[:, 1]], axis=1)
    rx = c[:, None] * t[..., 0] - s[:, None] * t[..., 1] + pos[:, 0:1]
    ry = s[:, None] * t[..., 0] + c[:, None] * t[..., 1] + pos[:, 1:2]
    err2 = (rx - o[None, :, 0]) ** 2 + (ry - o[None, :, 1]) ** 2
    res = np.sqrt((w_all * err2).sum(axis=1) / wsum)
    return theta, pos, res


class PatternMatcher:
    """The standard pattern of one league, ready to match (templates, id table, expected areas)."""

    def __init__(self, pattern: PatternGeometry, params: PatternParams) -> None:
        self.pattern, self.params = pattern, params
        self.slots = np.array(pattern.dot_positions_m, dtype=np.float64)
        self.assign = np.array(list(itertools.permutations(range(len(self.slots)))), dtype=np.int64)
        # the id of each code (pink slots as bits), -1 for a code no robot has
        self.id_of_code = np.full(1 << len(self.slots), -1, dtype=np.int64)
        in_play = set(params.ids_in_play) or set(range(len(pattern.ids)))
        for i, code in enumerate(pattern.ids):
            if i in in_play:
                self.id_of_code[sum(1 << s for s, ch in enumerate(code) if ch == "P")] = i
        self.centre_area = math.pi * (pattern.center_dot_diameter_m / 2.0) ** 2
        self.dot_area = math.pi * (pattern.id_dot_diameter_m / 2.0) ** 2

    def detect(self, geo: RegionGeometry, classes: dict[str, int], height_m: dict[Team, float],
               is_pink: Callable[[NDArray[np.float64]], bool | None]) -> list[RobotDetection]:
        """Robots of both teams; ``classes`` maps the roles blue, yellow, pink, green to class
        indices; ``is_pink(pixel)`` reads an id dot's colour at a pixel where no region was found
        (None: neither colour). Duplicates (one robot found twice) are merged."""
        regions, params = geo.regions, self.params
        lo, hi = params.min_area_fraction, params.max_area_fraction
        pink_idx, green_idx = regions.of_class(classes["pink"]), regions.of_class(classes["green"])
        dot_idx = np.concatenate([pink_idx, green_idx])
        dpink = np.arange(dot_idx.size) < pink_idx.size
        found: list[RobotDetection] = []
        for team in TEAMS:
            z = height_m[team]
            c_idx = regions.of_class(classes[team])
            cw = geo.area_m2(c_idx, z) / self.centre_area
            ok = (cw >= lo) & (cw <= hi)
            if not ok.any() or dot_idx.size < params.min_dots:
                continue
            c_idx, cw = c_idx[ok], cw[ok]
            dw = geo.area_m2(dot_idx, z) / self.dot_area
            table = kern.match_patterns(geo.xy(c_idx, z), cw, geo.xy(dot_idx, z), dw, dpink, (dw >= lo) & (dw <= hi),
                                        self.slots, self.assign, params.search_radius_m, params.min_dots,
                                        self.id_of_code, params.max_residual_m, params.residual_scale_m,
                                        params.min_confidence)
            for r in np.flatnonzero(table[:, kern.M_VERDICT] != kern.V_REJECT):
                row, robot_id = table[r], int(table[r, kern.M_ID])
                conf = float(row[kern.M_CONF])
                if row[kern.M_VERDICT] == kern.V_READ_MISSING:
                    robot_id, seen = self._complete(row, z, geo.camera, is_pink)
                    if robot_id < 0:
                        continue
                    conf *= 1.0 if seen else params.table_confidence
                pixel = regions.centroid[c_idx[r]]
                heading = math.remainder(float(row[kern.M_THETA]), 2.0 * math.pi)
                found.append(RobotDetection(team, robot_id, float(row[kern.M_X]), float(row[kern.M_Y]), heading,
                                            conf, (float(pixel[0]), float(pixel[1]))))
        return merge_duplicates(found, params.duplicate_distance_m)

    def _complete(self, row: NDArray[np.float64], z: float, camera: CameraModel,
                  is_pink: Callable[[NDArray[np.float64]], bool | None]) -> tuple[int, bool]:
        """The id of a fit with a dot the regions missed (glare, a dark corner), its colour read
        where the fit puts it, and True; where neither colour is there (the dot hidden), the one id
        in play that the three dots seen fit, and False; -1 where the colour read makes a code no
        robot in play has, or where both colours make one (ambiguous)."""
        missing = int(row[kern.M_MISSING])
        c, s = math.cos(row[kern.M_THETA]), math.sin(row[kern.M_THETA])
        sx, sy = self.slots[missing]
        at = camera.project_xy(np.array([row[kern.M_X] + c * sx - s * sy, row[kern.M_Y] + s * sx + c * sy]), z)
        colour = is_pink(at)
        pink = int(row[kern.M_PINK])
        if colour is not None:
            return int(self.id_of_code[pink | int(colour) << missing]), True
        fits = [int(i) for i in (self.id_of_code[pink], self.id_of_code[pink | 1 << missing]) if i >= 0]
        return (fits[0] if len(fits) == 1 else -1), False


def merge_duplicates(robots: list[RobotDetection], distance_m: float) -> list[RobotDetection]:
    """Most confident first; a detection of a (team, id) already reported, or closer than
    ``distance_m`` to a reported robot, is the same robot seen twice and is dropped."""
    if not robots:
        return []
    xy = np.array([(r.x, r.y) for r in robots])
    conf = np.array([r.confidence for r in robots])
    key = np.array([r.id * len(TEAMS) + TEAMS.index(r.team) for r in robots], dtype=np.int64)
    return [robots[k] for k in kern.distinct_robots(xy, conf, key, distance_m)]


def ball_centre_reference(image: NDArray[np.uint8], box: NDArray[np.float64],
                          margin: int) -> tuple[float, float, float, float]:
    """The ball's centre (u, v at pixel centres) from the coverage of the pixels around its
    region's box (u0, v0, u1, v1 inclusive) grown by ``margin``, the coverage's sum (px) and the
    centre's standard deviation per axis (px) from false coverage: the plain-numpy reference of
    :func:`vision._kernels.ball_centre`, which explains the unmixing and the deviation."""
    nan4 = (math.nan, math.nan, math.nan, math.nan)
    h, w = image.shape[:2]
    u0, v0, u1, v1 = (int(x) for x in box)
    wu0, wv0, wu1, wv1 = max(u0 - margin, 0), max(v0 - margin, 0), min(u1 + margin, w - 1), min(v1 + margin, h - 1)
    ring = np.zeros((h, w), dtype=bool)
    ring[max(wv0 - 1, 0) : wv1 + 2, max(wu0 - 1, 0) : wu1 + 2] = True
    ring[wv0 : wv1 + 1, wu0 : wu1 + 1] = False
    px = image.astype(np.float64)
    if not ring.any():
        return nan4
    bg = np.median(px[ring], axis=0)
    inner = px[v0 + 1 : v1, u0 + 1 : u1] if u1 - u0 >= 2 and v1 - v0 >= 2 else px[v0 : v1 + 1, u0 : u1 + 1]
    ball = inner.reshape(-1, 3).sum(axis=0)
    if ball @ ball <= 0.0:
        return nan4
    off = bg - (bg @ ball) / (ball @ ball) * ball
    den = bg @ off
    if den < 1.0:
        return nan4
    cover = np.clip(1.0 - px[wv0 : wv1 + 1, wu0 : wu1 + 1] @ off / den, 0.0, 1.0)
    total = float(cover.sum())
    if total <= 0.0:
        return nan4
    v, u = np.mgrid[wv0 : wv1 + 1, wu0 : wu1 + 1]
    cu, cv = float((cover * u).sum()) / total, float((cover * v).sum()) / total
    false_cover = np.maximum(1.0 - px[ring] @ off / den, 0.0)  # the ring is background: any coverage there is false
    lever2 = 0.5 * float(((u - cu) ** 2 + (v - cv) ** 2).sum())
    sigma = math.sqrt(float(np.mean(false_cover**2)) * lever2) / total
    return cu + 0.5, cv + 0.5, total, sigma


def detect_ball(
    geo: RegionGeometry,
    image: NDArray[np.uint8],
    orange: int,
    ball_radius_m: float,
    robots: list[RobotDetection],
    robot_height_m: dict[Team, float],
    pattern_radius_m: float,
    params: BallParams,
    in_field: Callable[[float, float], bool] = lambda x, y: True,
) -> list[BallDetection]:
    """Ball candidates: orange regions of the ball's size and shape, not inside a detected
    robot's pattern, inside the field mask ``in_field(x, y)``, centred as ``params.centre`` says
    in ``image`` (H, W, 3) BGR uint8 and projected on the plane of the ball centre's height plus
    ``params.blob_height_above_centre_m``; most confident first."""
    regions = geo.regions
    idx = regions.of_class(orange)
    if idx.size == 0 or params.max_balls == 0:
        return []
    heights = [robot_height_m[r.team] for r in robots]
    keep, ratio, elong = kern.ball_candidates(
        regions.area[idx], regions.moments[idx], regions.bbox[idx], geo.rays[idx], geo.pixel_area[idx],
        geo.camera.center, ball_radius_m, np.array([(r.x, r.y) for r in robots]).reshape(-1, 2),
        np.array(heights, dtype=np.float64), pattern_radius_m, params.min_area_fraction, params.max_area_fraction,
        params.max_elongation, params.min_fill)
    px = regions.centroid[idx]
    z = ball_radius_m + params.blob_height_above_centre_m
    sigma = np.full(idx.size, math.nan)
    if params.centre == "coverage":
        px = px.copy()
        # metres per pixel on the ball's plane, and the whole ball's area in pixels
        m_per_px = np.sqrt(geo.pixel_area[idx]) * (geo.camera.center[2] - z)
        disc_px = math.pi * ball_radius_m**2 / m_per_px**2
        for j in np.flatnonzero(keep):
            u, v, covered, noise_px = kern.ball_centre(image, regions.bbox[idx[j]], params.centre_margin_px)
            if math.isfinite(u):  # else (ball and background alike) the region's centroid
                px[j] = (u, v)
                hidden = max(0.0, 1.0 - covered / disc_px[j])  # share of the disc not seen
                hidden_px = params.hidden_shift_radii * math.sqrt(disc_px[j] / math.pi) * hidden
                sigma[j] = math.hypot(params.sigma_floor_m, m_per_px[j] * math.hypot(noise_px, hidden_px))
    xy = geo.pixel_xy(px, z)
    out = []
    for j in np.flatnonzero(keep):
        size_conf = min(ratio[j], 1.0 / ratio[j])
        shape_conf = min(1.0, 1.5 / elong[j])
        conf = float(np.clip(size_conf * shape_conf / 0.6, 0.0, 1.0))
        if conf >= params.min_confidence and in_field(float(xy[j, 0]), float(xy[j, 1])):
            out.append(BallDetection(float(xy[j, 0]), float(xy[j, 1]), conf, (float(px[j, 0]), float(px[j, 1])),
                                     float(sigma[j])))
    out.sort(key=lambda b: -b.confidence)
    return out[: params.max_balls]
