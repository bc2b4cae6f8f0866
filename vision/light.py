"""Colour classes that follow the light: gains per cell of a grid over the image, learnt from
confident detections only (after Gloye et al., "Plug & Play", colour maps per cell of a grid).

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

    follow: bool = False  # colour classes follow the light (per cell, from confident detections)
    grid: tuple[int, int] = setting((4, 3), lo=1, hi=64)  # cells across and down the image
    rate: float = setting(0.1, lo=0.0, hi=1.0)  # share of a cell's measured change taken per frame
    min_confidence: float = setting(0.7, lo=0.0, hi=1.0)  # detections at least this confident teach
    max_change: float = setting(2.0, lo=1.0, hi=8.0)  # a gain stays within [1 / this, this]; a marker
    #   further than this from its role's colour in a channel teaches nothing
    every_frames: int = setting(6, lo=1, hi=1000)  # the gains are updated every this many frames (light drifts slowly)


class LightFollower:
    """The gains per cell of one camera, updated from each frame's detections."""

    def __init__(self, params: LightParams, league: LeagueParams, camera: CameraModel,
                 heights: dict[Team, float]) -> None:
        self.params, self.camera, self.heights = params, camera, heights
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
