"""Robot pattern and ball detection from colour regions (Bruce's thesis, appendix A.2).

Robots carry the league's standard pattern (:class:`cmdragons.geometry.PatternGeometry`): a
team-colour centre dot and four pink/green id dots. Each centre region is projected to the field
on the plane of the robot tops; the pink and green regions around it are gathered and the dot
arrangement is fitted to the template by weighted least squares over position and heading, for
every assignment of dots to template slots (A.2.2-A.2.3). The best fit gives the slots' colours,
hence the id, the centre and the heading; its residual and the regions' areas give a confidence.

The ball is the orange region of the right size and shape, on the plane of the ball centre,
that is not inside a detected robot's pattern.

Field frame, metres, radians; pixels as in :mod:`vision.cmvision`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.config import Validated, setting
from cmdragons.geometry import TEAMS, PatternGeometry, Team
from cmdragons.messages import BallDetection, RobotDetection
from vision.cmvision import Regions

__all__ = ["BallParams", "PatternParams", "detect_ball", "detect_robots", "field_regions"]


@dataclass(frozen=True)
class PatternParams(Validated):
    """configs/vision.yaml ``patterns``: matching the standard robot pattern."""

    search_radius_m: float = setting(0.1, lo=0.02, hi=0.5)  # id dots this far from the centre dot, at most
    max_residual_m: float = setting(0.02, lo=0.001, hi=0.2)  # RMS fit residual above which no robot is reported
    residual_scale_m: float = setting(0.006, lo=0.0005, hi=0.1)  # confidence exp(-(res/scale)^2 / 2)
    min_area_fraction: float = setting(0.3, lo=0.0, hi=1.0)  # of a dot's expected area, for centre and id dots
    max_area_fraction: float = setting(2.5, lo=1.0, hi=20.0)
    min_dots: int = setting(4, lo=3, hi=4)  # id dots needed; with 3 the missing slot's colour is read from the image
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


@dataclass(frozen=True)
class FieldRegions:
    """Regions placed on a horizontal plane: field position (n, 2) m and area (n,) m^2."""

    xy: NDArray[np.float64]
    area_m2: NDArray[np.float64]
    pixel: NDArray[np.float64]


def field_regions(regions: Regions, idx: NDArray[np.int64], camera: CameraModel, z: float) -> FieldRegions:
    """Regions ``idx`` projected to the field plane at height ``z`` (m): centroid through the
    camera model, pixel area through the local Jacobian of the pixel -> field map."""
    px = regions.centroid[idx]
    if idx.size == 0:
        return FieldRegions(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)))
    pts = np.concatenate([px, px + [1.0, 0.0], px + [0.0, 1.0]], axis=0)
    xy = camera.unproject(pts, z)
    n = idx.size
    du, dv = xy[n : 2 * n] - xy[:n], xy[2 * n :] - xy[:n]
    jac = np.abs(du[:, 0] * dv[:, 1] - du[:, 1] * dv[:, 0])
    return FieldRegions(xy[:n], regions.area[idx] * jac, px)


def _templates(pattern: PatternGeometry) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    slots = np.array(pattern.dot_positions_m, dtype=np.float64)
    perms = np.array(list(itertools.permutations(range(len(slots)))), dtype=np.int64)
    return slots, perms


F64 = NDArray[np.float64]


def _fit(centre: F64, w_centre: float, obs: F64, w_obs: F64, slots: F64) -> tuple[F64, F64, F64]:
    """Weighted least-squares rigid fits (2D Procrustes) of the pattern to the observed dots, for
    every row of ``slots`` (m, k, 2): the template positions the k observed dots are assigned to.
    The centre dot sits at the template origin. Returns heading (m,), position (m, 2) and the
    weighted RMS residual (m,)."""
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


@dataclass(frozen=True)
class _Dots:
    xy: NDArray[np.float64]
    area_m2: NDArray[np.float64]
    pink: NDArray[np.bool_]


def detect_robots(regions: Regions, classes: dict[str, int], camera: CameraModel, pattern: PatternGeometry,
                  height_m: dict[Team, float], params: PatternParams) -> list[RobotDetection]:  # fmt: skip
    """Robots of both teams from the regions of one image; ``classes`` maps the roles blue,
    yellow, pink, green to class indices. Duplicates (one robot found twice) are merged."""
    slots, perms = _templates(pattern)
    code_to_id = {code: i for i, code in enumerate(pattern.ids)}
    centre_area = math.pi * (pattern.center_dot_diameter_m / 2.0) ** 2
    dot_area = math.pi * (pattern.id_dot_diameter_m / 2.0) ** 2
    lo, hi = params.min_area_fraction, params.max_area_fraction
    found: list[RobotDetection] = []
    for team in TEAMS:
        z = height_m[team]
        centres = field_regions(regions, regions.of_class(classes[team]), camera, z)
        ok = (centres.area_m2 >= lo * centre_area) & (centres.area_m2 <= hi * centre_area)
        if not ok.any():
            continue
        pink = field_regions(regions, regions.of_class(classes["pink"]), camera, z)
        green = field_regions(regions, regions.of_class(classes["green"]), camera, z)
        dots = _Dots(
            np.concatenate([pink.xy, green.xy]), np.concatenate([pink.area_m2, green.area_m2]),
            np.concatenate([np.ones(len(pink.xy), bool), np.zeros(len(green.xy), bool)]),
        )  # fmt: skip
        good = (dots.area_m2 >= lo * dot_area) & (dots.area_m2 <= hi * dot_area)
        for k in np.flatnonzero(ok):
            det = _match(team, centres.xy[k], centres.area_m2[k], centres.pixel[k], dots, good, slots, perms,
                         code_to_id, centre_area, dot_area, params)  # fmt: skip
            if det is not None:
                found.append(det)
    return merge_duplicates(found, params.duplicate_distance_m)


def _match(team: str, centre: NDArray[np.float64], centre_a: float, pixel: NDArray[np.float64], dots: _Dots,
           good: NDArray[np.bool_], slots: NDArray[np.float64], perms: NDArray[np.int64], code_to_id: dict[str, int],
           centre_area: float, dot_area: float, params: PatternParams) -> RobotDetection | None:  # fmt: skip
    d = np.hypot(dots.xy[:, 0] - centre[0], dots.xy[:, 1] - centre[1])
    near = np.flatnonzero(good & (d <= params.search_radius_m))
    if near.size < params.min_dots:
        return None
    ring = float(np.mean(np.hypot(slots[:, 0], slots[:, 1])))
    if near.size > len(slots):  # the dots nearest the pattern's ring
        near = near[np.argsort(np.abs(d[near] - ring))[: len(slots)]]
    k = near.size
    # each assignment of the k observed dots to k distinct template slots
    assign = np.unique(perms[:, :k], axis=0)
    w_obs = dots.area_m2[near] / dot_area
    theta, pos, res = _fit(centre, centre_a / centre_area, dots.xy[near], w_obs, slots[assign])
    best = int(np.argmin(res))
    if res[best] > params.max_residual_m:
        return None
    if k < len(slots):
        return None  # TODO(min_dots=3): read the missing slot's colour from the image
    code = ["?"] * len(slots)
    for obs_i, slot in enumerate(assign[best]):
        code[slot] = "P" if dots.pink[near[obs_i]] else "G"
    rid = code_to_id.get("".join(code))
    if rid is None:
        return None
    areas = np.concatenate([[centre_a / centre_area], w_obs])
    area_conf = float(np.clip(np.min(np.minimum(areas, 1.0 / np.maximum(areas, 1e-9))) / 0.5, 0.0, 1.0))
    conf = math.exp(-0.5 * (float(res[best]) / params.residual_scale_m) ** 2) * area_conf
    if conf < params.min_confidence:
        return None
    return RobotDetection(team, rid, float(pos[best, 0]), float(pos[best, 1]),  # type: ignore[arg-type]
                          math.remainder(float(theta[best]), 2.0 * math.pi), conf,
                          (float(pixel[0]), float(pixel[1])))  # fmt: skip


def merge_duplicates(robots: list[RobotDetection], distance_m: float) -> list[RobotDetection]:
    """Most confident first; a detection of a (team, id) already reported, or closer than
    ``distance_m`` to a reported robot, is the same robot seen twice and is dropped."""
    kept: list[RobotDetection] = []
    for r in sorted(robots, key=lambda r: -r.confidence):
        if any((k.team == r.team and k.id == r.id) or math.hypot(k.x - r.x, k.y - r.y) < distance_m for k in kept):
            continue
        kept.append(r)
    return kept


def detect_ball(regions: Regions, orange: int, camera: CameraModel, ball_radius_m: float,
                robots: list[RobotDetection], robot_height_m: dict[Team, float], pattern_radius_m: float,
                params: BallParams) -> list[BallDetection]:  # fmt: skip
    """Ball candidates: orange regions of the ball's size and shape, not inside a detected
    robot's pattern, on the plane of the ball centre; most confident first."""
    idx = regions.of_class(orange)
    if idx.size == 0 or params.max_balls == 0:
        return []
    reg = field_regions(regions, idx, camera, ball_radius_m)
    expected = math.pi * ball_radius_m**2
    ratio = reg.area_m2 / expected
    mom = regions.moments[idx]
    tr, det = mom[:, 0] + mom[:, 1], mom[:, 0] * mom[:, 1] - mom[:, 2] ** 2
    disc = np.sqrt(np.maximum(tr * tr / 4.0 - det, 0.0))
    elong = np.sqrt((tr / 2.0 + disc) / np.maximum(tr / 2.0 - disc, 1e-6))
    box = regions.bbox[idx]
    fill = regions.area[idx] / ((box[:, 2] - box[:, 0] + 1.0) * (box[:, 3] - box[:, 1] + 1.0))
    keep = (
        (ratio >= params.min_area_fraction) & (ratio <= params.max_area_fraction)
        & (elong <= params.max_elongation) & (fill >= params.min_fill)
    )  # fmt: skip
    if robots:
        # a pattern holds no orange: an orange spot inside one is a misread marker
        tops = np.array([[r.x, r.y] for r in robots])
        heights = np.array([robot_height_m[r.team] for r in robots])
        for j in np.flatnonzero(keep):
            at_top = np.stack([camera.unproject(reg.pixel[j], float(h)) for h in heights])
            if np.any(np.hypot(*(at_top - tops).T) < pattern_radius_m):
                keep[j] = False
    out = []
    for j in np.flatnonzero(keep):
        size_conf = min(ratio[j], 1.0 / ratio[j])
        shape_conf = min(1.0, 1.5 / elong[j])
        conf = float(np.clip(size_conf * shape_conf / 0.6, 0.0, 1.0))
        if conf >= params.min_confidence:
            out.append(BallDetection(float(reg.xy[j, 0]), float(reg.xy[j, 1]), conf,
                                     (float(reg.pixel[j, 0]), float(reg.pixel[j, 1]))))  # fmt: skip
    out.sort(key=lambda b: -b.confidence)
    return out[: params.max_balls]
