"""Colour classes that follow the light: gains per cell of a grid over the image, learnt from
confident detections only (after Gloye et al., "Plug & Play", colour maps per cell of a grid).

Each BGR channel of a pixel is scaled by its gain before it is classified
(:meth:`vision.cmvision.Segmenter.set_light`), so a class box learnt once holds under light that
is uneven over the field and drifts over a match. The colours the boxes were made for are the
first confident detections' (per role: the ball, the team markers, the id dots' pink and green);
afterwards every confident robot's markers and every confident ball measure, in the cell they lie
in, how far the gains there are from bringing them back to those colours, and the cell's gains move
toward that by ``rate`` a frame; a cell with nothing seen this frame moves, at half that rate,
toward its starting gains times the change the whole frame measured (light that changes everywhere
at once). The gains are each cell's at its centre, interpolated in between (:func:`gain_table`).
A marker whose colour is far off its role's (a dot taped over, glare) teaches nothing. The gains
are updated every ``every_frames`` frames: light drifts over seconds, and a frame's update costs a
few milliseconds.

The gains a run starts with (``gains``) are measured by ``tune --auto`` (:func:`start_gains`): per
cell, the carpet's colour there against the whole field's, so uneven light is handled from the first
frame and the follower only tracks its drift (a cell with nothing seen follows the whole frame's drift
from its own starting gains).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.config import Validated, setting
from cmdragons.geometry import LeagueParams, Team
from cmdragons.messages import BallDetection, RobotDetection

__all__ = ["BAND_PX", "LightFollower", "LightParams", "apply_gains", "cell_index", "gain_at", "gain_table",
           "start_gains"]

Gains = tuple[tuple[tuple[float, float, float], ...], ...]


@dataclass(frozen=True)
class LightParams(Validated):
    """configs/vision.yaml ``light``."""

    follow: bool = False  # colour classes follow the light (per cell, from confident detections)
    grid: tuple[int, int] = setting((4, 3), lo=1, hi=64)  # cells across and down the image
    rate: float = setting(0.1, lo=0.0, hi=1.0)  # share of a cell's measured change taken per frame
    min_confidence: float = setting(0.7, lo=0.0, hi=1.0)  # detections at least this confident teach
    max_change: float = setting(2.0, lo=1.0, hi=8.0)  # a gain stays within [1 / this, this]; a marker
    #   further than this from its role's colour in a channel teaches nothing
    every_frames: int = setting(6, lo=1, hi=1000)  # the gains are updated every this many frames (light drifts slowly)
    # the gains a run starts with: rows of cells down the image, each [B, G, R] per cell across (written
    # by tune --auto); (): 1 everywhere
    gains: Gains = setting((), lo=0.0, hi=8.0)
    carpet_tolerance: float = setting(30.0, lo=1.0, hi=255.0)  # tune --auto: a cell's carpet, its field
    #   pixels within this BGR distance (grey levels) of the cell's median
    min_cell_pixels: int = setting(400, lo=1, hi=10**7)  # tune --auto: a cell with fewer carpet pixels
    #   in view takes the gains of the nearest cell with enough

    def __post_init__(self) -> None:
        super().__post_init__()
        nx, ny = self.grid
        if self.gains and (len(self.gains) != ny or any(len(row) != nx for row in self.gains)):
            raise ValueError(f"gains: {ny} rows of {nx} cells (grid {list(self.grid)}) expected")
        lo, hi = 1.0 / self.max_change, self.max_change
        if any(not lo <= g <= hi for row in self.gains for cell in row for g in cell):
            raise ValueError(f"gains: each within [1 / max_change, max_change] = [{lo:g}, {hi:g}]")

    def with_start(self, gains: NDArray[np.float64]) -> LightParams:
        """These params starting from ``gains`` (rows of cells, columns of cells, 3), as written to
        vision.yaml (three decimals)."""
        rows = tuple(tuple((round(float(g[0]), 3), round(float(g[1]), 3), round(float(g[2]), 3)) for g in row)
                     for row in gains)
        return dataclasses.replace(self, gains=rows)

    def start(self) -> NDArray[np.float64]:
        """The starting gains (rows of cells, columns of cells, 3)."""
        nx, ny = self.grid
        return np.array(self.gains, dtype=np.float64) if self.gains else np.ones((ny, nx, 3))


def cell_index(size: int, cells: int) -> NDArray[np.int64]:
    """The cell (0 .. cells - 1) of each of ``size`` pixels along one axis: cells split the image evenly."""
    return np.minimum(np.arange(size) * cells // size, cells - 1).astype(np.int64)


BAND_PX = 8  # image rows that share one row of interpolated gains (the light changes little over 8 rows)


def _between_centres(positions: NDArray[np.float64], size: int,
                     cells: int) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """For pixel coordinates ``positions`` along an axis of ``size`` pixels split into ``cells``:
    the cells whose centres lie either side and the share of the second (clamped beyond the outer centres)."""
    c = np.clip(positions * cells / size - 0.5, 0.0, cells - 1.0)
    i0 = np.floor(c).astype(np.int64)
    return i0, np.minimum(i0 + 1, cells - 1), c - i0


def gain_table(gains: NDArray[np.float64], width: int, height: int) -> tuple[NDArray[np.int32], NDArray[np.int64]]:
    """The gains per pixel of a ``width`` x ``height`` image from ``gains`` (rows of cells, columns
    of cells, 3: B, G, R), each cell's gains at its centre, bilinear between the centres (the outer
    cells' beyond them): a table (bands, width * 3) int32 x 256 (rounded), one row per band of
    :data:`BAND_PX` image rows (at the band's middle), and the band (height,) of each image row --
    as :func:`vision._kernels.classify` takes them. Smooth in the image, unlike a gain per cell:
    light that changes within a cell (a lamp's pool, vignetting) is followed, with no steps at the
    cells' borders."""
    ny, nx = gains.shape[:2]
    j0, j1, tu = _between_centres(np.arange(width, dtype=np.float64) + 0.5, width, nx)
    g = np.clip(gains, 0.0, 8.0)
    across = g[:, j0] * (1.0 - tu)[None, :, None] + g[:, j1] * tu[None, :, None]  # (ny, width, 3)
    starts = np.arange(0, height, BAND_PX)
    middles = (starts + np.minimum(starts + BAND_PX, height)).astype(np.float64) / 2.0
    i0, i1, tv = _between_centres(middles, height, ny)
    table = across[i0] * (1.0 - tv)[:, None, None] + across[i1] * tv[:, None, None]
    fixed = np.ascontiguousarray(np.round(table * 256.0).astype(np.int32).reshape(len(starts), width * 3))
    return fixed, (np.arange(height) // BAND_PX).astype(np.int64)


def apply_gains(image: NDArray[np.uint8], gains: NDArray[np.float64]) -> NDArray[np.uint8]:
    """``image`` (H, W, 3) BGR with each pixel's channels scaled by its gains (:func:`gain_table`
    of ``gains``, rows of cells, columns of cells, 3) as the classifier scales them (x 256 fixed
    point, rounded, saturated at 255; :meth:`vision.cmvision.Segmenter.set_light`)."""
    h, w = image.shape[:2]
    table, band = gain_table(gains, w, h)
    per_px = table[band].reshape(h, w, 3).astype(np.int64)
    out: NDArray[np.uint8] = np.minimum((image.astype(np.int64) * per_px + 128) >> 8, 255).astype(np.uint8)
    return out


def gain_at(gains: NDArray[np.float64], pixel: tuple[float, float], width: int, height: int) -> NDArray[np.float64]:
    """The gains (B, G, R) at ``pixel`` (u, v), bilinear between the cells' centres as in :func:`gain_table`."""
    ny, nx = gains.shape[:2]
    j0, j1, tu = _between_centres(np.array([pixel[0]]), width, nx)
    i0, i1, tv = _between_centres(np.array([pixel[1]]), height, ny)
    a, b = float(tu[0]), float(tv[0])
    top = gains[i0[0], j0[0]] * (1.0 - a) + gains[i0[0], j1[0]] * a
    bottom = gains[i1[0], j0[0]] * (1.0 - a) + gains[i1[0], j1[0]] * a
    out: NDArray[np.float64] = top * (1.0 - b) + bottom * b
    return out


def start_gains(frames: Sequence[tuple[NDArray[np.uint8], NDArray[np.bool_]]],
                params: LightParams) -> NDArray[np.float64]:
    """The gains per cell of ``params.grid`` that bring the carpet in each cell to the whole
    field's carpet colour (after Gloye et al., "Plug & Play": colour per cell of a grid over the
    field), from frames (BGR image, mask of its pixels on the field). A cell's carpet: its field
    pixels within ``carpet_tolerance`` of the cell's median colour (not the lines, the robots, the
    ball); the whole field's: the mean over every cell's carpet. A cell with fewer than
    ``min_cell_pixels`` carpet pixels takes the gains of the nearest cell with enough; none with
    enough: 1 everywhere. Gains clipped to [1 / max_change, max_change]. Multiplying holds for a
    camera's gamma too (a power of a product is a product of powers); a black level offsets it."""
    nx, ny = params.grid
    sums, counts = np.zeros((ny, nx, 3)), np.zeros((ny, nx))
    for image, mask in frames:
        h, w = image.shape[:2]
        rows, cols = cell_index(h, ny), cell_index(w, nx)
        for i in range(ny):
            for j in range(nx):
                rs, cs = np.flatnonzero(rows == i), np.flatnonzero(cols == j)
                block = image[rs[0] : rs[-1] + 1, cs[0] : cs[-1] + 1]
                px = block[mask[rs[0] : rs[-1] + 1, cs[0] : cs[-1] + 1]].astype(np.float64)
                if not len(px):
                    continue
                near = np.linalg.norm(px - np.median(px, axis=0), axis=1) <= params.carpet_tolerance
                sums[i, j] += px[near].sum(axis=0)
                counts[i, j] += float(near.sum())
    ok = counts >= params.min_cell_pixels
    if not ok.any():
        return np.ones((ny, nx, 3))
    whole = sums[ok].sum(axis=0) / counts[ok].sum()
    gains = np.ones((ny, nx, 3))
    gains[ok] = whole / np.maximum(sums[ok] / counts[ok][:, None], 1.0)
    seen = np.argwhere(ok)
    for i, j in np.argwhere(~ok):
        k = int(np.argmin(np.hypot(seen[:, 0] - i, seen[:, 1] - j)))
        gains[i, j] = gains[tuple(seen[k])]
    out: NDArray[np.float64] = np.clip(gains, 1.0 / params.max_change, params.max_change)
    return out


class LightFollower:
    """The gains per cell of one camera, updated from each frame's detections."""

    def __init__(self, params: LightParams, league: LeagueParams, camera: CameraModel,
                 heights: dict[Team, float]) -> None:
        self.params, self.camera, self.heights = params, camera, heights
        self.start = params.start()  # the gains measured at tuning; drift is followed from them
        self.gains = self.start.copy()
        self.reference: dict[str, NDArray[np.float64]] = {}  # role -> the BGR its boxes were made for
        pat = league.pattern
        self.pattern = pat
        self.dots = np.array(pat.dot_positions_m, dtype=np.float64).reshape(-1, 2)
        depth = camera.center[2] - league.robot.height_m
        # every marker sampled within 0.6 of an id dot's radius (at least the pixel and its 4 neighbours)
        r = max(1.0, 0.6 * pat.id_dot_diameter_m / 2 * camera.f / depth)
        k = int(math.ceil(r))
        dv, du = np.mgrid[-k : k + 1, -k : k + 1]
        keep = du**2 + dv**2 <= r * r
        self.offsets = np.stack([du[keep], dv[keep]], axis=1).astype(np.int64)  # (n, 2) (du, dv)
        self.frames = 0

    def cell(self, pixel: tuple[float, float]) -> tuple[int, int]:
        """(row, column) of the cell holding ``pixel`` (u, v)."""
        ny, nx = self.gains.shape[:2]
        j = min(nx - 1, max(0, int(pixel[0] * nx // self.camera.width)))
        i = min(ny - 1, max(0, int(pixel[1] * ny // self.camera.height)))
        return i, j

    def corrected(self, bgr: NDArray[np.float64], pixel: tuple[float, float]) -> NDArray[np.float64]:
        """Colour ``bgr`` seen at ``pixel`` as the classes see it (the gains there applied)."""
        out: NDArray[np.float64] = bgr * gain_at(self.gains, pixel, self.camera.width, self.camera.height)
        return out

    def observe(self, image: NDArray[np.uint8], robots: list[RobotDetection],
                balls: list[BallDetection]) -> NDArray[np.float64] | None:
        """Update the gains from this frame's confident detections, every ``every_frames``-th frame;
        returns them (rows, columns, 3) when they were updated, else None."""
        p = self.params
        self.frames += 1
        if (self.frames - 1) % p.every_frames:
            return None
        roles: list[str] = []
        pixels: list[NDArray[np.float64]] = []
        for r in robots:
            if r.confidence < p.min_confidence:
                continue
            c, s = math.cos(r.theta), math.sin(r.theta)
            xy = np.array([r.x, r.y]) + self.dots @ np.array([[c, s], [-s, c]])
            pixels += [np.array(r.pixel, dtype=np.float64)[None], self.camera.project_xy(xy, self.heights[r.team])]
            roles += [r.team, *("pink" if pink else "green" for pink in self.pattern.dot_is_pink(r.id))]
        for b in balls:
            if b.confidence >= p.min_confidence:
                pixels.append(np.array(b.pixel, dtype=np.float64)[None])
                roles.append("ball")
        if not roles:
            return None
        means = self._means(image, np.concatenate(pixels))
        ny, nx = self.gains.shape[:2]
        num, den = np.zeros((ny, nx, 3)), np.zeros((ny, nx, 3))
        drift_num, drift_den = np.zeros(3), np.zeros(3)
        px_all = np.concatenate(pixels)
        for role, pixel, bgr in zip(roles, px_all, means, strict=True):
            if not np.all(np.isfinite(bgr)):
                continue
            where = (float(pixel[0]), float(pixel[1]))
            ref = self.reference.get(role)
            if ref is None:
                self.reference[role] = self.corrected(bgr, where)
                continue
            now = gain_at(self.gains, where, self.camera.width, self.camera.height)
            seen = np.maximum(bgr, 1.0) * now  # as the classes see it now
            ratio = ref / seen
            if np.any(ratio > p.max_change) or np.any(ratio < 1.0 / p.max_change):
                continue  # a dot taped over, glare: not the marker's colour
            cell = self.cell(where)
            # the cell's gains scaled by how far off the marker still is (the gains between the
            # cells' centres are interpolated: the marker's own is not its cell's)
            num[cell] += ref
            den[cell] += seen / self.gains[cell]
            drift_num += ref
            drift_den += np.maximum(bgr, 1.0) * gain_at(self.start, where, self.camera.width, self.camera.height)
        if not den.any():
            return None
        seen_cells = den[..., 0] > 0.0
        measured = np.where(seen_cells[..., None], num / np.where(den > 0.0, den, 1.0), self.gains)
        drift = drift_num / drift_den  # the whole frame's light against the starting gains'
        self.gains = np.where(seen_cells[..., None], self.gains + p.rate * (measured - self.gains),
                              self.gains + 0.5 * p.rate * (self.start * drift - self.gains))
        self.gains = np.clip(self.gains, 1.0 / p.max_change, p.max_change)
        return self.gains

    def _means(self, image: NDArray[np.uint8], pixels: NDArray[np.float64]) -> NDArray[np.float64]:
        """Mean BGR (n, 3) of the pixels within the id dots' inner radius of each of ``pixels``
        (n, 2) (u, v); NaN where that reaches off the image."""
        h, w = image.shape[:2]
        i = np.floor(pixels[:, 1]).astype(np.int64)[:, None] + self.offsets[None, :, 1]
        j = np.floor(pixels[:, 0]).astype(np.int64)[:, None] + self.offsets[None, :, 0]
        ok = np.all((i >= 0) & (i < h) & (j >= 0) & (j < w), axis=1)
        out = np.full((len(pixels), 3), np.nan)
        if ok.any():
            out[ok] = image[i[ok], j[ok]].astype(np.float64).mean(axis=1)
        return out
