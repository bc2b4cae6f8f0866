"""Camera calibration from the field's painted lines: no hand-picked points.

From a rough start (the camera's height, measured, and the part of the field it sees) the camera
model of :mod:`cmdragons.camera` (pose, focal length, radial distortion k1, k2) is fitted to the
white-line pixels of one image, in five steps:

1. **Line pixels** (:func:`line_strength`): a white top-hat of the image's brightness (what is
   brighter than its surroundings over a few line widths), kept where the pixel is not coloured
   (the robots' dots, the ball and the team colours are brighter than the carpet too).
2. **Coarse search**: the field model (every straight line and the centre circle of
   configs/field.yaml, sampled along their centre lines) projected through candidate cameras
   around the rough start (position, the four quarter turns, the focal
   length), scored by the chamfer distance to the line pixels (truncated, so that a
   line hidden by a robot costs no more than a fixed amount); the best few are refined by least
   squares on the same distance.
3. **Tape width**: the width of the lines in the image is measured across the coarse fit's lines
   (configs/field.yaml's line_width_m is only where the search starts: labs tape 45 mm lines).
4. **Fine fit**: for every model point, the line's centre is measured across the projected line
   (the strength profile along its normal, its weighted centroid over the tape's width:
   sub-pixel, the middle of the tape), and all parameters are fitted by least squares to the
   normal distances (point to line, robust loss), the correspondences measured again from each
   new fit until it settles.
5. **Checks**: a fit that cannot be right is refused with the reason (:func:`_check`): lines the
   fit puts in view that the image does not show, too few lines or all one way, a field of view
   or a tape width implausible, a known focal length missed. The field's quarter turns are
   searched in step 2; its half turn looks the same to the lines and the rough start decides.

A camera looking at one plane sees the same from height h with focal length f (and k1, k2) as
from k h with k f (k^2 k1, k^4 k2): the height is kept from the rough start, as in
:func:`vision.calibrate.calibrate`. The reprojection error is the RMS of every measured line
centre's distance to the fitted model's lines (px), measured with the fitted camera.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares
from scipy.spatial import cKDTree
from threadpoolctl import threadpool_limits

from cmdragons.camera import CameraModel, CameraParams
from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, LeagueParams

__all__ = [
    "CalibrationRefused",
    "LineCalibration",
    "LineFitParams",
    "calibrate_from_lines",
    "draw_field",
    "field_lines",
    "field_samples",
    "line_strength",
    "rough_start",
    "true_error_px",
]

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class LineFitParams(Validated):
    """How far the rough start may be off, and what counts as a painted line."""

    reach_m: float = setting(0.4, lo=0.0, hi=3.0)  # the search over position: +- this along x and y
    grid_steps: int = setting(9, lo=1, hi=41)  # positions per axis in that search
    focal_range: float = setting(0.15, lo=0.0, hi=0.5)  # the search over focal length: +- this share
    # that search's candidates scored exactly, the best by a quick estimate (the exact best four were
    # within the estimate's best six on every test frame and the real lab frame)
    grid_rescored: int = setting(24, lo=4, hi=100000)
    white_chroma: float = setting(60.0, lo=1.0, hi=255.0)  # grey levels from grey where a pixel stops being white
    min_strength_grey: float = setting(8.0, lo=0.0, hi=255.0)  # a line pixel's top-hat, at least (noise's reach)
    coarse_cap_px: float = setting(20.0, lo=2.0, hi=200.0)  # chamfer distances truncated here in the search
    refine_cap_px: float = setting(6.0, lo=1.0, hi=50.0)  # ... and here in its refinement
    search_px: float = setting(5.0, lo=1.0, hi=50.0)  # line centres looked for this far across a projected line
    widest_line_m: float = setting(0.08, lo=0.005, hi=0.3)  # the tape's width is measured up to this
    min_found: float = setting(0.6, lo=0.0, hi=1.0)  # share of the model's points in view whose line is found
    min_lines: int = setting(4, lo=2, hi=40)  # field lines seen (half their length in view found), at least
    fov_deg: tuple[float, float] = (30.0, 150.0)  # the horizontal field of view a fitted focal length may give
    # a focal length known beforehand (the lens's): the fit's may be off by this share at most. A field
    # scaled as a whole looks the same as a camera of another focal length at the height kept: only
    # this catches a field.yaml or a --height off by a common factor
    known_focal_px: float = setting(0.0, lo=0.0, hi=1e5)  # 0: not known
    known_focal_tolerance: float = setting(0.05, lo=0.0, hi=1.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not 1.0 <= self.fov_deg[0] < self.fov_deg[1] <= 179.0:
            raise ValueError(f"fov_deg must be [lo, hi] within 1..179 degrees, lo < hi, got {list(self.fov_deg)}")


class CalibrationRefused(ValueError):
    """A fit that cannot be right (the reason in the message): the field model does not match
    what the image shows, or the camera it implies is impossible."""


@dataclass(frozen=True)
class LineCalibration:
    params: CameraParams
    rms_px: float  # every measured line centre to the fitted model's lines (normal distance)
    max_px: float
    points: int  # line centres measured with the fitted model
    line_pixels: int  # pixels the line detector found
    line_width_px: float  # the tape's width measured in the image (median over the lines)
    found: float  # share of the model's points in view whose line centre was found
    lines_seen: int  # field lines with at least half their length in view found
    centres: F64  # the measured line centres (n, 2), px
    residuals_px: F64  # each centre's signed normal distance to the fitted line, px
    line_of: NDArray[np.int64]  # each centre's field line (index into field_samples' lines)
    notes: tuple[str, ...] = ()  # what the fit decided that the lines alone could not


def field_lines(league: LeagueParams) -> list[tuple[float, float, float, float] | float]:
    """The painted markings a line calibration looks for: straight lines as (x0, y0, x1, y1) and
    the centre circle as its radius, m; without what field.yaml says is not painted (the centre
    circle, the line from goal to goal, the touch and goal lines where walls stand)."""
    f = Field(league)
    d = f.dims
    out: list[tuple[float, float, float, float] | float] = [
        (*s.a, *s.b) for s in f.painted_segments(outer=d.outer_lines == "painted")
    ]
    if d.center_circle:
        out.append(d.center_circle_radius_m)
    return out


def field_samples(league: LeagueParams, step_m: float) -> tuple[F64, F64, NDArray[np.int64]]:
    """Points along the centre lines of every painted marking (:func:`field_lines`) (n, 3) at
    z = 0, each point's unit tangent (n, 2) in the field frame and its line's index (n,), about
    ``step_m`` apart."""
    pts, tan, ids = [], [], []
    for k, line in enumerate(field_lines(league)):
        if isinstance(line, tuple):
            a, b = np.array(line[:2]), np.array(line[2:])
            length = float(np.hypot(*(b - a)))
            n = max(2, int(math.ceil(length / step_m)) + 1)
            s = np.linspace(0.0, 1.0, n)[:, None]
            pts.append(a + s * (b - a))
            tan.append(np.repeat(((b - a) / length)[None], n, axis=0))
        else:
            n = max(8, int(math.ceil(2 * math.pi * line / step_m)))
            phi = np.arange(n) * 2 * math.pi / n
            pts.append(np.stack([line * np.cos(phi), line * np.sin(phi)], axis=1))
            tan.append(np.stack([-np.sin(phi), np.cos(phi)], axis=1))
        ids.append(np.full(n, k, np.int64))
    xy = np.concatenate(pts)
    return np.concatenate([xy, np.zeros((len(xy), 1))], axis=1), np.concatenate(tan), np.concatenate(ids)


def line_strength(image: NDArray[np.uint8], line_width_px: float, white_chroma: float = 60.0) -> NDArray[np.float32]:
    """How much each pixel looks like a painted line: the white top-hat of the brightness over a
    window of a few line widths, times the pixel's lack of colour (1 for grey, 0 from a chroma
    distance of ``white_chroma`` grey levels up); float32 grey levels, 0 where nothing is."""
    ycc = cv2.cvtColor(image, cv2.COLOR_BGR2YCrCb)
    k = 2 * max(2, int(math.ceil(2.0 * line_width_px))) + 1
    # on the 8-bit brightness: the same top-hat as in float (minima, maxima and a difference of whole grey
    # levels), two to three times faster with a window of tens of pixels
    tophat = cv2.morphologyEx(np.ascontiguousarray(ycc[..., 0]), cv2.MORPH_TOPHAT,
                              cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))).astype(np.float32)
    cr, cb = ycc[..., 1].astype(np.float32), ycc[..., 2].astype(np.float32)
    chroma = np.hypot(cr - 128.0, cb - 128.0)
    out: NDArray[np.float32] = tophat * np.clip(1.0 - chroma / white_chroma, 0.0, 1.0)
    return out


def _line_mask(strength: NDArray[np.float32], floor: float) -> NDArray[np.uint8]:
    """Line pixels: strength above a third of the strong lines' (the 99.5th percentile of the
    non-zero strengths) and above ``floor`` grey levels."""
    nz = strength[strength > 1.0]
    level = max(floor, float(np.percentile(nz, 99.5)) / 3.0) if nz.size else floor
    return (strength > level).astype(np.uint8)


def rough_start(base: CameraParams, height_m: float, sees: tuple[float, float, float, float]) -> CameraParams:
    """A downward camera at ``height_m`` over the centre of the field rectangle ``sees``
    (x0, y0, x1, y1, m), the image's width along the rectangle's longer side, the focal length that
    fits the rectangle into the image; resolution and principal point from ``base``."""
    x0, y0, x1, y1 = sees
    w, h = base.resolution_px
    along_x = abs(x1 - x0) >= abs(y1 - y0)
    half_u = (abs(x1 - x0) if along_x else abs(y1 - y0)) / 2.0
    half_v = (abs(y1 - y0) if along_x else abs(x1 - x0)) / 2.0
    focal = min(w / 2.0 / (half_u / height_m), h / 2.0 / (half_v / height_m))
    return dataclasses.replace(
        base, position_m=((x0 + x1) / 2.0, (y0 + y1) / 2.0, height_m), yaw_rad=0.0 if along_x else -math.pi / 2.0,
        tilt_x_rad=0.0, tilt_y_rad=0.0, focal_px=focal, k1=0.0, k2=0.0,
    )


def _params(x: F64, base: CameraParams, n: int) -> CameraParams:
    """``base`` with the first ``n`` of (yaw, tilt x, tilt y, x, y, focal, k1, k2) from ``x``."""
    full = [base.yaw_rad, base.tilt_x_rad, base.tilt_y_rad, base.position_m[0], base.position_m[1], base.focal_px,
            base.k1, base.k2]
    full[:n] = [float(v) for v in x[:n]]
    yaw, tx, ty, px, py, f, k1, k2 = full
    return dataclasses.replace(
        base, yaw_rad=math.remainder(yaw, 2 * math.pi), tilt_x_rad=float(np.clip(tx, -0.49, 0.49)),
        tilt_y_rad=float(np.clip(ty, -0.49, 0.49)), position_m=(px, py, base.position_m[2]),
        focal_px=max(f, 10.0), k1=float(np.clip(k1, -0.99, 0.99)), k2=float(np.clip(k2, -0.99, 0.99)),
    )


def _vector(p: CameraParams) -> F64:
    return np.array([p.yaw_rad, p.tilt_x_rad, p.tilt_y_rad, p.position_m[0], p.position_m[1], p.focal_px, p.k1, p.k2])


def _sample(img: NDArray[np.float32], px: F64) -> F64:
    """Bilinear samples of ``img`` at pixel positions (n, 2) (u, v from the top-left corner)."""
    n = len(px)
    cols = 1024  # OpenCV's maps stay below 32767 rows and columns
    flat = np.zeros((-(-n // cols) * cols, 2), np.float32)
    flat[:n] = px - 0.5  # OpenCV measures from the top-left pixel's centre
    maps = flat.reshape(-1, cols, 2)
    out = cv2.remap(img, maps[..., 0], maps[..., 1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return np.asarray(out, dtype=np.float64).ravel()[:n]


def _chamfer(params: CameraParams, pts: F64, dist: NDArray[np.float32], line_px: F64, cap_px: float) -> F64:
    """Both ways of the truncated chamfer distance (px): from each model point's projection to
    the nearest line pixel (a point outside the image costs the cap: pushing lines out of view
    gains nothing), and from each of the sampled line pixels ``line_px`` (n, 2) to the nearest
    projected model point (so that a model shrunk onto a few lines gains nothing either)."""
    model = CameraModel(params)
    px = model.project(pts)
    inside = np.isfinite(px).all(axis=1) & model.in_image(np.nan_to_num(px, nan=-1.0), margin=1.0)
    out = np.full(len(pts) + len(line_px), cap_px)
    if inside.any():
        out[: len(pts)][inside] = np.minimum(_sample(dist, px[inside]), cap_px)
        d, _ = cKDTree(px[inside]).query(line_px, distance_upper_bound=cap_px)
        out[len(pts) :] = np.minimum(d, cap_px)
    return out


def _chamfer_jacobian(x: F64, base: CameraParams, pts: F64, dist: NDArray[np.float32],
                      slope: tuple[NDArray[np.float32], NDArray[np.float32]], line_px: F64, cap_px: float) -> F64:
    """The Jacobian (m, 6) of :func:`_chamfer` for ``_params(x, base, 6)``: each distance's
    gradient in the image (``slope``, the distance field's along u and v; the unit vector from the
    line pixel to its nearest projected point) times its point's derivative along each parameter
    (a forward difference of the projection), zero where the cap holds."""
    model = CameraModel(_params(x, base, 6))
    px = model.project(pts)
    inside = np.isfinite(px).all(axis=1) & model.in_image(np.nan_to_num(px, nan=-1.0), margin=1.0)
    jac = np.zeros((len(pts) + len(line_px), 6))
    if not inside.any():
        return jac
    seen, at = pts[inside], px[inside]
    steps = np.array([1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-4])  # rad, rad, rad, m, m, px
    moved = [CameraModel(_params(x + h * e, base, 6)).project(seen) for h, e in zip(steps, np.eye(6), strict=True)]
    dpx = np.stack([(m - at) / h for m, h in zip(moved, steps, strict=True)], axis=2)  # (k, 2, 6) px per unit
    live = _sample(dist, at) < cap_px
    du, dv = _sample(slope[0], at[live]), _sample(slope[1], at[live])
    jac[np.flatnonzero(inside)[live]] = du[:, None] * dpx[live, 0] + dv[:, None] * dpx[live, 1]
    d, nearest = cKDTree(at).query(line_px, distance_upper_bound=cap_px)
    near = (d < cap_px) & (d > 0.0)
    k = nearest[near]
    toward = (at[k] - line_px[near]) / d[near, None]
    jac[len(pts) + np.flatnonzero(near)] = toward[:, :1] * dpx[k, 0] + toward[:, 1:] * dpx[k, 1]
    return jac


def _bounds(p: CameraParams, n: int, reach_m: float) -> tuple[F64, F64]:
    """Least-squares bounds around ``p`` for its first ``n`` parameters: what a rough start can
    be off by (tilts 0.2 rad, position ``reach_m``, focal length 25 %, k1 and k2 0.3)."""
    v = _vector(p)
    half = np.array([0.35, 0.2, 0.2, reach_m, reach_m, 0.25 * p.focal_px, 0.3, 0.3])
    return (v - half)[:n], (v + half)[:n]


def _model_distance(pts: F64, cell_m: float, pad_m: float) -> tuple[NDArray[np.float32], F64]:
    """The distance (m) from every cell of a grid over the field plane to the nearest of the model
    points ``pts`` (n, 3) (each put in its cell of ``cell_m``), over the points' extent plus
    ``pad_m`` each way; and the grid's corner (x, y), m."""
    corner = pts[:, :2].min(axis=0) - pad_m
    cols, rows = np.ceil((pts[:, :2].max(axis=0) + pad_m - corner) / cell_m).astype(np.int64) + 1
    empty = np.ones((rows, cols), np.uint8)
    cell = ((pts[:, :2] - corner) / cell_m).astype(np.int64)
    empty[cell[:, 1], cell[:, 0]] = 0
    out = cv2.distanceTransform(empty, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * np.float32(cell_m)
    return out, corner


def _quick_chamfer(p: CameraParams, shifts: F64, pts: F64, dist: NDArray[np.float32], line_px: F64, cap_px: float,
                   model_dist: tuple[NDArray[np.float32], F64], cell_m: float) -> F64:
    """:func:`_chamfer`'s mean for the camera ``p`` moved by each of ``shifts`` (s, 2) m, all at
    once: the model-to-line half as there (the camera moved by d sees the points moved by -d);
    the line-to-model half measured on the field plane (the line pixels seen on the carpet, moved
    by d, their distance to the nearest model point on :func:`_model_distance`'s grid at the
    camera's scale), which differs from the image's by the cell and the tilt."""
    model = CameraModel(p)
    moved = pts[None, :, :] - np.concatenate([shifts, np.zeros((len(shifts), 1))], axis=1)[:, None, :]
    px = model.project(moved)
    inside = np.isfinite(px).all(axis=2) & model.in_image(np.nan_to_num(px, nan=-1.0), margin=1.0)
    to_lines = np.full(px.shape[:2], cap_px)
    to_lines[inside] = np.minimum(_sample(dist, px[inside]), cap_px)
    grid, corner = model_dist
    # a pixel whose ray misses the carpet: off the grid, as far from the model as the cap
    seen = np.nan_to_num(model.unproject(line_px, 0.0), nan=-1e3, posinf=-1e3, neginf=-1e3)
    at = (seen[None, :, :] + shifts[:, None, :] - corner) / cell_m
    metres = _sample(grid, at.reshape(-1, 2)).reshape(len(shifts), len(line_px))
    to_model = np.minimum(metres * (model.f / p.position_m[2]), cap_px)
    out: F64 = (to_lines.sum(axis=1) + to_model.sum(axis=1)) / (len(pts) + len(line_px))
    return out


def _coarse(start: CameraParams, pts: F64, dist: NDArray[np.float32], line_px: F64,
            fit: LineFitParams) -> CameraParams:
    """The best candidate camera around ``start`` by the truncated chamfer distance: a grid over
    position (+- ``reach_m``), the four quarter turns and the focal length (+- ``focal_range``,
    five steps), ranked by :func:`_quick_chamfer`, its best ``grid_rescored`` scored by
    :func:`_chamfer`; then a least-squares refinement (yaw, tilts, position, focal length) of the
    best few."""
    steps = np.linspace(-fit.reach_m, fit.reach_m, fit.grid_steps)
    shifts = np.array([(dx, dy) for dx in steps for dy in steps])
    x0, y0, z = start.position_m
    cap0, cap1 = fit.coarse_cap_px, fit.refine_cap_px
    pixel_m = z / start.focal_px  # a pixel at the start's scale, on the carpet
    # the estimate's grid: a pixel's cells, at most 2048 along the field (it only ranks the candidates)
    cell_m = max(pixel_m, float(np.ptp(pts[:, :2], axis=0).max()) / 2048.0)
    model_dist = _model_distance(pts, cell_m, cap0 * pixel_m / (1.0 - fit.focal_range) + cell_m)
    views = [dataclasses.replace(start, yaw_rad=start.yaw_rad + turn, focal_px=start.focal_px * fs)
             for turn in (0.0, math.pi / 2.0, math.pi, -math.pi / 2.0)  # which way the image lies: from the lines
             for fs in 1.0 + np.linspace(-fit.focal_range, fit.focal_range, 5)]
    quick = np.concatenate([_quick_chamfer(v, shifts, pts, dist, line_px, cap0, model_dist, cell_m) for v in views])
    cands = []
    for k in np.argsort(quick, kind="stable")[: fit.grid_rescored]:
        dx, dy = shifts[k % len(shifts)]
        p = dataclasses.replace(views[k // len(shifts)], position_m=(x0 + dx, y0 + dy, z))
        cands.append((float(np.mean(_chamfer(p, pts, dist, line_px, cap0))), int(k), p))
    cands.sort(key=lambda c: c[:2])  # ties in the grid's order
    best, best_cost = start, math.inf
    du = np.asarray(np.gradient(dist, axis=1), dtype=np.float32)  # the distance field's slope along u and v
    dv = np.asarray(np.gradient(dist, axis=0), dtype=np.float32)
    for _, _, p in cands[:4]:
        lo, hi = _bounds(p, 6, 0.15)
        for cap in (cap0, cap1):
            sol = least_squares(lambda x, p=p, cap=cap: _chamfer(_params(x, p, 6), pts, dist, line_px, cap),
                                np.clip(_vector(p)[:6], lo, hi), bounds=(lo, hi), max_nfev=100,
                                jac=lambda x, p=p, cap=cap: _chamfer_jacobian(x, p, pts, dist, (du, dv), line_px, cap),
                                x_scale=np.array([0.01, 0.01, 0.01, 0.02, 0.02, 5.0]))
            p = _params(sol.x, p, 6)
        cost = float(np.mean(_chamfer(p, pts, dist, line_px, cap1)))
        if cost < best_cost:
            best, best_cost = p, cost
    return best


def _normals(model: CameraModel, pts: F64, tan: F64) -> tuple[F64, F64]:
    """Projected points (n, 2) and the unit normals (n, 2) of their lines in the image."""
    px = model.project(pts)
    ahead = model.project(pts + np.concatenate([tan * 0.01, np.zeros((len(tan), 1))], axis=1))
    d = ahead - px
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    return px, np.stack([-d[:, 1], d[:, 0]], axis=1)


def _profiles(model: CameraModel, pts: F64, tan: F64, strength: NDArray[np.float32],
              reach_px: float) -> tuple[NDArray[np.int64], F64, F64, F64, F64]:
    """The strength profile across the projected line at each model point in view: the points
    kept, their pixels (k, 2) and normals (k, 2), the offsets (m,) px and the profiles (k, m)."""
    px, nrm = _normals(model, pts, tan)
    ok = np.isfinite(px).all(axis=1) & np.isfinite(nrm).all(axis=1)
    ok &= model.in_image(np.nan_to_num(px, nan=-1.0), margin=reach_px + 2.0)
    idx = np.flatnonzero(ok)
    offs = np.arange(-reach_px, reach_px + 1e-9, 0.25)
    grid = px[idx, None, :] + offs[None, :, None] * nrm[idx, None, :]
    prof = _sample(strength, grid.reshape(-1, 2)).reshape(len(idx), len(offs)) if idx.size else np.zeros((0, len(offs)))
    return idx, px[idx], nrm[idx], offs, prof


def _weighted_centre(prof: F64, offs: F64, around: F64, half: float, floor: F64) -> F64:
    """The centroid of each profile's part above ``floor`` within ``half`` px of ``around``."""
    wts = np.where(np.abs(offs[None, :] - around[:, None]) <= half, np.maximum(prof - floor[:, None], 0.0), 0.0)
    out: F64 = (wts * offs[None, :]).sum(axis=1) / np.maximum(wts.sum(axis=1), 1e-12)
    return out


def _centres(model: CameraModel, pts: F64, tan: F64, strength: NDArray[np.float32], level: float,
             reach_px: float, width_px: float) -> tuple[NDArray[np.int64], F64, F64]:
    """Where the line of each model point really is: along the projected normal within
    ``reach_px``, the strength profile's peak, then the weighted centroid of the profile over
    the tape's width (``width_px``) around it, taken twice (on a wide tape's flat top the peak
    can be anywhere: the first centroid finds the middle). Returns the model points kept, the
    measured centres (n, 2) and the normals."""
    idx, px, nrm, offs, prof = _profiles(model, pts, tan, strength, reach_px)
    if idx.size == 0:
        return idx, np.zeros((0, 2)), np.zeros((0, 2))
    peak = np.argmax(prof, axis=1)
    top = prof[np.arange(len(idx)), peak]
    half = max(1.5, 0.5 * width_px + 1.0)
    t = _weighted_centre(prof, offs, offs[peak], 2.0 * half, 0.5 * top)
    t = _weighted_centre(prof, offs, t, half, 0.3 * top)
    # a line at the window's edge is another line or none; one below the line level is no line
    keep = (top > level) & (np.abs(t) < reach_px - 0.5 * width_px - 0.5)
    # a second strong peak in the window (a parallel line, a goal wall's edge): ambiguous
    other = np.where(np.abs(offs[None, :] - t[:, None]) > max(3.0, width_px + 2.0), prof, 0.0).max(axis=1)
    keep &= other < 0.6 * top
    # wider than the tape: where another line joins or crosses, or a white thing lies on it
    keep &= _run_width(prof, offs, peak, top) <= 1.5 * width_px + 2.0
    return idx[keep], px[keep] + t[keep, None] * nrm[keep], nrm[keep]


def _run_width(prof: F64, offs: F64, peak: NDArray[np.int64], top: F64) -> F64:
    """The width (px) of each profile's run at or above half its height that holds its peak;
    infinite where the run reaches the window's edge."""
    above = prof >= 0.5 * top[:, None]
    pos = np.arange(len(offs))[None, :]
    left = np.where(~above & (pos < peak[:, None]), pos, -1).max(axis=1)
    right = np.where(~above & (pos > peak[:, None]), pos, len(offs)).min(axis=1)
    out: F64 = np.where((left >= 0) & (right < len(offs)), (right - left - 1) * float(offs[1] - offs[0]), np.inf)
    return out


def _line_width(model: CameraModel, pts: F64, tan: F64, strength: NDArray[np.float32], level: float,
                reach_px: float) -> float:
    """The tape's width in the image, px: the median over the model points in view of the
    profile's width at half its height around the peak (the profiles of points whose line is
    missing or cut by the window's edge left out)."""
    idx, _, _, offs, prof = _profiles(model, pts, tan, strength, reach_px)
    if idx.size == 0:
        return 0.0
    peak = np.argmax(prof, axis=1)
    top = prof[np.arange(len(idx)), peak]
    widths = _run_width(prof, offs, peak, top)
    widths = widths[np.isfinite(widths) & (top > level)]
    return float(np.median(widths)) if widths.size >= 20 else 0.0


def _fine(start: CameraParams, pts: F64, tan: F64, strength: NDArray[np.float32], level: float,
          search_px: float, width_px: float) -> CameraParams:
    """Point-to-line least squares on measured line centres, measured again after each fit: the
    first time ``search_px`` (plus half the tape) across each line and without distortion, then
    ever closer with it."""
    p = start
    near = min(search_px, 2.0)
    for reach, n_fit in ((search_px, 6), (min(search_px, 3.0), 8), (near, 8), (near, 8), (near, 8)):
        idx, centres, nrm = _centres(CameraModel(p), pts, tan, strength, level, reach + width_px, width_px)
        if len(idx) < 20:
            raise CalibrationRefused(f"only {len(idx)} line points found near the model: the rough start is too far "
                                     "off, or this is not the field in field.yaml")
        sub = pts[idx]

        def resid(x: F64, sub: F64 = sub, centres: F64 = centres, nrm: F64 = nrm, n_fit: int = n_fit,
                  base: CameraParams = p) -> F64:
            proj = CameraModel(_params(x, base, n_fit)).project(sub)
            out: F64 = np.nan_to_num(np.sum((proj - centres) * nrm, axis=1), nan=50.0)
            return out

        lo, hi = _bounds(p, n_fit, 0.1)
        sol = least_squares(resid, np.clip(_vector(p)[:n_fit], lo, hi), bounds=(lo, hi), loss="soft_l1",
                            f_scale=max(1.0, 0.1 * width_px),
                            x_scale=np.array([1e-3, 1e-3, 1e-3, 2e-3, 2e-3, 1.0, 1e-3, 1e-3])[:n_fit])
        p = _params(sol.x, p, n_fit)
    return p


@dataclass(frozen=True)
class _Match:
    """How well one camera's projection of the field model matches the image's lines."""

    idx: NDArray[np.int64]  # model points whose line centre was found
    centres: F64
    residuals: F64  # signed normal distances, px
    found: float  # share of the model points in view found
    lines_seen: int
    directions: int  # 1: all lines seen run one way; 2: both
    missing: tuple[int, ...]  # lines mostly in view of which little was found


def _match(params: CameraParams, pts: F64, tan: F64, ids: NDArray[np.int64], strength: NDArray[np.float32],
           level: float, reach_px: float, width_px: float) -> _Match:
    model = CameraModel(params)
    idx, centres, nrm = _centres(model, pts, tan, strength, level, reach_px + width_px, width_px)
    res = np.sum((model.project(pts[idx]) - centres) * nrm, axis=1) if idx.size else np.zeros(0)
    px = model.project(pts)
    view = np.isfinite(px).all(axis=1) & model.in_image(np.nan_to_num(px, nan=-1.0), margin=reach_px + width_px + 2.0)
    n_view = np.bincount(ids[view], minlength=int(ids.max()) + 1)
    n_found = np.bincount(ids[idx], minlength=int(ids.max()) + 1)
    seen = (n_found >= np.maximum(8, 0.5 * n_view)) & (n_view > 0)
    along_x = np.array([abs(tan[ids == k][:, 0]).mean() > 0.7 for k in range(len(n_view))])
    circle = np.array([np.ptp(tan[ids == k][:, 0]) > 1.0 for k in range(len(n_view))])
    dirs = (int((seen & along_x & ~circle).any()) + int((seen & ~along_x & ~circle).any())
            + 2 * int((seen & circle).any()))
    missing = np.flatnonzero((n_view >= 20) & (n_found < 0.25 * n_view))
    return _Match(idx, centres, res, float(idx.size / max(1, int(view.sum()))), int(seen.sum()), min(dirs, 2),
                  tuple(int(k) for k in missing))


def _half_turn(p: CameraParams) -> CameraParams:
    """The same camera on the field turned by a half turn about the centre spot: the field's
    lines look exactly the same to it."""
    x, y, z = p.position_m
    return dataclasses.replace(p, position_m=(-x, -y, z), yaw_rad=math.remainder(p.yaw_rad + math.pi, 2 * math.pi))


def _describe(line: tuple[float, float, float, float] | float) -> str:
    if isinstance(line, tuple):
        return f"the line from ({line[0]:.2f}, {line[1]:.2f}) to ({line[2]:.2f}, {line[3]:.2f}) m"
    return f"the centre circle of radius {line:.2f} m"


def _check(p: CameraParams, m: _Match, width_px: float, league: LeagueParams, fit: LineFitParams) -> None:
    """Refuse a fit that cannot be right, with the reason (CalibrationRefused)."""
    fov = math.degrees(2.0 * math.atan(p.resolution_px[0] / 2.0 / p.focal_px))
    lo, hi = fit.fov_deg
    if not lo <= fov <= hi:
        raise CalibrationRefused(f"the fit's focal length {p.focal_px:.0f} px gives a {fov:.0f} degree field of view "
                                 f"(plausible: {lo:.0f}-{hi:.0f}): wrong --height or field size")
    known = fit.known_focal_px
    if known > 0.0 and abs(p.focal_px / known - 1.0) > fit.known_focal_tolerance:
        raise CalibrationRefused(f"the fit's focal length {p.focal_px:.0f} px is {p.focal_px / known - 1.0:+.0%} off "
                                 f"the known {known:.0f} px (at most {fit.known_focal_tolerance:.0%}): the field's "
                                 "size in field.yaml or the --height is off by that share")
    metres = width_px / max(CameraModel(p).pixels_per_metre((p.position_m[0], p.position_m[1]), 0.0), 1e-9)
    if not 0.3 * league.dims.line_width_m <= metres <= max(fit.widest_line_m, 3.0 * league.dims.line_width_m):
        raise CalibrationRefused(f"the lines measure {metres * 1000:.0f} mm across at the fitted scale, field.yaml's "
                                 f"line_width_m is {league.dims.line_width_m * 1000:.0f} mm: the scale is wrong "
                                 "(--height, the field's size) or line_width_m is")
    if m.found < fit.min_found:
        raise CalibrationRefused(f"only {m.found:.0%} of the field lines the fit puts in view are in the image (at "
                                 f"least {fit.min_found:.0%} needed): the field in field.yaml (its size, lines, centre "
                                 "circle) is not the one in the image, or the rough start is too far off")
    if m.missing:
        lines = field_lines(league)
        what = "; ".join(_describe(lines[k]) for k in m.missing)
        raise CalibrationRefused(f"the fit puts field lines in view that the image does not show ({what}): the "
                                 "field in field.yaml (its size, lines, centre circle) is not the one in the image")
    if m.lines_seen < fit.min_lines or m.directions < 2:
        raise CalibrationRefused(f"{m.lines_seen} field lines seen{'' if m.directions >= 2 else ', all one way'}: too "
                                 f"few to fix the camera (at least {fit.min_lines}, both ways or the centre circle)")


def calibrate_from_lines(image: NDArray[np.uint8], league: LeagueParams, start: CameraParams,
                         fit: LineFitParams | None = None) -> LineCalibration:
    """Fit one camera to the field lines in ``image`` (H, W, 3) BGR uint8, from ``start`` (its
    height is kept; its position may be off by up to about ``fit.reach_m``, its focal length by
    ``fit.focal_range``, its yaw by a few degrees or a half turn).

    The tape's width is measured in the image (field.yaml's line_width_m is where the search
    starts, ``fit.widest_line_m`` its end) and the line centres are the middles of the tape. The
    reported error is every measured centre's distance to the fitted lines. A fit that cannot be
    right raises :class:`CalibrationRefused` with the reason (:func:`_check`); lines that cannot
    be found raise ValueError."""
    # the least-squares problems are a few thousand rows by six to eight columns: BLAS threads cost
    # more than they give (an SVD of 2600 x 6, the trust region's, takes 40 times the CPU with two
    # OpenBLAS threads than with one on two busy cores)
    with threadpool_limits(limits=1, user_api="blas"):
        return _calibrate(image, league, start, fit or LineFitParams())


def _calibrate(image: NDArray[np.uint8], league: LeagueParams, start: CameraParams,
               fit: LineFitParams) -> LineCalibration:
    if image.shape[:2] != (start.resolution_px[1], start.resolution_px[0]):
        w, h = start.resolution_px
        raise ValueError(f"the image is {image.shape[1]}x{image.shape[0]} px, the camera {w}x{h}: give its resolution")
    scale = start.focal_px / start.position_m[2]  # px per metre on the carpet, roughly
    widest_px = max(league.dims.line_width_m, fit.widest_line_m) * scale
    wide = line_strength(image, widest_px, fit.white_chroma)
    mask = _line_mask(wide, fit.min_strength_grey)
    if int(mask.sum()) < 200:
        raise ValueError(f"only {int(mask.sum())} line pixels found: is the field in view and lit?")
    dist = cv2.distanceTransform((1 - mask).astype(np.uint8), cv2.DIST_L2, 5).astype(np.float32)
    coarse_pts, _, _ = field_samples(league, max(0.02, 8.0 / scale))
    v, u = np.nonzero(mask)
    pick = np.random.default_rng(0).permutation(len(u))[:1500]  # a fixed sample: the same fit every run
    line_px = np.stack([u[pick] + 0.5, v[pick] + 0.5], axis=1).astype(np.float64)
    p = _coarse(start, coarse_pts, dist, line_px, fit)
    pts, tan, ids = field_samples(league, max(0.005, 3.0 / scale))
    level = 0.5 * float(np.median(wide[mask > 0]))
    width_px = _line_width(CameraModel(p), pts, tan, wide, level, 1.5 * widest_px + fit.search_px)
    if width_px <= 0.0:
        raise CalibrationRefused("the field lines were not found where the rough start puts them: too few to "
                                 "measure their width")
    strength = line_strength(image, width_px, fit.white_chroma)
    level = 0.5 * float(np.median(strength[_line_mask(strength, fit.min_strength_grey) > 0]))
    p = _fine(p, pts, tan, strength, level, fit.search_px, width_px)
    near = min(fit.search_px, 2.0)
    m = _match(p, pts, tan, ids, strength, level, near, width_px)
    notes: list[str] = []
    # every field looks the same turned half a turn about the centre spot: the rough start decides
    other = _half_turn(p)
    off = [abs(math.remainder(q.yaw_rad - start.yaw_rad, 2 * math.pi)) for q in (p, other)]
    if off[1] < off[0]:
        p, m = other, _match(other, pts, tan, ids, strength, level, near, width_px)
    if abs(off[1] - off[0]) < math.radians(30.0):
        notes.append(f"the rough start's yaw is {math.degrees(min(off)):.0f} and {math.degrees(max(off)):.0f} "
                     "degrees from the two half turns the lines allow: check which goal is +x")
    _check(p, m, width_px, league, fit)
    err = np.abs(m.residuals)
    return LineCalibration(p, float(np.sqrt(np.mean(err**2))), float(err.max()), len(err), int(mask.sum()), width_px,
                           m.found, m.lines_seen, m.centres, m.residuals, ids[m.idx], tuple(notes))


def draw_field(image: NDArray[np.uint8], params: CameraParams, league: LeagueParams,
               fit: LineCalibration | None = None) -> NDArray[np.uint8]:
    """A copy of ``image`` with the field model drawn through the camera (magenta, 1 px); with
    ``fit``, the line centres it used (green within 1 px of the fitted line, red beyond) and each
    line's RMS residual in px written beside it."""
    out = image.copy()
    model = CameraModel(params)
    pts, _, ids = field_samples(league, 0.01)
    px = model.project(pts)
    lines = field_lines(league)
    for k, line in enumerate(lines):
        piece = px[ids == k]
        if not isinstance(line, tuple):
            piece = np.concatenate([piece, piece[:1]])
        good = np.isfinite(piece).all(axis=1)
        if good.sum() >= 2:
            poly = np.round((piece[good] - 0.5) * 16).astype(np.int32)  # OpenCV's pixel centres, 4 fractional bits
            cv2.polylines(out, [poly.reshape(-1, 1, 2)], False, (255, 0, 255), 1, cv2.LINE_AA, shift=4)
    if fit is None:
        return out
    for c, r in zip(fit.centres, fit.residuals_px, strict=True):
        colour = (0, 200, 0) if abs(r) <= 1.0 else (0, 0, 255)
        cv2.circle(out, (int(c[0]), int(c[1])), 1, colour, -1)
    for k in np.unique(fit.line_of):
        sel = fit.line_of == k
        at = fit.centres[sel][len(fit.centres[sel]) // 2]
        rms = float(np.sqrt(np.mean(fit.residuals_px[sel] ** 2)))
        cv2.putText(out, f"{rms:.2f} px", (int(at[0]) + 6, int(at[1]) - 6), cv2.FONT_HERSHEY_SIMPLEX, 0.45,
                    (255, 255, 255), 1, cv2.LINE_AA)
    return out


def true_error_px(got: CameraParams, true: CameraParams, league: LeagueParams) -> float:
    """RMS normal distance (px) between the fitted and the true projections of the field's line
    centres in view: a line fit's error against the true centres."""
    pts, tan, _ = field_samples(league, 0.01)
    a, b = CameraModel(got), CameraModel(true)
    pa, pb = a.project(pts), b.project(pts)
    ahead = b.project(pts + np.concatenate([tan * 0.01, np.zeros((len(tan), 1))], axis=1))
    d = ahead - pb
    nrm = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1, keepdims=True)
    view = b.in_image(np.nan_to_num(pb, nan=-1.0), margin=2.0)
    return float(np.sqrt(np.mean(np.sum((pa[view] - pb[view]) * nrm[view], axis=1) ** 2)))
