"""The top-down match view: the field seen from above, drawn with OpenCV, one image per frame.

:class:`ViewFrame` is everything the view draws, as plain values a bus can carry: the tracked
world (what our team believes), the truth as faint ghosts, the game state, each own robot's
planned path, its braking trajectory from the safety search, the pass evaluation's heat map and
the commands. :class:`TopDownView` draws it at ``px_per_m`` (default 140 px/m: a robot is
~25 px across, its id printed inside it in ~12 px digits, its heading a tick outside its rim),
with the score, the time, the game state and a legend in a band above the field. Field frame,
metres; image x to the right is field +x, image up is field +y.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.geometry import Field
from cmdragons.messages import GameState, GroundTruth, RobotCommand, TeamReport, WorldState

__all__ = ["TopDownView", "ViewFrame", "view_frame"]

Points = NDArray[np.float64]  # (k, 2) field frame, m

_CARPET = (40, 95, 40)
_LINE = (235, 235, 235)
_BLUE = (235, 140, 20)  # BGR: our robots
_YELLOW = (20, 220, 240)
_BALL = (0, 140, 255)
_PLAN = (255, 230, 120)
_BRAKE = (60, 60, 255)
_GHOST = (150, 150, 150)
_TEXT = (245, 245, 245)
_BAND = (30, 30, 30)
_FONT = cv2.FONT_HERSHEY_SIMPLEX


@dataclass(frozen=True)
class ViewFrame:
    """One frame of the view. ``plans`` and ``braking``: own robot id -> (k, 2) points, field
    frame, m (braking: where the safety search's stopping trajectory goes); ``pass_heat``: the
    receiving points (n, 2) and their values (n,) >= 0, or None."""

    t: float
    world: WorldState | None
    truth: GroundTruth | None
    game: GameState
    ours: str = "blue"
    plans: dict[int, Points] = field(default_factory=dict)
    braking: dict[int, Points] = field(default_factory=dict)
    pass_heat: tuple[Points, NDArray[np.float64]] | None = None
    commands: tuple[RobotCommand, ...] = ()


def view_frame(truth: GroundTruth | None, game: GameState, world: WorldState | None, report: TeamReport,
               commands: Sequence[RobotCommand],
               heat: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None) -> ViewFrame:
    """A :class:`ViewFrame` from one frame's messages on the bus: the simulator's truth, the
    referee's game state, our tracked world, our team's report (plans, the braking paths the safety
    search checked), our commands after safety, and the latest pass evaluation (points, values:
    reports carry it only in the frames it was redone)."""
    plans = {r.id: np.asarray(r.path, dtype=np.float64).reshape(-1, 2) for r in report.robots if len(r.path) >= 2}
    braking = {r.id: np.asarray(r.braking, dtype=np.float64).reshape(-1, 2) for r in report.robots if len(r.braking)}
    if len(report.pass_points):
        heat = (report.pass_points, report.pass_values)
    t = truth.t if truth is not None else report.t
    return ViewFrame(t, world, truth, game, report.team, plans, braking, heat, tuple(commands))


class TopDownView:
    """Draws :class:`ViewFrame` s of one field (see the module docstring)."""

    def __init__(self, geometry: Field, robot_radius_m: float, px_per_m: float = 140.0) -> None:
        self.f, self.r, self.s = geometry, robot_radius_m, px_per_m
        self.band = 64  # px of score, time and legend above the field
        hl, hw = geometry.boundary_half_length, geometry.boundary_half_width
        w, h = int(round(2 * hl * px_per_m)), int(round(2 * hw * px_per_m))
        self.width, self.height = w + w % 2, h + self.band + (h + self.band) % 2  # even: H.264 needs it
        self._hl, self._hw = hl, hw
        self._ball_px = max(5.0, geometry.league.ball.radius_m * px_per_m)  # drawn at least 10 px across
        self._background = self._field()

    # --- coordinates --------------------------------------------------------------------------
    def px(self, xy: Points) -> NDArray[np.int32]:
        """Field points (k, 2) -> pixel centres (k, 2), with 4 bits of sub-pixel (cv2 ``shift=4``)."""
        p = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        u = (p[:, 0] + self._hl) * self.s
        v = self.band + (self._hw - p[:, 1]) * self.s
        return np.round(np.column_stack([u, v]) * 16).astype(np.int32)

    def _pt(self, x: float, y: float) -> tuple[int, int]:
        p = self.px(np.array([[x, y]]))[0]
        return int(p[0]), int(p[1])

    # --- static field ---------------------------------------------------------------------------
    def _field(self) -> NDArray[np.uint8]:
        img = np.zeros((self.height, self.width, 3), dtype=np.uint8)
        img[:] = _CARPET
        img[: self.band] = _BAND
        lw = max(1, int(round(self.f.dims.line_width_m * self.s)))
        for seg in self.f.line_segments():
            a, b = self._pt(*seg.a), self._pt(*seg.b)
            cv2.line(img, a, b, _LINE, lw, cv2.LINE_AA, 4)
        cv2.circle(img, self._pt(0.0, 0.0), int(self.f.dims.center_circle_radius_m * self.s * 16), _LINE, lw,
                   cv2.LINE_AA, 4)
        g, d = self.f.goal_half_width, self.f.dims.goal_depth_m
        for sx in (-1.0, 1.0):
            x0 = sx * self.f.half_length
            pts = self.px(np.array([[x0, g], [x0 + sx * d, g], [x0 + sx * d, -g], [x0, -g]]))
            cv2.polylines(img, [pts.reshape(-1, 1, 2)], False, (200, 200, 200), 3, cv2.LINE_AA, 4)
        return img

    # --- per frame ------------------------------------------------------------------------------
    def draw(self, v: ViewFrame) -> NDArray[np.uint8]:
        """The view of one frame, BGR uint8 (height, width, 3)."""
        img = self._background.copy()
        self._heat(img, v)
        self._ghosts(img, v)
        for path in v.plans.values():
            if len(path) >= 2:
                cv2.polylines(img, [self.px(path).reshape(-1, 1, 2)], False, _PLAN, 1, cv2.LINE_AA, 4)
        for path in v.braking.values():
            if len(path) >= 2:
                cv2.polylines(img, [self.px(path).reshape(-1, 1, 2)], False, _BRAKE, 2, cv2.LINE_AA, 4)
        self._world(img, v)
        self._header(img, v)
        return img

    def _heat(self, img: NDArray[np.uint8], v: ViewFrame) -> None:
        if v.pass_heat is None or not len(v.pass_heat[0]):
            return
        pts, vals = v.pass_heat
        vmax = float(np.max(vals)) if len(vals) else 0.0
        if vmax <= 0.0:
            return
        layer = img.copy()
        rad = int(0.05 * self.s * 16)
        for (x, y), val in zip(self.px(pts), vals, strict=True):
            if val > 0.1 * vmax:  # the weak points would only hide the field
                level = int(255 * val / vmax)
                cv2.circle(layer, (int(x), int(y)), rad, (0, level, 255 - level), -1, cv2.LINE_AA, 4)
        cv2.addWeighted(layer, 0.4, img, 0.6, 0.0, dst=img)

    def _ghosts(self, img: NDArray[np.uint8], v: ViewFrame) -> None:
        if v.truth is None:
            return
        rad = int(self.r * self.s * 16)
        for r in v.truth.robots:
            cv2.circle(img, self._pt(r.x, r.y), rad, _GHOST, 1, cv2.LINE_AA, 4)
        b = v.truth.ball
        cv2.circle(img, self._pt(b.x, b.y), int(self._ball_px * 16), _GHOST, 1, cv2.LINE_AA, 4)

    def _world(self, img: NDArray[np.uint8], v: ViewFrame) -> None:
        if v.world is None:
            return
        rad = int(self.r * self.s * 16)
        commands = {c.id: c for c in v.commands}
        for r in v.world.robots:
            colour = _BLUE if r.team == "blue" else _YELLOW
            c = self._pt(r.x, r.y)
            cv2.circle(img, c, rad, colour if r.visible else _GHOST, -1, cv2.LINE_AA, 4)
            ux, uy = np.cos(r.theta), np.sin(r.theta)
            rim = self._pt(r.x + self.r * ux, r.y + self.r * uy)
            tip = self._pt(r.x + 1.6 * self.r * ux, r.y + 1.6 * self.r * uy)
            cv2.line(img, rim, tip, colour, 3, cv2.LINE_AA, 4)
            text = str(r.id)
            (tw, th), _ = cv2.getTextSize(text, _FONT, 0.55, 2)
            ink = (255, 255, 255) if r.team == "blue" else (0, 0, 0)
            cv2.putText(img, text, (c[0] // 16 - tw // 2, c[1] // 16 + th // 2), _FONT, 0.55, ink, 2, cv2.LINE_AA)
            cmd = commands.get(r.id) if r.team == v.ours else None
            if cmd is not None and (cmd.vx or cmd.vy):
                end = self._pt(r.x + 0.3 * cmd.vx, r.y + 0.3 * cmd.vy)  # 0.3 m of arrow per m/s
                cv2.arrowedLine(img, c, end, (255, 255, 255), 1, cv2.LINE_AA, 4, 0.25)
        b = v.world.ball
        if b is not None:
            cv2.circle(img, self._pt(b.x, b.y), int(self._ball_px * 16), _BALL if b.visible else _GHOST, -1,
                       cv2.LINE_AA, 4)

    def _header(self, img: NDArray[np.uint8], v: ViewFrame) -> None:
        g = v.game
        mins, secs = divmod(v.t, 60.0)
        state = g.command + (f" ({g.for_team})" if g.for_team else "")
        cv2.putText(img, f"blue (us) {g.score_blue} : {g.score_yellow} yellow", (12, 26), _FONT, 0.8, _TEXT, 2,
                    cv2.LINE_AA)
        cv2.putText(img, f"{int(mins):02d}:{secs:05.2f}   {state}", (12, 54), _FONT, 0.6, _TEXT, 1, cv2.LINE_AA)
        x = self.width // 2 - 40
        items = [(_BLUE, "blue robot (tracked)", "disc"), (_YELLOW, "yellow robot", "disc"),
                 (_BALL, "ball", "disc"), (_GHOST, "truth", "ring"), (_PLAN, "plan", "line"),
                 (_BRAKE, "braking (DSS)", "line"), ((0, 200, 55), "pass value", "disc")]  # fmt: skip
        for k, (colour, label, kind) in enumerate(items):
            cx, cy = x + (k % 4) * 150, 20 + (k // 4) * 26
            if kind == "disc":
                cv2.circle(img, (cx, cy), 7, colour, -1, cv2.LINE_AA)
            elif kind == "ring":
                cv2.circle(img, (cx, cy), 7, colour, 1, cv2.LINE_AA)
            else:
                cv2.line(img, (cx - 8, cy), (cx + 8, cy), colour, 2, cv2.LINE_AA)
            cv2.putText(img, label, (cx + 14, cy + 5), _FONT, 0.45, _TEXT, 1, cv2.LINE_AA)
