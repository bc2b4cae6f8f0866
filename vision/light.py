"""Colour classes that follow the light: gains per cell of a grid over the image (after Gloye et
al., "Plug & Play", colour maps per cell of a grid), measured on the carpet or learnt from
confident detections.

``measure: carpet`` (the default, with ``grid: [8, 6]`` and ``saturation_reach: 1.25``): the
carpet is one material over the whole field and is seen in every cell in every frame, so its colour
in a cell is that cell's light (vignetting, lamps' pools, a window's light and their drift). At the
first update the reference is the ``carpet_reference_percentile`` of the cells' carpets (per BGR
channel); every cell darker than it is lifted to it (its gains bring its carpet there), a brighter
cell is left as it is (the boxes were learnt on frames as the camera gives them, bright parts
included); the lift applies over the field mask only (``carpet_band_px``): a lifted wooden floor
passes for pink. The field's robots, lines and ball are few of a cell's pixels, so the median of
the field's pixels sampled in a cell is the carpet's. Nothing has to be detected first: a cell a
robot drives into is lifted before the robot gets there, and a marker lost in a dark corner does
not leave its cell's light unlearnt. It cannot darken a cell nor follow a colour cast that
brightens a channel (``markers`` can). On ``bench vision``'s lab rows it finds the daylight ball at
the image's dark bottom edge and the dim light's robot in the dark top-left corner (every lab row
at its target); on tests/vision/test_realistic_pipeline.py's 1280x800 lab camera 99.9% of the
robots (the markers: 99.5%). It needs classes kept apart: lifted, a dot's dark fringe comes within
reach of a box that strays across grey (a blue box learnt from a pink dot taken for blue reached
pink's fringe, and 97.8% were found there, until ``tune --auto`` left out blobs off their hue).

``measure: markers``:

Each BGR channel of a pixel is scaled by its cell's gain before it is classified
(:meth:`vision.cmvision.Segmenter.set_light`), so a class box learnt once holds under light that
is uneven over the field and drifts over a match. The colours the boxes were made for are the
first confident detections' (per role: the ball, the team markers, the id dots' pink and green);
afterwards every confident robot's markers and every confident ball measure, in the cell they lie
in, the gain that brings them back to those colours, and the cell's gain moves toward it by
``rate`` a frame; a cell with nothing seen this frame moves, at half that rate, toward the gain
the whole frame measured (light that changes everywhere at once). A marker whose colour is far
off its role's (a dot taped over, glare) teaches nothing. The gains are updated every
``every_frames`` frames: light drifts over seconds, and a frame's update costs a few milliseconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.config import Validated, setting
from cmdragons.geometry import LeagueParams, Team
from cmdragons.messages import BallDetection, RobotDetection

__all__ = ["LightFollower", "LightParams"]


@dataclass(frozen=True)
class LightParams(Validated):
    """configs/vision.yaml ``light``."""

    follow: bool = False  # colour classes follow the light (per cell, measured as ``measure`` says)
    grid: tuple[int, int] = setting((8, 6), lo=1, hi=64)  # cells across and down the image
    rate: float = setting(0.1, lo=0.0, hi=1.0)  # share of a cell's measured change taken per frame
    min_confidence: float = setting(0.7, lo=0.0, hi=1.0)  # detections at least this confident teach
    max_change: float = setting(2.0, lo=1.0, hi=8.0)  # a gain stays within [1 / this, this]; a marker
    #   further than this from its role's colour in a channel teaches nothing
    every_frames: int = setting(6, lo=1, hi=1000)  # the gains are updated every this many frames (light drifts slowly)
    measure: str = setting("carpet", choices=("carpet", "markers"))  # what the light is measured on
    carpet_step_px: int = setting(8, lo=1, hi=64)  # carpet: the field's pixels sampled every this many
    carpet_min_samples: int = setting(40, lo=1, hi=100000)  # carpet: a cell with fewer samples on the field
    #   takes the whole field's gains
    carpet_band_px: int = setting(8, lo=1, hi=256)  # carpet: the gains apply over the field mask (and the
    #   goals), decided per band of about this many rows; the floor past it is taken as it is
    # tune --auto: a box's chroma (U, V) reaches this many times further from grey than its samples on
    # the side away from grey (bright samples are clipped by the sensor; lifted, unclipped colours lie further)
    saturation_reach: float = setting(1.25, lo=1.0, hi=2.0)
    carpet_reference_percentile: float = setting(50.0, lo=0.0, hi=100.0)  # carpet: cells darker than this
    #   percentile of the cells' carpets at the first update are lifted to it, brighter ones left


class LightFollower:
    """The gains per cell of one camera, updated from each frame's carpet or its detections."""

    def __init__(self, params: LightParams, league: LeagueParams, camera: CameraModel,
                 heights: dict[Team, float]) -> None:
        self.params, self.camera, self.heights = params, camera, heights
        dims = league.dims
        self.half_field = (dims.length_m / 2.0, dims.width_m / 2.0)
        nx, ny = params.grid
        self.gains = np.ones((ny, nx, 3))
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
        self.carpet_ref: NDArray[np.float64] | None = None  # the field's carpet (BGR) at the first update
        self._carpet_samples()

    def _carpet_samples(self) -> None:
        """The pixels sampled on the field (every ``carpet_step_px``, inside the field lines), as flat
        indices sorted by cell, and where each cell's run of them starts (``_starts``, one more than cells)."""
        cam, step = self.camera, self.params.carpet_step_px
        v, u = np.mgrid[step // 2 : cam.height : step, step // 2 : cam.width : step]
        rays = cam.rays(np.stack([u + 0.5, v + 0.5], axis=-1).reshape(-1, 2).astype(np.float64))
        xy = cam.center[:2] + cam.center[2] * rays[:, :2]
        on = (np.abs(xy[:, 0]) <= self.half_field[0]) & (np.abs(xy[:, 1]) <= self.half_field[1])
        on &= np.all(np.isfinite(xy), axis=1)
        u, v = u.ravel()[on], v.ravel()[on]
        ny, nx = self.gains.shape[:2]
        cell = np.minimum(v * ny // cam.height, ny - 1) * nx + np.minimum(u * nx // cam.width, nx - 1)
        order = np.argsort(cell, kind="stable")
        self._flat = (v * cam.width + u)[order].astype(np.int64)
        self._starts = np.searchsorted(cell[order], np.arange(nx * ny + 1))

    def cell(self, pixel: tuple[float, float]) -> tuple[int, int]:
        """(row, column) of the cell holding ``pixel`` (u, v)."""
        ny, nx = self.gains.shape[:2]
        j = min(nx - 1, max(0, int(pixel[0] * nx // self.camera.width)))
        i = min(ny - 1, max(0, int(pixel[1] * ny // self.camera.height)))
        return i, j

    def corrected(self, bgr: NDArray[np.float64], pixel: tuple[float, float]) -> NDArray[np.float64]:
        """Colour ``bgr`` seen at ``pixel`` as the classes see it (its cell's gains applied)."""
        out: NDArray[np.float64] = bgr * self.gains[self.cell(pixel)]
        return out

    def observe(self, image: NDArray[np.uint8], robots: list[RobotDetection],
                balls: list[BallDetection]) -> NDArray[np.float64] | None:
        """Update the gains from this frame's confident detections, every ``every_frames``-th frame;
        returns them (rows, columns, 3) when they were updated, else None."""
        p = self.params
        self.frames += 1
        if (self.frames - 1) % p.every_frames:
            return None
        if p.measure == "carpet":
            return self._observe_carpet(image)
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
        px_all = np.concatenate(pixels)
        for role, pixel, bgr in zip(roles, px_all, means, strict=True):
            if not np.all(np.isfinite(bgr)):
                continue
            where = (float(pixel[0]), float(pixel[1]))
            ref = self.reference.get(role)
            if ref is None:
                self.reference[role] = self.corrected(bgr, where)
                continue
            ratio = ref / np.maximum(bgr, 1.0)
            if np.any(ratio > p.max_change) or np.any(ratio < 1.0 / p.max_change):
                continue  # a dot taped over, glare: not the marker's colour
            cell = self.cell(where)
            num[cell] += ref
            den[cell] += np.maximum(bgr, 1.0)
        if not den.any():
            return None
        seen_cells = den[..., 0] > 0.0
        measured = np.where(seen_cells[..., None], num / np.where(den > 0.0, den, 1.0), self.gains)
        whole = num.sum(axis=(0, 1)) / den.sum(axis=(0, 1))
        self.gains = np.where(seen_cells[..., None], self.gains + p.rate * (measured - self.gains),
                              self.gains + 0.5 * p.rate * (whole - self.gains))
        self.gains = np.clip(self.gains, 1.0 / p.max_change, p.max_change)
        return self.gains

    def _observe_carpet(self, image: NDArray[np.uint8]) -> NDArray[np.float64] | None:
        """Each cell's gains toward those that bring its carpet (the median of its field samples) up
        to the reference carpet: at the first update, the ``carpet_reference_percentile`` of the
        cells' carpets (taken at once then, by ``rate`` after); a cell brighter is left as it is."""
        p = self.params
        flat = image.reshape(-1, 3)[self._flat].astype(np.float64)
        if len(flat) < p.carpet_min_samples:
            return None
        whole = np.median(flat, axis=0)
        ny, nx = self.gains.shape[:2]
        seen = np.empty((ny * nx, 3))
        for c in range(nx * ny):
            a, b = self._starts[c], self._starts[c + 1]
            seen[c] = np.median(flat[a:b], axis=0) if b - a >= p.carpet_min_samples else whole
        seen = np.maximum(seen, 1.0)
        first = self.carpet_ref is None
        if self.carpet_ref is None:
            self.carpet_ref = np.percentile(seen, p.carpet_reference_percentile, axis=0)
        measured = np.clip(self.carpet_ref / seen, 1.0, p.max_change).reshape(ny, nx, 3)
        self.gains = measured if first else self.gains + p.rate * (measured - self.gains)
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
