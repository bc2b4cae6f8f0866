"""Colour tuning: threshold boxes (thesis A.1.3) from sampled pixels.

Samples come with nothing labelled from a calibrated camera's frames (:func:`auto_samples`: the
robots' patterns and the ball found by their sizes and the pattern's geometry), from a user's
labels -- a few spots clicked on a real frame, each a colour name, a pixel position and a radius
-- or from a recording's truth, where every visible dot and the ball are known exactly. Each
colour's box spans a central share of its samples per channel of the colour space, widened by a
margin for light the samples did not see (and, learnt automatically, by the light's spread over
the field seen on the carpet: :func:`widen_for_light`); boxes that hold another class's samples,
or the carpet's or the lines', are cut apart (:func:`keep_apart`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.config import ConfigError, Validated, setting
from cmdragons.geometry import Field, LeagueParams
from cmdragons.recording import RecordingReader
from vision.cmvision import ColourClass, ColourSpace, convert_colour
from vision.sources import open_sources

__all__ = [
    "AutoTuneParams",
    "AutoTuneReport",
    "Label",
    "auto_samples",
    "hue_outliers",
    "learn_boxes",
    "boxes_from_samples",
    "keep_apart",
    "overlaps",
    "read_labels",
    "read_yaml_any",
    "samples_from_labels",
    "samples_from_truth",
    "widen_for_light",
]

Samples = dict[str, list[NDArray[np.int32]]]


@dataclass(frozen=True)
class Label:
    """A labelled spot: colour name, pixel (u, v) of its centre, radius in pixels, and the image
    it is on (index into the images given, default the first)."""

    colour: str
    pixel: tuple[float, float]
    radius_px: float
    image: int = 0


def read_yaml_any(path: str | Path) -> Any:
    """A YAML or JSON file (JSON is YAML) whose top level may be a list; raises ConfigError."""
    try:
        return yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise ConfigError(path, "", f"cannot read: {exc}") from None


def read_labels(path: str | Path) -> list[Label]:
    """A YAML (or JSON) list of ``{colour, pixel: [u, v], radius, image}``; raises ConfigError."""
    data = read_yaml_any(path)
    if isinstance(data, dict):
        data = data.get("labels")
    if not isinstance(data, list) or not data:
        raise ConfigError(path, "", "expected a list of labels {colour, pixel: [u, v], radius}")
    out = []
    for k, item in enumerate(data):
        try:
            u, v = item["pixel"]
            out.append(Label(str(item["colour"]), (float(u), float(v)), float(item.get("radius", 3.0)),
                             int(item.get("image", 0))))
        except (KeyError, TypeError, ValueError) as exc:
            raise ConfigError(path, f"[{k}]", f"bad label {item!r}: {exc}") from None
    return out


def _disc(image: NDArray[np.uint8], centre: tuple[float, float], radius: float) -> NDArray[np.uint8]:
    """Pixels (n, 3) whose centres lie within ``radius`` of ``centre`` (u, v)."""
    h, w = image.shape[:2]
    u, v = centre
    i0, i1 = max(0, int(v - radius)), min(h, int(math.ceil(v + radius)) + 1)
    j0, j1 = max(0, int(u - radius)), min(w, int(math.ceil(u + radius)) + 1)
    if i0 >= i1 or j0 >= j1:
        return np.zeros((0, 3), np.uint8)
    vv, uu = np.mgrid[i0:i1, j0:j1] + 0.5
    inside = (uu - u) ** 2 + (vv - v) ** 2 <= radius * radius
    out: NDArray[np.uint8] = image[i0:i1, j0:j1][inside]
    return out


def samples_from_labels(images: Sequence[NDArray[np.uint8]], labels: Iterable[Label], space: ColourSpace) -> Samples:
    out: Samples = {}
    for lab in labels:
        if not 0 <= lab.image < len(images):
            raise ValueError(f"label {lab} names image {lab.image}, but {len(images)} image(s) were given")
        px = _disc(images[lab.image], lab.pixel, lab.radius_px)
        out.setdefault(lab.colour, []).append(convert_colour(px[None], space)[0])
    return out


def samples_from_truth(recording: Path, league: LeagueParams, roles: Mapping[str, str], space: ColourSpace,
                       max_frames: int = 60, inner_fraction: float = 0.5) -> Samples:
    """Samples of every pattern dot and the ball a recording's truth says are visible: the inner
    ``inner_fraction`` of each dot's radius, in up to ``max_frames`` frames per camera. ``roles``
    maps ball, blue, yellow, pink, green to colour names."""
    reader = RecordingReader(recording)
    truth = {t.frame_number: t for t in reader.truth()}
    if not truth:
        raise ValueError(f"{recording}: no truth.jsonl to tune from")
    pat, h = league.pattern, league.robot.height_m
    out: Samples = {}

    def add(name: str, image: NDArray[np.uint8], model: CameraModel, xy: NDArray[np.float64], z: float,
            r_m: float) -> None:
        px = model.project_xy(xy, z)
        r_px = inner_fraction * r_m * model.pixels_per_metre((float(xy[0]), float(xy[1])), z)
        got = _disc(image, (float(px[0]), float(px[1])), max(r_px, 0.8))
        out.setdefault(name, []).append(convert_colour(got[None], space)[0])

    numbers = sorted(truth)
    wanted = set(numbers[:: max(1, len(numbers) // max_frames)][:max_frames])
    for src in open_sources([str(recording)])[0]:
        model = src.camera or reader.camera_model(src.camera_id)
        for k, image in src.frames():
            t = truth.get(k)
            if t is None or k not in wanted or image is None or image.shape != (model.height, model.width, 3):
                continue  # bad frames are the run's business, not the tuner's
            cam = src.camera_id
            for r in t.robots:
                if cam not in r.pixels:
                    continue
                add(roles[r.team], image, model, np.array([r.x, r.y]), h, pat.center_dot_diameter_m / 2)
                c, s = math.cos(r.theta), math.sin(r.theta)
                for (dx, dy), pink in zip(pat.dot_positions_m, pat.dot_is_pink(r.id), strict=True):
                    xy = np.array([r.x + c * dx - s * dy, r.y + s * dx + c * dy])
                    add(roles["pink" if pink else "green"], image, model, xy, h, pat.id_dot_diameter_m / 2)
            seen = t.ball.pixels.get(cam)
            if seen is not None and seen[2] >= 0.95 and t.ball.z < 2.0 * league.ball.radius_m:
                add(roles["ball"], image, model, np.array([t.ball.x, t.ball.y]), league.ball.radius_m,
                    league.ball.radius_m)
    return out


def boxes_from_samples(samples: Samples, share: float = 0.998, margin: int = 8,
                       min_area_px: int = 6) -> dict[str, ColourClass]:
    """Per colour, the box holding the central ``share`` of its samples in each channel, widened
    by ``margin`` grey levels."""
    out = {}
    tail = (1.0 - share) / 2.0 * 100.0
    for name, parts in samples.items():
        px = np.concatenate(parts, axis=0)
        if len(px) < 10:
            raise ValueError(f"colour {name!r}: only {len(px)} samples; label more or larger spots")
        lo = np.clip(np.floor(np.percentile(px, tail, axis=0)) - margin, 0, 255).astype(int)
        hi = np.clip(np.ceil(np.percentile(px, 100.0 - tail, axis=0)) + margin, 0, 255).astype(int)
        out[name] = ColourClass(lo=(int(lo[0]), int(lo[1]), int(lo[2])), hi=(int(hi[0]), int(hi[1]), int(hi[2])),
                                min_area_px=min_area_px)
    return out


@dataclass(frozen=True)
class AutoTuneParams(Validated):
    """What ``tune --auto`` takes for a coloured marker, a dot and a ball (grey levels, shares)."""

    min_contrast: float = setting(40.0, lo=1.0, hi=255.0)  # colour distance from the carpet's (Y counts half)
    min_saturation: float = setting(20.0, lo=0.0, hi=255.0)  # distance from grey in U, V: not white, grey, black
    area_range: tuple[float, float] = (0.3, 2.5)  # a blob's area against the dot's or ball's expected area
    dot_distance_tolerance_m: float = setting(0.015, lo=0.001, hi=0.05)  # id dots from the centre dot
    inner_fraction: float = setting(0.6, lo=0.1, hi=1.0)  # sampled within this share of a blob's expected radius
    max_overlap: float = setting(0.01, lo=0.0, hi=1.0)  # share of a class's samples in another's box: warned
    # a blob whose hue (its angle about grey in U, V) is further than this from its role's median blob's is
    # left out (a pink dot taken for a blue centre dot by its U, an orange ball for a pink dot): the hue, not the
    # brightness nor the saturation, since both scale with the light
    max_hue_off_deg: float = setting(30.0, lo=1.0, hi=180.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not 0.0 < self.area_range[0] < 1.0 < self.area_range[1]:
            raise ValueError(f"area_range must be [lo, hi] with 0 < lo < 1 < hi, got {list(self.area_range)}")


@dataclass(frozen=True)
class AutoTuneReport:
    """What ``tune --auto`` found: samples per role, and the background's (carpet, lines)."""

    samples: dict[str, list[NDArray[np.int32]]]  # role (ball, blue, yellow, pink, green) -> samples
    background: dict[str, NDArray[np.int32]]  # carpet, lines -> samples
    patterns: int  # standard patterns found (a centre dot with three or four id dots around it)
    balls: int
    # per role, how much darker and brighter the carpet gets over the field in view than it is
    # around the blobs sampled (the light's spread the role's box must reach)
    light: dict[str, tuple[float, float]]
    # per role, the blobs left out because their hue is off the role's (``max_hue_off_deg``)
    left_out: dict[str, int]


