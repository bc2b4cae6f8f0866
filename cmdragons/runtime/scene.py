"""Foxglove's 3D scene of a match, written into the run's MCAP log beside the bus's topics.

Topics (Foxglove's published ``foxglove.SceneUpdate`` schema, from foxglove-schemas-protobuf), all in
the frame ``field`` (the field frame, metres; pick it as the 3D panel's display frame):

    /scene/field    once: the carpet, the field's lines and the centre circle
    /scene/objects  per frame: every robot (a cylinder in its team's colour, an arrow along its
                    heading) and the ball, at their true positions
    /scene/plans    per frame and brain: each robot's planned path and the braking trajectory the
                    safety search (DSS) checked

So a user opens run.mcap in Foxglove, adds a 3D panel, and sees the match without writing anything.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from cmdragons.geometry import Field
from cmdragons.messages import GroundTruth, TeamReport
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.log import RunLog
from cmdragons.runtime.topics import ANY, Contract, Port

__all__ = ["FRAME", "SceneStage"]

FRAME = "field"
# colours (r, g, b, a), 0..1
_TEAM_RGBA = {"blue": (0.15, 0.35, 1.0, 1.0), "yellow": (1.0, 0.85, 0.0, 1.0)}
_BALL_RGBA = (1.0, 0.45, 0.0, 1.0)
_LINE_RGBA = (1.0, 1.0, 1.0, 1.0)
_CARPET_RGBA = (0.05, 0.35, 0.1, 1.0)
_PATH_RGBA = (0.9, 0.9, 0.9, 0.8)
_BRAKE_RGBA = (1.0, 0.1, 0.1, 0.9)
_CIRCLE_POINTS = 48  # the centre circle as a closed polygon of this many corners


class SceneStage(BaseStage):
    """Writes the scene topics into ``log`` from the truth and the brains' reports."""

    contract = Contract("scene", (Port("truth", ANY), Port("report/*", ANY)))

    def __init__(self, log: RunLog, field: Field, robot_radius_m: float, robot_height_m: float,
                 ball_radius_m: float) -> None:
        from foxglove_schemas_protobuf import LinePrimitive_pb2, SceneUpdate_pb2

        self._update = SceneUpdate_pb2.SceneUpdate
        self._kinds = LinePrimitive_pb2.LinePrimitive.Type
        self.log = log
        self.field = field
        self.robot = (robot_radius_m, robot_height_m)
        self.ball_radius_m = ball_radius_m
        self._field_written = False

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, GroundTruth):
            if not self._field_written:
                self.log.write_proto("/scene/field", message.t, self._field_scene(message.t))
                self._field_written = True
            self.log.write_proto("/scene/objects", message.t, self._objects(message))
        elif isinstance(message, TeamReport):
            self.log.write_proto("/scene/plans", message.t, self._plans(message))

    def _entity(self, update: Any, t: float, entity_id: str) -> Any:
        e = update.entities.add(frame_id=FRAME, id=entity_id)
        e.timestamp.FromNanoseconds(max(0, int(round(t * 1e9))))
        return e

    @staticmethod
    def _rgba(into: Any, rgba: tuple[float, float, float, float]) -> None:
        into.r, into.g, into.b, into.a = rgba

    def _line(self, entity: Any, points: Any, rgba: tuple[float, float, float, float], thickness_m: float,
              kind: str = "LINE_STRIP", z: float = 0.0) -> None:
        line = entity.lines.add(type=self._kinds.Value(kind), thickness=thickness_m)
        line.pose.orientation.w = 1.0
        for x, y in np.asarray(points, dtype=np.float64).reshape(-1, 2):
            line.points.add(x=float(x), y=float(y), z=z)
        self._rgba(line.color, rgba)

    def _field_scene(self, t: float) -> Any:
        f, d = self.field, self.field.dims
        update = self._update()
        e = self._entity(update, t, "field")
        carpet = e.cubes.add()
        carpet.pose.position.z = -0.005
        carpet.pose.orientation.w = 1.0
        carpet.size.x, carpet.size.y, carpet.size.z = 2 * f.boundary_half_length, 2 * f.boundary_half_width, 0.01
        self._rgba(carpet.color, _CARPET_RGBA)
        segments = [p for s in f.line_segments() for p in (s.a, s.b)]
        self._line(e, segments, _LINE_RGBA, d.line_width_m, "LINE_LIST", z=0.001)
        a = np.linspace(0.0, 2 * math.pi, _CIRCLE_POINTS, endpoint=False)
        r = d.center_circle_radius_m
        self._line(e, np.stack([r * np.cos(a), r * np.sin(a)], axis=1), _LINE_RGBA, d.line_width_m, "LINE_LOOP",
                   z=0.001)
        return update

    def _objects(self, gt: GroundTruth) -> Any:
        radius, height = self.robot
        update = self._update()
        e = self._entity(update, gt.t, "objects")
        for rt in gt.robots:
            c = e.cylinders.add()
            c.pose.position.x, c.pose.position.y, c.pose.position.z = rt.x, rt.y, height / 2
            c.pose.orientation.z, c.pose.orientation.w = math.sin(rt.theta / 2), math.cos(rt.theta / 2)
            c.size.x = c.size.y = 2 * radius
            c.size.z = height
            c.bottom_scale = c.top_scale = 1.0
            self._rgba(c.color, _TEAM_RGBA[rt.team])
            arrow = e.arrows.add(shaft_length=radius, shaft_diameter=0.02, head_length=0.04, head_diameter=0.05)
            arrow.pose.position.x, arrow.pose.position.y, arrow.pose.position.z = rt.x, rt.y, height + 0.01
            arrow.pose.orientation.z, arrow.pose.orientation.w = math.sin(rt.theta / 2), math.cos(rt.theta / 2)
            self._rgba(arrow.color, _LINE_RGBA)
            e.texts.add(text=f"{rt.team[0].upper()}{rt.id}", font_size=0.12, billboard=True,
                        pose={"position": {"x": rt.x, "y": rt.y, "z": height + 0.1}, "orientation": {"w": 1.0}},
                        color={"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0})
        b = gt.ball
        s = e.spheres.add()
        s.pose.position.x, s.pose.position.y, s.pose.position.z = b.x, b.y, b.z + self.ball_radius_m
        s.pose.orientation.w = 1.0
        s.size.x = s.size.y = s.size.z = 2 * self.ball_radius_m
        self._rgba(s.color, _BALL_RGBA)
        return update

    def _plans(self, report: TeamReport) -> Any:
        update = self._update()
        e = self._entity(update, report.t, f"plans/{report.team}")
        for r in report.robots:
            if len(r.path) > 1:
                self._line(e, r.path, _PATH_RGBA, 0.015, z=0.005)
            if len(r.braking) > 1:
                self._line(e, r.braking, _BRAKE_RGBA, 0.03, z=0.01)
        return update
