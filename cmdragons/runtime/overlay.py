"""Match videos from the bus: the top-down view or the camera images with overlays of what the
team believed and intended.

Drawn per camera through its own model, so they sit on the objects they describe: tracked robots
(circle, id, heading) and ball, planned paths, each robot's command before (thin) and after (thick)
the safety search, and the pass evaluation as a heat map of receiving points.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.geometry import Field, Team
from cmdragons.messages import CameraFrame, GameState, GroundTruth, RobotCommand, TeamCommands, TeamReport, WorldState
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.topics import ANY, Contract, Port

__all__ = ["MatchVideoStage", "draw_overlays", "tile_cameras"]

Heat = tuple[NDArray[np.float64], NDArray[np.float64]]  # the pass evaluation: points (n, 2), values (n,)

_OURS = (255, 255, 255)
_THEIRS = (0, 215, 255)
_PATH = (255, 200, 0)
_BEFORE = (180, 180, 180)
_AFTER = (0, 0, 255)


def _px(model: CameraModel, xy: NDArray[np.float64], z: float) -> NDArray[np.int32]:
    p = model.project_xy(np.asarray(xy, dtype=np.float64).reshape(-1, 2), z)
    return np.nan_to_num(p * 16, nan=-1e6, posinf=-1e6, neginf=-1e6).astype(np.int32)  # 4 bits of subpixel


def draw_overlays(image: NDArray[np.uint8], model: CameraModel, world: WorldState | None, report: TeamReport,
                  commands: Sequence[RobotCommand], robot_height: float,
                  heat: Heat | None = None) -> NDArray[np.uint8]:
    """A copy of ``image`` with the overlays drawn (BGR): ``world`` and ``commands`` (after safety)
    of ``report``'s team in the same frame, and the latest pass evaluation ``heat`` (points, values)."""
    out = image.copy()
    if heat is not None and len(heat[0]):
        points, values = heat
        vmax = max(float(values.max()), 1e-9)
        for (x, y), v in zip(_px(model, points, 0.0), values, strict=True):
            if v > 0.02 * vmax:
                level = int(255 * v / vmax)
                cv2.circle(out, (int(x), int(y)), 3 * 16, (0, level, 255 - level), -1, cv2.LINE_AA, 4)
    for robot_plan in report.robots:
        if len(robot_plan.path) >= 2:
            pts = _px(model, np.array(robot_plan.path), 0.0)
            cv2.polylines(out, [pts.reshape(-1, 1, 2)], False, _PATH, 1, cv2.LINE_AA, 4)
    if world is not None:
        scale = 0.25  # metres of arrow per m/s
        after = {c.id: c for c in commands}
        for r in world.robots:
            c = _px(model, np.array([r.x, r.y]), robot_height)[0]
            colour = _OURS if r.team == report.team else _THEIRS
            cv2.circle(out, (int(c[0]), int(c[1])), 14 * 16, colour, 1, cv2.LINE_AA, 4)
            tip = _px(model, np.array([r.x + 0.12 * np.cos(r.theta), r.y + 0.12 * np.sin(r.theta)]), robot_height)[0]
            cv2.line(out, (int(c[0]), int(c[1])), (int(tip[0]), int(tip[1])), colour, 1, cv2.LINE_AA, 4)
            cv2.putText(out, str(r.id), (int(c[0]) // 16 + 10, int(c[1]) // 16 - 10), cv2.FONT_HERSHEY_SIMPLEX, 0.4,
                        colour, 1, cv2.LINE_AA)
            if r.team != report.team:
                continue
            plan = report.robot(r.id)
            base = np.array([r.x, r.y])
            for cmd, col, width in ((plan.command if plan else None, _BEFORE, 1), (after.get(r.id), _AFTER, 2)):
                if cmd is None:
                    continue
                end = _px(model, base + scale * np.array([cmd.vx, cmd.vy]), 0.0)[0]
                start = _px(model, base, 0.0)[0]
                cv2.arrowedLine(out, (int(start[0]), int(start[1])), (int(end[0]), int(end[1])), col, width,
                                cv2.LINE_AA, 4, 0.2)
        if world.ball is not None:
            b = _px(model, np.array([world.ball.x, world.ball.y]), 0.0215)[0]
            cv2.circle(out, (int(b[0]), int(b[1])), 8 * 16, (0, 140, 255) if world.ball.visible else (0, 0, 255), 1,
                       cv2.LINE_AA, 4)
    return out


def tile_cameras(images: dict[int, NDArray[np.uint8]], models: Sequence[CameraModel]) -> NDArray[np.uint8]:
    """All camera images in one picture, laid out as the cameras hang over the field."""
    cams = [m for m in models if m.id in images]
    if not cams:
        raise ValueError("no camera images to tile")
    first = cams[0]
    # field directions of image 'right' and 'up' in the first camera
    c = np.array([[first.width / 2, first.height / 2], [first.width / 2 + 50, first.height / 2],
                  [first.width / 2, first.height / 2 - 50]])
    p = first.unproject(c, 0.0)
    right, up = p[1] - p[0], p[2] - p[0]
    right, up = right / np.linalg.norm(right), up / np.linalg.norm(up)
    pos = {m.id: (float(m.center[:2] @ right), float(m.center[:2] @ up)) for m in cams}
    cols = sorted({round(v[0], 1) for v in pos.values()})
    rows = sorted({round(v[1], 1) for v in pos.values()}, reverse=True)
    h = max(images[m.id].shape[0] for m in cams)
    w = max(images[m.id].shape[1] for m in cams)
    out = np.zeros((h * len(rows), w * len(cols), 3), dtype=np.uint8)
    for m in cams:
        img = images[m.id]
        r, k = rows.index(round(pos[m.id][1], 1)), cols.index(round(pos[m.id][0], 1))
        out[r * h : r * h + img.shape[0], k * w : k * w + img.shape[1]] = img
    return out


class MatchVideoStage(BaseStage):
    """``match.mp4`` from the bus: once a frame's commands of ``team`` came, the frame drawn as the
    top-down field (``view`` "field", :mod:`cmdragons.runtime.topdown`) or as the camera images with
    the team's overlays, tiled as the cameras hang ("cameras"); H.264 through PyAV."""

    def __init__(self, path: Path, view: str, team: Team, models: Sequence[CameraModel], geometry: Field,
                 robot_radius_m: float, robot_height_m: float, fps: float) -> None:
        from cmdragons.runtime.topdown import TopDownView

        self.contract = Contract("video", tuple(Port(t, ANY) for t in ("camera/*", "truth", "referee", f"world/{team}",
                                                                        f"report/{team}", f"commands/{team}")))
        self.path, self.view, self.team, self.fps = path, view, team, fps
        self.models = list(models)
        self.robot_height_m = robot_height_m
        self.topdown = TopDownView(geometry, robot_radius_m)
        self.writer: Any = None
        self._images: dict[int, CameraFrame] = {}
        self._truth: GroundTruth | None = None
        self._game = GameState(0.0)
        self._world: WorldState | None = None
        self._report: TeamReport | None = None
        self._heat: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None  # the latest pass evaluation

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, CameraFrame):
            self._images[message.camera_id] = message
        elif isinstance(message, GroundTruth):
            self._truth = message
        elif isinstance(message, GameState):
            self._game = message
        elif isinstance(message, WorldState):
            self._world = message
        elif isinstance(message, TeamReport):
            self._report = message
            if len(message.pass_points):
                self._heat = (message.pass_points, message.pass_values)
        elif isinstance(message, TeamCommands) and self._report is not None:
            image = self._draw(message)
            if image is not None:
                self._write(image)

    def _draw(self, commands: TeamCommands) -> NDArray[np.uint8] | None:
        from cmdragons.runtime.topdown import view_frame

        assert self._report is not None
        if self.view == "field":
            return self.topdown.draw(view_frame(self._truth, self._game, self._world, self._report, commands.commands,
                                                self._heat))
        frames = {cam: f for cam, f in self._images.items() if f.frame_number == commands.frame_number}
        if not frames:
            return None
        drawn = {cam: draw_overlays(f.image, next(m for m in self.models if m.id == cam), self._world, self._report,
                                    commands.commands, self.robot_height_m, self._heat)
                 for cam, f in frames.items()}
        return tile_cameras(drawn, self.models)

    def _write(self, image: NDArray[np.uint8]) -> None:
        from cmdragons.videoio import VideoWriter

        if self.writer is None:
            self.writer = VideoWriter(self.path, image.shape[1], image.shape[0], self.fps)
        self.writer.write(image)

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