@dataclass(frozen=True)
class _Blob:
    label: int
    area: float
    pixel: NDArray[np.float64]  # centroid (u, v), px
    colour: NDArray[np.float64]  # mean Y, U, V


def _blobs(image: NDArray[np.uint8], model: CameraModel, league: LeagueParams,
           p: AutoTuneParams) -> tuple[list[_Blob], NDArray[np.int32], dict[str, NDArray[np.int32]]]:
    """Coloured blobs on the field (its boundary included): pixels far from the carpet's colour
    and from grey, grouped 8-connected. Returns the blobs, the label image and the background's
    samples (YUV): the carpet (the field's pixels near its median colour, off the lines) and the
    lines (pixels on the centres of the painted lines)."""
    yuv = convert_colour(image, "yuv")
    ground = model.center[:2] + model.center[2] * model.pixel_rays_grid().astype(np.float64)
    f = Field(league)
    inside = (np.abs(ground[..., 0]) <= f.boundary_half_length) & (np.abs(ground[..., 1]) <= f.boundary_half_width)
    if inside.sum() < 1000:
        raise ValueError("the calibrated camera sees almost none of the field: calibrate it first (vision calibrate)")
    carpet = np.median(yuv[inside], axis=0)
    d = yuv.astype(np.float64) - carpet
    contrast = np.sqrt((0.5 * d[..., 0]) ** 2 + d[..., 1] ** 2 + d[..., 2] ** 2)
    sat = np.hypot(yuv[..., 1] - 128.0, yuv[..., 2] - 128.0)
    coloured = inside & (contrast > p.min_contrast) & (sat > p.min_saturation)
    depth = float(model.center[2]) - league.robot.height_m
    if league.pattern.id_dot_diameter_m / 2.0 * model.f / depth >= 2.0:
        # id dots 4 px across or more: a 3x3 cross opening drops the colour fringes one or two pixels
        # wide that a Bayer sensor's demosaicing leaves along the white lines (they would join a ball on a line)
        cross = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))
        coloured = cv2.morphologyEx(coloured.astype(np.uint8), cv2.MORPH_OPEN, cross).astype(bool)
    n, labels, stats, cents = cv2.connectedComponentsWithStats(coloured.astype(np.uint8), connectivity=8)
    blobs = []
    sums = np.zeros((n, 3))
    flat = labels.ravel()
    for c in range(3):
        sums[:, c] = np.bincount(flat, weights=yuv[..., c].ravel().astype(np.float64), minlength=n)
    for k in range(1, n):
        area = float(stats[k, cv2.CC_STAT_AREA])
        if area >= 4:
            blobs.append(_Blob(k, area, cents[k] + 0.5, sums[k] / area))
    # the background: carpet near its median colour, and the painted lines' middles
    near_carpet = inside & (contrast < 0.5 * p.min_contrast)
    line_px = _line_pixels(model, league)
    background = {"carpet": yuv[near_carpet][:: max(1, int(near_carpet.sum()) // 20000)]}
    # the carpet's brightness around each pixel (its mean over about a robot's width), where it is seen
    win = max(9, int(0.4 * model.pixels_per_metre((float(model.center[0]), float(model.center[1])), 0.0)) | 1)
    seen = cv2.boxFilter(near_carpet.astype(np.float32), -1, (win, win), normalize=False)
    total = cv2.boxFilter(np.where(near_carpet, yuv[..., 0], 0).astype(np.float32), -1, (win, win), normalize=False)
    background["light"] = np.where(seen > 0, total / np.maximum(seen, 1.0), 0.0).astype(np.int32)
    if line_px.size:
        on_line = yuv[line_px[:, 1], line_px[:, 0]]
        background["lines"] = on_line[sat[line_px[:, 1], line_px[:, 0]] <= p.min_saturation]  # not a dot on it
    return blobs, labels.astype(np.int32), background


def _line_pixels(model: CameraModel, league: LeagueParams) -> NDArray[np.int64]:
    """Integer pixels (n, 2) (u, v) on the middles of the painted lines in view."""
    from vision.field_lines import field_samples  # calibration's field model: one description of the lines

    pts, _, _ = field_samples(league, 0.01)
    px = model.project(pts)
    ok = np.isfinite(px).all(axis=1) & model.in_image(np.nan_to_num(px, nan=-1.0), margin=1.0)
    return np.floor(px[ok]).astype(np.int64).clip(0, [model.width - 1, model.height - 1])


def auto_samples(images: Sequence[NDArray[np.uint8]], model: CameraModel, league: LeagueParams, space: ColourSpace,
                 params: AutoTuneParams | None = None) -> AutoTuneReport:
    """Colour samples of every role with nothing labelled, from frames of a calibrated camera
    (after Gunnarsson et al., "The Color and the Shape": regions matched to the shapes expected).

    Coloured blobs on the field are matched to the standard pattern's geometry (configs/field.yaml):
    a blob of the centre dot's size with three or four blobs of the id dots' size at the id dots'
    distance around it is a robot; its centre dot samples the team colour (blue when its U is
    above grey's, yellow below), its id dots pink (V above grey's) or green. A round blob of the
    ball's size (field.yaml's ball radius) that is no pattern's, orange (U below and V above
    grey's, V's excess at least 0.4 of U's shortfall: not a yellow marker), not on a robot's top
    (a marker blob with an id dot round it), samples the ball: of those in a frame, the one most
    saturated and round. Each blob is sampled within ``inner_fraction`` of its expected
    radius, in the colour space ``space``."""
    p = params or AutoTuneParams()
    pat, h = league.pattern, league.robot.height_m
    dots = np.array(pat.dot_positions_m)
    dot_dist = float(np.median(np.hypot(dots[:, 0], dots[:, 1])))
    r_centre, r_id, r_ball = pat.center_dot_diameter_m / 2, pat.id_dot_diameter_m / 2, league.ball.radius_m
    lo_a, hi_a = p.area_range
    samples: dict[str, list[NDArray[np.int32]]] = {}
    lit: dict[str, list[float]] = {}
    background: dict[str, list[NDArray[np.int32]]] = {}
    n_patterns = n_balls = 0
    for image in images:
        blobs, labels, back = _blobs(image, model, league, p)
        light_img = back.pop("light")
        for key, value in back.items():
            background.setdefault(key, []).append(value)
        conv = convert_colour(image, space)
        if not blobs:
            continue
        ground = np.array([model.unproject(b.pixel, h) for b in blobs])
        ppm = np.array([model.pixels_per_metre((float(g[0]), float(g[1])), h) for g in ground])
        area = np.array([b.area for b in blobs])
        is_centre = (area >= lo_a * math.pi * (r_centre * ppm) ** 2) & (area <= hi_a * math.pi * (r_centre * ppm) ** 2)
        is_id = (area >= lo_a * math.pi * (r_id * ppm) ** 2) & (area <= hi_a * math.pi * (r_id * ppm) ** 2)
        used = np.zeros(len(blobs), bool)
        robot_tops: list[NDArray[np.float64]] = []

        for k in np.flatnonzero(is_centre):
            dist = np.hypot(*(ground - ground[k]).T)
            ring = np.flatnonzero(is_id & (np.abs(dist - dot_dist) <= p.dot_distance_tolerance_m) & ~used)
            ring = ring[ring != k]
            if len(ring) >= 1:
                robot_tops.append(ground[k])  # a marker with id dots round it: no ball, pattern or not
            if not 3 <= len(ring) <= 4:
                continue
            used[k] = True
            used[ring] = True
            n_patterns += 1
            _take(samples, lit, "blue" if blobs[k].colour[1] > 128.0 else "yellow", blobs[k],
                  max(1.0, p.inner_fraction * r_centre * ppm[k]), labels, conv, light_img)
            for j in ring:
                _take(samples, lit, "pink" if blobs[j].colour[2] > 128.0 else "green", blobs[j],
                      max(1.0, p.inner_fraction * r_id * ppm[j]), labels, conv, light_img)
        tops = np.array(robot_tops).reshape(-1, 2)
        on_robot = np.zeros(len(blobs), bool)
        if len(tops):
            on_robot = np.min(np.hypot(ground[:, None, 0] - tops[:, 0], ground[:, None, 1] - tops[:, 1]), axis=1) \
                <= league.robot.radius_m
        best_ball: tuple[float, int] | None = None  # saturation times fill, blob
        for k in np.flatnonzero(~used & ~on_robot):
            b = blobs[k]
            g = model.unproject(b.pixel, r_ball)
            expect = math.pi * (r_ball * model.pixels_per_metre((float(g[0]), float(g[1])), r_ball)) ** 2
            # orange: U below grey's, V well above it and red enough against U not to be yellow (a team
            # marker of no pattern found, of about the lab ball's size)
            orange = b.colour[1] < 128.0 and b.colour[2] > 140.0 and b.colour[2] - 128.0 >= 0.4 * (128.0 - b.colour[1])
            ys, xs = np.nonzero(labels == b.label)
            fill = b.area / max(1.0, float((np.ptp(xs) + 1) * (np.ptp(ys) + 1)))
            if orange and lo_a * expect <= b.area <= hi_a * expect and fill >= 0.5:
                sat = math.hypot(b.colour[1] - 128.0, b.colour[2] - 128.0)
                if best_ball is None or sat * fill > best_ball[0]:
                    best_ball = (sat * fill, int(k))
        if best_ball is not None:  # one ball a frame, the most saturated and round: glare and clutter are paler
            kb = best_ball[1]
            n_balls += 1
            _take(samples, lit, "ball", blobs[kb], max(1.0, p.inner_fraction * r_ball * ppm[kb]), labels, conv,
                  light_img)
    back_all = {k: np.concatenate(v) for k, v in background.items()}
    y = back_all["carpet"][:, 0].astype(np.float64)
    dark, bright = (float(np.percentile(y, q)) for q in (0.5, 99.5))
    kept: dict[str, list[NDArray[np.int32]]] = {}
    light: dict[str, tuple[float, float]] = {}
    left_out: dict[str, int] = {}
    for role in [r for r in samples if not r.endswith("/colour")]:
        off = hue_outliers(np.concatenate(samples[role + "/colour"]).astype(np.float64), p.max_hue_off_deg)
        parts = [part for part, o in zip(samples[role], off, strict=True) if not o]
        if parts:
            kept[role] = parts
        if off.any():
            left_out[role] = int(off.sum())
        seen = np.array(lit[role])[~off]
        seen = seen[np.isfinite(seen)]
        if len(seen):
            light[role] = (min(1.0, dark / float(seen.min())), max(1.0, bright / float(seen.max())))
    return AutoTuneReport(kept, back_all, n_patterns, n_balls, light, left_out)


def _take(samples: dict[str, list[NDArray[np.int32]]], lit: dict[str, list[float]], role: str, b: _Blob,
          r_px: float, labels: NDArray[np.int32], conv: NDArray[Any], light_img: NDArray[Any]) -> None:
    """Sample blob ``b`` for colour class ``role``: its pixels (in ``conv``'s colour space) within
    ``r_px`` of its centre, and the light at its centre (``light_img``; NaN where no carpet is
    seen around it), and its mean colour (YUV) under ``role + "/colour"`` (one entry each, per part)."""
    h, w = labels.shape[:2]
    i0, i1 = max(0, int(b.pixel[1] - r_px)), min(h, int(b.pixel[1] + r_px) + 1)
    j0, j1 = max(0, int(b.pixel[0] - r_px)), min(w, int(b.pixel[0] + r_px) + 1)
    vv, uu = np.mgrid[i0:i1, j0:j1] + 0.5
    sel = ((uu - b.pixel[0]) ** 2 + (vv - b.pixel[1]) ** 2 <= r_px * r_px) & (labels[i0:i1, j0:j1] == b.label)
    if sel.any():
        samples.setdefault(role, []).append(conv[i0:i1, j0:j1][sel])
        samples.setdefault(role + "/colour", []).append(np.round(b.colour).astype(np.int32)[None])
        local = float(light_img[min(int(b.pixel[1]), h - 1), min(int(b.pixel[0]), w - 1)])
        lit.setdefault(role, []).append(local if local > 0.0 else math.nan)


def hue_outliers(colours: NDArray[np.float64], max_off_deg: float) -> NDArray[np.bool_]:
    """Which of the blobs' mean colours ``colours`` (n, 3) YUV have a hue (the angle of (U, V)
    about grey) further than ``max_off_deg`` from the hue of the blobs' median U and V. The hue
    holds under brighter or dimmer light (U and V scale about grey with it) where a box's bounds
    do not; the median stands while fewer than half the blobs are another colour's."""
    u, v = colours[:, 1] - 128.0, colours[:, 2] - 128.0
    ref = math.atan2(float(np.median(v)), float(np.median(u)))
    off = np.abs((np.arctan2(v, u) - ref + math.pi) % (2.0 * math.pi) - math.pi)
    out: NDArray[np.bool_] = off > math.radians(max_off_deg)
    return out


def widen_for_light(box: ColourClass, light: tuple[float, float], space: ColourSpace,
                    saturation_reach: float = 1.0) -> ColourClass:
    """``box`` stretched for light ``light`` (darker, brighter) times the light it was sampled in:
    every channel scales with the light (U and V about grey in YUV); a colour sampled in one part
    of the field is then found in the darker and brighter parts too. In YUV, a chroma channel (U,
    V) whose box lies on one side of grey reaches ``saturation_reach`` times as far from grey on
    its far side: bright markers' samples are mostly clipped by the sensor (a channel at its
    ceiling pulls their chroma toward grey), and the same colour unclipped, where it is darker or
    lifted by the light follower, lies further out (:func:`keep_apart` still cuts the box where
    another class's or the background's samples lie)."""
    lo, hi = np.array(box.lo, np.float64), np.array(box.hi, np.float64)
    grey = np.array([0.0, 128.0, 128.0]) if space == "yuv" else np.zeros(3)
    ends = [grey + (v - grey) * r for v in (lo, hi) for r in light]
    new_lo = np.clip(np.floor(np.min(ends, axis=0)), 0, 255).astype(int)
    new_hi = np.clip(np.ceil(np.max(ends, axis=0)), 0, 255).astype(int)
    if space == "yuv":
        for c in (1, 2):
            if new_lo[c] >= 128 and new_hi[c] > 128:
                new_hi[c] = min(255, int(128 + (new_hi[c] - 128) * saturation_reach))
            elif new_hi[c] <= 128 and new_lo[c] < 128:
                new_lo[c] = max(0, int(128 - (128 - new_lo[c]) * saturation_reach))
    return ColourClass(lo=(int(new_lo[0]), int(new_lo[1]), int(new_lo[2])),
                       hi=(int(new_hi[0]), int(new_hi[1]), int(new_hi[2])), min_area_px=box.min_area_px)


def overlaps(boxes: Mapping[str, ColourClass], samples: Mapping[str, NDArray[np.int32]],
             max_share: float) -> list[tuple[str, str, float]]:
    """(what, box, share): where more than ``max_share`` of ``what``'s samples fall in another
    class's ``box`` (a colour class's or the carpet's or lines' samples)."""
    out = []
    for name, px in samples.items():
        for other, box in boxes.items():
            if other == name or not len(px):
                continue
            share = float(np.mean(np.all((px >= box.lo) & (px <= box.hi), axis=1)))
            if share > max_share:
                out.append((name, other, share))
    return out


def keep_apart(boxes: dict[str, ColourClass], samples: Mapping[str, NDArray[np.int32]], movable: set[str],
               min_share: float = 0.01, space: ColourSpace = "yuv") -> dict[str, ColourClass]:
    """``boxes`` with each box of ``movable`` cut back, where more than ``min_share`` of another's
    samples (a class's, the carpet's, the lines') fall in it: the cut along one channel that misplaces the fewest
    samples of either, and of those the one that gives up the least of the box."""
    out = dict(boxes)
    for name in movable:
        own = samples.get(name)
        if own is None or not len(own):
            own = np.zeros((0, 3), np.int32)  # nothing seen of it: the cut keeps the most of the box instead
        for other, px in samples.items():
            box = out[name]
            lo, hi = np.array(box.lo), np.array(box.hi)
            if other == name or not len(px) or np.mean(np.all((px >= lo) & (px <= hi), axis=1)) <= min_share:
                continue
            best: tuple[int, int, int, int] | None = None  # misplaced, channel, side, cut
            theirs = px[np.all((px >= lo) & (px <= hi), axis=1)]
            for c in range(3):
                cuts = np.arange(int(lo[c]), int(hi[c]) + 1)
                mine_at = np.searchsorted(np.sort(own[:, c]), cuts)  # own samples below each cut
                theirs_at = np.searchsorted(np.sort(theirs[:, c]), cuts)
                mine_above = len(own) - np.searchsorted(np.sort(own[:, c]), cuts, side="right")
                theirs_above = len(theirs) - np.searchsorted(np.sort(theirs[:, c]), cuts, side="right")
                # side 0: lo raised to the cut (the other lies below); 1: hi lowered to it
                width = max(1, int(hi[c]) - int(lo[c]))
                costs = ((0, mine_at + (len(theirs) - theirs_at)), (1, mine_above + (len(theirs) - theirs_above)))
                for side, cost in costs:
                    # misplaced samples first, then the share of the box given up (twice in brightness, the
                    # channel the light moves most)
                    given_up = np.abs(cuts - (lo[c] if side == 0 else hi[c])) * (999 if c or space != "yuv" else 1998)
                    cost = cost * 2000 + given_up // width
                    k = int(np.argmin(cost))
                    if best is None or int(cost[k]) < best[0]:
                        best = (int(cost[k]), c, side, int(cuts[k]))
            if best is None:
                continue
            _, c, side, cut = best
            if side == 0:
                lo[c] = cut
            else:
                hi[c] = cut
            out[name] = ColourClass(lo=(int(lo[0]), int(lo[1]), int(lo[2])), hi=(int(hi[0]), int(hi[1]), int(hi[2])),
                                    min_area_px=box.min_area_px)
    return out


def learn_boxes(samples: Samples, background: Mapping[str, NDArray[np.int32]], light: Mapping[str, tuple[float, float]],
                current: Mapping[str, ColourClass], space: ColourSpace, margin: int = 16,
                max_overlap: float | None = None,
                saturation_reach: float = 1.0) -> tuple[dict[str, ColourClass], list[str]]:
    """The colour boxes from samples per colour name (and, learnt automatically, the background's
    samples and the light each box must reach): each sampled colour's box
    (:func:`boxes_from_samples`, widened by :func:`widen_for_light`), the others as ``current``
    has them, all cut apart where they overlap (:func:`keep_apart`). Returns the boxes and the
    warnings, one line each: where boxes overlapped, and where they still do after the cut."""
    share = AutoTuneParams().max_overlap if max_overlap is None else max_overlap
    learnt = boxes_from_samples(samples, margin=margin)
    boxes = {**current, **{n: widen_for_light(b, light[n], space, saturation_reach) if n in light else b
                           for n, b in learnt.items()}}
    pooled = {**{n: np.concatenate(p) for n, p in samples.items()}, **background}
    warnings = [f"{part:.0%} of the {what} samples fall in {other}'s box (lo {list(boxes[other].lo)} hi "
                f"{list(boxes[other].hi)}): the boxes are cut apart"
                for what, other, part in overlaps(boxes, pooled, share)]
    boxes = keep_apart(boxes, pooled, set(boxes), share, space)
    warnings += [f"still {part:.0%} of the {what} samples in {other}'s box: those pixels are misread; label more or "
                 "other spots" for what, other, part in overlaps(boxes, pooled, share)]
    return boxes, warnings
