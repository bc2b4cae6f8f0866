"""Scenes rendered by the simulator's camera renderer, with their truth, for vision tests."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, CamerasParams, cameras_from_config
from cmdragons.geometry import LeagueParams
from sim.render import CameraRenderer, CameraTruth, RenderParams
from sim.snapshot import Snapshot

LEAGUE = LeagueParams()


def snapshot(
    robots: Sequence[Sequence[float]], ball: Sequence[float] = (50.0, 50.0, 0.0215), frame: int = 0
) -> Snapshot:
    """Robots as (team 0 blue / 1 yellow, id, x, y, theta[, vx, vy, omega]), ball (x, y, z[, vx, vy, vz]);
    field frame, SI units."""
    rows = np.zeros((len(robots), 8))
    for k, r in enumerate(robots):
        rows[k, : len(r)] = r
    b = np.zeros(6)
    b[: len(ball)] = ball
    return Snapshot(t=frame / 60.0, frame_number=frame, ball=b, robots=rows)


def grid_of_robots(model: CameraModel, headings: Sequence[float], margin_px: float = 60.0) -> list[list[float]]:
    """Every id of both teams once per heading, on a grid inside ``model``'s view (robot tops at
    least ``margin_px`` inside the image): rows (team, id, x, y, theta)."""
    h = LEAGUE.robot.height_m
    corners = model.unproject(
        np.array([[margin_px, margin_px], [model.width - margin_px, model.height - margin_px]]), h
    )
    (x0, x1), (y0, y1) = sorted(corners[:, 0]), sorted(corners[:, 1])
    out = []
    k = 0
    spacing = 0.3
    nx = int((x1 - x0) / spacing)
    for heading in headings:
        for team in (0, 1):
            for rid in range(16):
                out.append([team, rid, x0 + (k % nx) * spacing, y0 + (k // nx) * spacing, heading + 0.37 * rid])
                k += 1
    if y0 + (k // nx) * spacing > y1:
        raise ValueError("too many robots for one camera view")
    return out


@pytest.fixture(scope="session")
def cameras() -> list[CameraModel]:
    return cameras_from_config(CamerasParams(), LEAGUE)


def render(model: CameraModel, snap: Snapshot, params: RenderParams | None = None,
           seed: int = 0) -> tuple[NDArray[np.uint8], CameraTruth]:
    renderer = CameraRenderer(model, LEAGUE, params or RenderParams(), seed=seed)
    image, truth = renderer.render(snap)
    return image.copy(), truth
