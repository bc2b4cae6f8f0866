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
off its role's (a dot taped over, glare) teaches nothing.
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


class LightFollower:
    """The gains per cell of one camera, updated from each frame's detections."""

    def __init__(self, params: LightParams, league: LeagueParams, camera: CameraModel,
                 heights: dict[Team, float]) -> None:  # fmt: skip
        self.params, self.camera, self.heights = params, camera, heights
        nx, ny = params.grid
        self.gains = np.ones((ny, nx, 3))
        self.reference: dict[str, NDArray[np.float64]] = {}  # role -> the BGR its boxes were made for
        pat = league.pattern
        self.pattern = pat
        self.dots = np.array(pat.dot_positions_m, dtype=np.float64).reshape(-1, 2)
        depth = camera.center[2] - league.robot.height_m
        self.dot_px = 0.6 * pat.id_dot_diameter_m / 2 * camera.f / depth  # sampled within this of a dot's centre
        self.centre_px = 0.6 * pat.center_dot_diameter_m / 2 * camera.f / depth
        self.ball_px = 0.5 * league.ball.radius_m * camera.f / camera.center[2]

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
                balls: list[BallDetection]) -> NDArray[np.float64]:  # fmt: skip
        """Update the gains from this frame's confident detections; returns them (rows, columns, 3)."""
        p = self.params
        seen: list[tuple[str, tuple[float, float], NDArray[np.float64]]] = []  # role, pixel, mean BGR
        for r in robots:
            if r.confidence < p.min_confidence:
                continue
            z = self.heights[r.team]
            seen.append((r.team, r.pixel, self._mean(image, r.pixel, self.centre_px)))
            c, s = math.cos(r.theta), math.sin(r.theta)
            pink = self.pattern.dot_is_pink(r.id)
            for (dx, dy), is_pink in zip(self.dots, pink, strict=True):
                px = self.camera.project_xy(np.array([r.x + c * dx - s * dy, r.y + s * dx + c * dy]), z)
                if np.all(np.isfinite(px)):
                    pixel = (float(px[0]), float(px[1]))
                    seen.append(("pink" if is_pink else "green", pixel, self._mean(image, pixel, self.dot_px)))
        for b in balls:
            if b.confidence >= p.min_confidence:
                seen.append(("ball", b.pixel, self._mean(image, b.pixel, self.ball_px)))
        ny, nx = self.gains.shape[:2]
        num, den = np.zeros((ny, nx, 3)), np.zeros((ny, nx, 3))
        for role, pixel, bgr in seen:
            if not np.all(np.isfinite(bgr)):
                continue
            ref = self.reference.get(role)
            cell = self.cell(pixel)
            if ref is None:
                self.reference[role] = self.corrected(bgr, pixel)
                continue
            ratio = ref / np.maximum(bgr, 1.0)
            if np.any(ratio > p.max_change) or np.any(ratio < 1.0 / p.max_change):
                continue  # a dot taped over, glare: not the marker's colour
            num[cell] += ref
            den[cell] += np.maximum(bgr, 1.0)
        if not den.any():
            return self.gains
        seen_cells = den[..., 0] > 0.0
        measured = np.where(seen_cells[..., None], num / np.where(den > 0.0, den, 1.0), self.gains)
        whole = num.sum(axis=(0, 1)) / den.sum(axis=(0, 1))
        self.gains = np.where(seen_cells[..., None], self.gains + p.rate * (measured - self.gains),
                              self.gains + 0.5 * p.rate * (whole - self.gains))  # fmt: skip
        self.gains = np.clip(self.gains, 1.0 / p.max_change, p.max_change)
        return self.gains

    @staticmethod
    def _mean(image: NDArray[np.uint8], pixel: tuple[float, float], r_px: float) -> NDArray[np.float64]:
        """Mean BGR of the pixels within ``r_px`` (at least 1) of ``pixel``; NaN off the image."""
        r = max(1.0, r_px)
        h, w = image.shape[:2]
        i0, i1 = int(pixel[1] - r), int(pixel[1] + r) + 1
        j0, j1 = int(pixel[0] - r), int(pixel[0] + r) + 1
        if not (0 <= i0 and i1 <= h and 0 <= j0 and j1 <= w):
            return np.full(3, np.nan)
        v, u = np.mgrid[i0:i1, j0:j1] + 0.5
        inside = (u - pixel[0]) ** 2 + (v - pixel[1]) ** 2 <= r * r
        out: NDArray[np.float64] = image[i0:i1, j0:j1][inside].astype(np.float64).mean(axis=0)
        return out
