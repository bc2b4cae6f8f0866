"""``cmdragons vision --overlay`` on a still image: a PNG of the frame with every detection, the
ball and the fitted field drawn where they are."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from cmdragons.camera import CameraModel
from cmdragons.cli import main
from cmdragons.geometry import Field

from .conftest import LEAGUE, grid_of_robots, render, snapshot


def test_overlay_of_a_still_image_draws_detections_ball_and_field(
    cameras: list[CameraModel], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    model = cameras[0]
    robots = grid_of_robots(model, [1.0], margin_px=80.0)[:6]
    r = LEAGUE.ball.radius_m
    ball = model.unproject(np.array([[model.width * 0.3, model.height * 0.85]]), r)[0]
    image, _ = render(model, snapshot(robots, ball=(ball[0], ball[1], r)))
    cv2.imwrite(str(tmp_path / "frame.png"), image)
    out = tmp_path / "out"
    assert main(["vision", str(tmp_path / "frame.png"), "--overlay", "--out", str(out), "--no-progress"]) == 0
    assert "overlays -> 1 PNG" in capsys.readouterr().out
    drawn = cv2.imread(str(out / "overlay" / "camera_0_000000.png"), cv2.IMREAD_COLOR)
    assert drawn is not None and drawn.shape == image.shape
    det = json.loads((out / "detections.jsonl").read_text().splitlines()[0])
    assert len(det["robots"]) == 6 and len(det["balls"]) == 1
    changed = np.any(drawn != image, axis=2)

    def ring(u: float, v: float, radius_px: float, colour: tuple[int, int, int]) -> int:
        """Pixels of ``colour`` (within 60 grey levels) drawn within ``radius_px`` + 3 of (u, v)."""
        vv, uu = np.mgrid[0 : image.shape[0], 0 : image.shape[1]]
        near = np.hypot(uu + 0.5 - u, vv + 0.5 - v) <= radius_px + 3
        close = np.all(np.abs(drawn.astype(int) - colour) < 60, axis=2)
        return int(np.count_nonzero(near & changed & close))

    ppm = model.pixels_per_metre((0.0, 0.0), LEAGUE.robot.height_m)
    for rd in det["robots"]:
        colour = (255, 160, 0) if rd["team"] == "blue" else (0, 230, 255)
        assert ring(*rd["pixel"], LEAGUE.robot.radius_m * ppm, colour) > 20, rd  # the outline and heading
    (b,) = det["balls"]
    assert ring(*b["pixel"], 8.0, (0, 140, 255)) > 10
    # the fitted field: the halfway line drawn in magenta where the camera model puts it
    f = Field(LEAGUE)
    line = model.project_xy(np.column_stack([np.zeros(20), np.linspace(-f.half_width, f.half_width, 20)]), 0.0)
    inside = model.in_image(line, margin=2.0)
    magenta = np.all(np.abs(drawn.astype(int) - (255, 0, 255)) < 90, axis=2)
    hits = [magenta[int(v) - 2 : int(v) + 3, int(u) - 2 : int(u) + 3].any() for u, v in line[inside]]
    assert inside.sum() >= 5 and all(hits)
    # nothing drawn far from every object and line: a patch of bare carpet stays as it was
    assert np.count_nonzero(changed) < 0.05 * changed.size
