"""Detections scored against ground truth: what ``cmdragons bench vision`` and ``cmdragons vision``
(on a recording with truth.jsonl) report.

Per camera frame, the objects that camera can see are scored: a robot whose whole top is in the
image (the truth's per-camera pixel), a ball whose silhouette is at least ``min_ball_visible``
visible. A detection within ``match_m`` of a true object of its kind is that object (found);
one with no true object that near is a false detection. Position and heading errors are taken
over robots found with the right team and id.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from cmdragons.messages import DetectionFrame, GroundTruth

__all__ = ["Score", "ball_height_bias_m"]


@dataclass
class Score:
    """Running totals over camera frames (field frame, metres, radians)."""

    match_m: float = 0.1
    min_ball_visible: float = 0.5
    frames: int = 0
    robots_visible: int = 0
    robots_found: int = 0
    robot_detections: int = 0
    ids_right: int = 0
    ball_visible: int = 0
    ball_found: int = 0
    false_robots: int = 0
    false_balls: int = 0
    robot_err_m: list[float] = field(default_factory=list)
    heading_err_rad: list[float] = field(default_factory=list)
    ball_err_m: list[float] = field(default_factory=list)
    # per ball found: camera id, detection (x, y), truth (x, y, z)
    ball_pairs: list[tuple[int, float, float, float, float, float]] = field(default_factory=list)

    def add(self, det: DetectionFrame, truth: GroundTruth) -> None:
        """Score one camera's detections against the truth of the same instant."""
        cam = det.camera_id
        self.frames += 1
        true_xy = np.array([[r.x, r.y] for r in truth.robots]).reshape(-1, 2)
        visible = [k for k, r in enumerate(truth.robots) if cam in r.pixels]
        self.robots_visible += len(visible)
        found: set[int] = set()
        for rd in det.robots:
            self.robot_detections += 1
            dist = np.hypot(true_xy[:, 0] - rd.x, true_xy[:, 1] - rd.y)
            if dist.size == 0 or float(dist.min()) > self.match_m:
                self.false_robots += 1
                continue
            k = int(np.argmin(dist))
            t = truth.robots[k]
            found.add(k)
            if t.team == rd.team and t.id == rd.id:
                self.ids_right += 1
                self.robot_err_m.append(float(dist[k]))
                self.heading_err_rad.append(math.remainder(rd.theta - t.theta, 2.0 * math.pi))
        self.robots_found += len(found & set(visible))
        b = truth.ball
        seen = b.pixels.get(cam)
        ball_visible = seen is not None and seen[2] >= self.min_ball_visible
        self.ball_visible += int(ball_visible)
        hit = False
        for bd in det.balls:
            d = math.hypot(bd.x - b.x, bd.y - b.y)
            if d > self.match_m:
                self.false_balls += 1
            elif not hit:
                hit = True
                self.ball_err_m.append(d)
                self.ball_pairs.append((cam, bd.x, bd.y, b.x, b.y, b.z))
        self.ball_found += int(hit and ball_visible)

    def summary(self) -> dict[str, float]:
        """Unit-named metrics: RMS errors in mm and degrees, rates in 0..1, false detections per frame."""

        def rms(v: list[float], scale: float) -> float:
            return float(np.sqrt(np.mean(np.square(v))) * scale) if v else math.nan

        def rate(a: int, b: int) -> float:
            return a / b if b else math.nan

        return {
            "robot_rms_mm": rms(self.robot_err_m, 1e3),
            "ball_rms_mm": rms(self.ball_err_m, 1e3),
            "heading_rms_deg": rms(self.heading_err_rad, 180.0 / math.pi),
            "id_accuracy": rate(self.ids_right, self.robot_detections - self.false_robots),
            "robot_detection_rate": rate(self.robots_found, self.robots_visible),
            "ball_detection_rate": rate(self.ball_found, self.ball_visible),
            "false_per_frame": rate(self.false_robots + self.false_balls, self.frames),
            "camera_frames": float(self.frames),
        }


def ball_height_bias_m(
    score: Score, centres: Mapping[int, NDArray[np.float64]], projected_above_centre_m: float
) -> float:
    """How much higher than vision projected them the ball's blobs should have been projected to
    meet the truth: least squares over the balls found (m; 0: no radial bias left).

    A detection is ``C + (C_z - z_p) * ray`` with C the optical centre (``centres`` by camera id,
    field frame) and z_p the true centre's height plus ``projected_above_centre_m``; the blob's
    ray meets the truth best at the true centre's height plus the fitted h. The result is
    ``h - projected_above_centre_m``: a bias outward from each camera's nadir, growing with the
    distance from it, shows as a positive height.
    """
    if not score.ball_pairs:
        return math.nan
    pairs = np.array(score.ball_pairs)
    c = np.array([centres[int(k)] for k in pairs[:, 0]])
    det, true_xy, true_z = pairs[:, 1:3], pairs[:, 3:5], pairs[:, 5]
    ray = (det - c[:, :2]) / (c[:, 2] - true_z - projected_above_centre_m)[:, None]
    # truth = C + (C_z - z - h) * ray  =>  a + h * ray = 0 with a = truth - C - (C_z - z) * ray
    a = true_xy - c[:, :2] - (c[:, 2] - true_z)[:, None] * ray
    h = -float(np.sum(a * ray) / np.sum(ray * ray))
    return h - projected_above_centre_m
