"""Overlays on the camera images for match videos: what the team believed and intended.

Drawn per camera through its own model, so they sit on the objects they describe: tracked robots
(circle, id, heading) and ball, planned paths, each robot's command before (thin) and after (thick)
the safety search, and the pass evaluation as a heat map of receiving points.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.geometry import Team
from cmdragons.messages import CameraFrame, RobotCommand, TeamCommands, TeamReport, WorldState
from cmdragons.runtime.bus import BaseStage, Publish

__all__ = ["OverlayStage", "draw_overlays"]

_OURS = (255, 255, 255)
_THEIRS = (0, 215, 255)
_PATH = (255, 200, 0)
_BEFORE = (180, 180, 180)
_AFTER = (0, 0, 255)


def _px(model: CameraModel, xy: NDArray[np.float64], z: float) -> NDArray[np.int32]:
    p = model.project_xy(np.asarray(xy, dtype=np.float64).reshape(-1, 2), z)
    return np.nan_to_num(p * 16, nan=-1e6, posinf=-1e6, neginf=-1e6).astype(np.int32)  # 4 bits of subpixel


def draw_overlays(image: NDArray[np.uint8], model: CameraModel, world: WorldState | None, report: TeamReport,
                  commands: Sequence[RobotCommand], robot_height: float) -> NDArray[np.uint8]:  # fmt: skip
    """A copy of ``image`` with the overlays drawn (BGR): ``world`` and ``commands`` (after safety)
    of ``report``'s team in the same frame."""
    out = image.copy()
    if report.pass_points:
        points, values = np.array(report.pass_points), np.array(report.pass_values)
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
                        colour, 1, cv2.LINE_AA)  # fmt: skip
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
                                cv2.LINE_AA, 4, 0.2)  # fmt: skip
        if world.ball is not None:
            b = _px(model, np.array([world.ball.x, world.ball.y]), 0.0215)[0]
            cv2.circle(out, (int(b[0]), int(b[1])), 8 * 16, (0, 140, 255) if world.ball.visible else (0, 0, 255), 1,
                       cv2.LINE_AA, 4)  # fmt: skip
    return out


class OverlayStage(BaseStage):
    """Draws one team's overlays on every camera's image of a frame once the frame's world, report
    and commands came, and hands the drawn images (camera id -> BGR) to ``sink``."""

    def __init__(self, team: Team, models: Sequence[CameraModel], robot_height: float,
                 sink: Callable[[dict[int, NDArray[np.uint8]]], None]) -> None:  # fmt: skip
        self.name = f"overlay/{team}"
        self.inputs = ("camera/*", f"world/{team}", f"report/{team}", f"commands/{team}")
        self.models = {m.id: m for m in models}
        self.robot_height = robot_height
        self.sink = sink
        self._images: dict[int, CameraFrame] = {}
        self._world: WorldState | None = None
        self._report: TeamReport | None = None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, CameraFrame):
            self._images[message.camera_id] = message
        elif isinstance(message, WorldState):
            self._world = message
        elif isinstance(message, TeamReport):
            self._report = message
        elif isinstance(message, TeamCommands) and self._report is not None and self._images:
            frames = {cam: f for cam, f in self._images.items() if f.frame_number == message.frame_number}
            self.sink({cam: draw_overlays(f.image, self.models[cam], self._world, self._report, message.commands,
                                          self.robot_height) for cam, f in sorted(frames.items())})  # fmt: skip
