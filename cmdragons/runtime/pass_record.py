"""Every pass of one team accounted for, from the simulator's true state.

A pass starts with a kick of ours the strategy meant as a pass (the team report's action) and the
pass it followed then (passer, receiver, target, one-touch or trap), with the kick speed the strategy
asked (over the ground, the passer's last armed command in the team report) and the kicker's speed
relative to the robot that fired. On the first true frame after the kick the record takes the kick
speed measured (the ball's speed over the ground then, with the sliding deceleration since the kick
added back: the ball's speed as it left the kicker), how far the ball runs off the
line to the target, and what the models predicted from that frame: when the ball reaches the target
(the two-phase ball model) and when the closest opponent can be in the ball's way (its limits). Then
it follows the true frames (the ball at the target: it touches, within ``touch_m``, the kicker face
of a robot standing at the target facing it) until the pass is over, and says how:

- ``received``: a team-mate touched the ball first and kicked it on within ``control_s`` or held it
  then (its centre within ``hold_m``);
- ``too_fast``: a team-mate touched it first and it got away (no kick, not held);
- ``intercepted``: an opponent touched it first;
- ``out``: it left the field untouched; ``stopped``: the referee stopped play first;
- ``late``: it ran ``past_m`` past the target or died there untouched, the receiver not yet there;
- ``missed``: so, with the receiver there (the ball off its line, or not met);
- ``too_slow``: it died short of the target untouched;
- ``reassigned``: late or missed after the strategy had given the pass up (the receiver taken off
  it) while the ball ran;
- ``timeout``: still untouched after the pass timeout.

Times are seconds after the kick; field frame, metres.
"""

from __future__ import annotations

import enum
import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from cmdragons.geometry import Field, RobotShape, Team
from cmdragons.messages import GameState, GroundTruth, Kick, KickPurpose, PassReport, RefereeCommand, TeamReport
from strategy.ballmodel import BallModel, interception_times, robot_limits
from strategy.passing import PassRecordParams

if TYPE_CHECKING:
    from cmdragons.runtime.settings import Settings

__all__ = ["PassEnd", "PassRecord", "PassRecorder"]

_GROUND_M = 1e-6  # a ball centre this little above its radius lies on the ground (float slack)


class PassEnd(enum.StrEnum):
    """How a pass ended (see the module docstring)."""

    RECEIVED = "received"
    TOO_FAST = "too_fast"
    INTERCEPTED = "intercepted"
    OUT = "out"
    STOPPED = "stopped"
    LATE = "late"
    MISSED = "missed"
    TOO_SLOW = "too_slow"
    REASSIGNED = "reassigned"
    TIMEOUT = "timeout"


@dataclass
class PassRecord:
    """One pass, as it went (times s after the kick, None: never)."""

    t_kick: float
    passer: int
    receiver: int | None  # None: a kick meant as a pass without a pass followed
    target: tuple[float, float] | None
    one_touch: bool
    speed_asked_m_s: float  # over the ground, as the strategy asked it (NaN: no armed command reported)
    kicker_m_s: float = math.nan  # the kicker's speed, relative to the robot (the simulator's kick)
    speed_m_s: float = math.nan  # over the ground as it left the kicker, measured on the first frame after the kick
    off_line_rad: float = math.nan  # the ball's direction off the line to the target
    ball_model_s: float | None = None  # the ball at the target, as the model predicted it from the kick
    opponent_s: float | None = None  # the closest opponent's interception, as predicted from the kick
    opponent: int | None = None
    ball_s: float | None = None  # the ball at the target (its way along the pass line reaches it)
    miss_m: float | None = None  # ... that far across the line from it
    receiver_s: float | None = None  # the receiver within at_target_m of the target
    dropped_s: float | None = None  # the strategy gave the pass up (its receiver taken off it)
    touch_speed_m_s: float | None = None  # the ball's speed relative to the first team-mate to touch it
    end: PassEnd | None = None
    end_s: float | None = None
    by: int | None = None  # who touched it first (ours: received or too fast; theirs: intercepted)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["end"] = None if self.end is None else self.end.value
        d["target"] = None if self.target is None else list(self.target)
        return {k: (round(v, 4) if isinstance(v, float) and math.isfinite(v) else v) for k, v in d.items()
                if not (isinstance(v, float) and not math.isfinite(v))}


class PassRecorder:
    """One team's passes, from its reports, the simulator's events and true state and the referee."""

    def __init__(self, team: Team, pitch: Field, robot: RobotShape, ball_radius_m: float, model: BallModel,
                 params: PassRecordParams, timeout_s: float) -> None:
        self.team, self.field, self.p, self.model = team, pitch, params, model
        self.timeout_s = timeout_s
        self.reach_m = robot.radius_m + ball_radius_m + params.touch_m
        self.contact_m = robot.front_distance_m + ball_radius_m  # the ball on the face of a robot at the target
        self.ball_radius_m = ball_radius_m  # the ball's centre this high: on the ground
        self.limits, self.latency_s = robot_limits(robot), robot.command_latency_s
        self.records: list[PassRecord] = []
        self._open: PassRecord | None = None
        self._measured = False
        self._passer_left = False
        self._touch_t: float | None = None
        self._kick_xy = (0.0, 0.0)  # the ball on the first frame after the kick
        self._start_command = RefereeCommand.NORMAL
        self._passing: PassReport | None = None
        self._asked: dict[int, float] = {}  # robot id -> the kick speed its last armed command asked (m/s)
        self._game = GameState(0.0)

    @classmethod
    def of(cls, team: Team, settings: Settings) -> PassRecorder:
        """``team``'s passes judged with its strategy's settings and the league's robots and ball."""
        s, league = settings.strategy, settings.field
        return cls(team, settings.field_geometry(), league.robot, league.ball.radius_m, s.skills.ball_model,
                   s.pass_record, s.pass_timeout_s)

    def report(self, report: TeamReport) -> None:
        self._passing = report.passing
        for r in report.robots:
            if r.command is not None and r.command.kick_speed > 0.0:
                self._asked[r.id] = r.command.kick_speed
        rec = self._open
        if rec is not None and self._measured and rec.dropped_s is None and rec.receiver is not None:
            ps = report.passing
            if ps is None or ps.receiver != rec.receiver:
                rec.dropped_s = report.t - rec.t_kick

    def referee(self, game: GameState) -> None:
        self._game = game

    def kick(self, e: Kick, action: KickPurpose | None, truth: GroundTruth | None) -> None:
        """One of our kicks; ``action``: what the strategy meant it for."""
        rec = self._open
        if rec is not None and e.id != rec.passer and truth is not None:
            self._touched(truth, e.id, kicked=True)  # a team-mate kicks the ball on: received
        elif rec is not None and e.id == rec.passer and self._measured:
            self._close(self._back(rec), e.t, e.id)  # the passer plays its own pass again
        if action is not KickPurpose.PASS or self._open is not None:
            return
        ps = self._passing if self._passing is not None and self._passing.passer == e.id else None
        self._open = PassRecord(e.t, e.id, ps.receiver if ps else None, ps.target if ps else None,
                                bool(ps and ps.shoot_at is not None), self._asked.get(e.id, math.nan),
                                e.speed_m_s)
        self._measured = self._passer_left = False
        self._touch_t = None
        self._start_command = self._game.command

    def truth(self, gt: GroundTruth) -> None:
        """A true frame: measure the kick on the first after it, then follow the pass to its end."""
        rec = self._open
        if rec is None:
            return
        if not self._measured:
            self._measure(rec, gt)
            self._measured = True
            return
        t = gt.t - rec.t_kick
        ball = gt.ball
        own = {r.id: r for r in gt.robots if r.team == self.team}
        along, across = self._along(rec, ball.x, ball.y)
        if rec.ball_s is None and rec.target is not None and along >= -self.p.touch_m:
            rec.ball_s, rec.miss_m = t, abs(across)
        if self._touch_t is not None:  # a team-mate touched it: held (or kicked on) at the end of control_s?
            if gt.t - self._touch_t >= self.p.control_s:
                holder = own.get(rec.by) if rec.by is not None else None
                held = holder is not None and math.hypot(holder.x - ball.x, holder.y - ball.y) < self.p.hold_m
                self._close(PassEnd.RECEIVED if held else PassEnd.TOO_FAST, gt.t, rec.by)
            return
        if not self._passer_left:
            passer = own.get(rec.passer)
            self._passer_left = passer is None or math.hypot(passer.x - ball.x, passer.y - ball.y) > self.reach_m
        # the receiver at its target
        if rec.receiver is not None and rec.target is not None and rec.receiver_s is None:
            r = own.get(rec.receiver)
            if r is not None and math.hypot(r.x - rec.target[0], r.y - rec.target[1]) < self.p.at_target_m:
                rec.receiver_s = t
        # the first touch
        toucher = None
        for r in gt.robots:
            if r.team == self.team and r.id == rec.passer and not self._passer_left:
                continue
            if math.hypot(r.x - ball.x, r.y - ball.y) < self.reach_m:
                toucher = r
                break
        if toucher is not None:
            if toucher.team == self.team and toucher.id == rec.passer:
                self._close(self._back(rec), gt.t, toucher.id)
            elif toucher.team != self.team:
                self._close(PassEnd.INTERCEPTED, gt.t, toucher.id)
            else:
                self._touched(gt, toucher.id, kicked=False)
            return
        # the ball along the pass line
        speed = math.hypot(ball.vx, ball.vy)
        g = self._game.command
        stopped = g in (RefereeCommand.HALT, RefereeCommand.STOP, RefereeCommand.TIMEOUT,
                        RefereeCommand.BALL_PLACEMENT, RefereeCommand.PENALTY) or (
            g.kick_restart and g != self._start_command)
        if abs(ball.x) > self.field.half_length or abs(ball.y) > self.field.half_width:
            self._close(PassEnd.OUT, gt.t, None)
        elif stopped:
            self._close(PassEnd.STOPPED, gt.t, None)
        elif rec.target is not None and along > self.p.past_m:
            self._close(self._unmet(rec), gt.t, None)
        elif speed < self.p.dead_m_s:
            short = rec.target is not None and rec.ball_s is None
            self._close(PassEnd.TOO_SLOW if short else self._unmet(rec), gt.t, None)
        elif t > self.timeout_s:
            self._close(PassEnd.TIMEOUT, gt.t, None)

    def _back(self, rec: PassRecord) -> PassEnd:
        """The passer met its own pass again, untouched by anyone else: short, or not met."""
        return PassEnd.TOO_SLOW if rec.target is not None and rec.ball_s is None else self._unmet(rec)

    def _unmet(self, rec: PassRecord) -> PassEnd:
        if rec.dropped_s is not None:
            return PassEnd.REASSIGNED
        return PassEnd.LATE if rec.receiver_s is None else PassEnd.MISSED

    def _along(self, rec: PassRecord, x: float, y: float) -> tuple[float, float]:
        """The ball's way along the pass line past the point it meets a receiver at the target (m),
        and across that line."""
        if rec.target is None:
            return -math.inf, 0.0
        tx, ty = rec.target
        dx, dy = tx - self._kick_xy[0], ty - self._kick_xy[1]
        d = max(math.hypot(dx, dy), 1e-9)
        ux, uy = dx / d, dy / d
        rx, ry = x - tx, y - ty
        return rx * ux + ry * uy + self.contact_m, -rx * uy + ry * ux

    def _measure(self, rec: PassRecord, gt: GroundTruth) -> None:
        b = gt.ball
        self._kick_xy = (b.x, b.y)
        speed = math.hypot(b.vx, b.vy)
        # the kick came between frames: a ball on the ground slid since (a chip flies undecelerated)
        on_ground = b.z <= self.ball_radius_m + _GROUND_M
        rec.speed_m_s = speed + (self.model.acc_slide_m_s2 * (gt.t - rec.t_kick) if on_ground else 0.0)
        opp = [r for r in gt.robots if r.team != self.team]
        if opp and speed > 0.0:
            xy = np.array([[r.x, r.y] for r in opp])
            vel = np.array([[r.vx, r.vy] for r in opp])
            ts, _ = interception_times(xy, vel, (b.x, b.y), (b.vx, b.vy), self.model, self.limits, self.latency_s,
                                       self.reach_m, self.p.horizon_s, self.p.step_s)
            k = int(np.argmin(ts))
            if math.isfinite(ts[k]):
                rec.opponent_s, rec.opponent = float(ts[k]) + (gt.t - rec.t_kick), opp[k].id
        if rec.target is None or speed <= 0.0:
            return
        dx, dy = rec.target[0] - b.x, rec.target[1] - b.y
        rec.off_line_rad = abs(math.remainder(math.atan2(b.vy, b.vx) - math.atan2(dy, dx), math.tau))
        run = math.hypot(dx, dy) - self.contact_m
        t_model = self.model.time_to(speed, max(run, 0.0))
        rec.ball_model_s = t_model + (gt.t - rec.t_kick) if math.isfinite(t_model) else None

    def _touched(self, gt: GroundTruth, rid: int, kicked: bool) -> None:
        rec = self._open
        assert rec is not None
        if self._touch_t is None:
            r = next((r for r in gt.robots if r.team == self.team and r.id == rid), None)
            if r is not None:
                rec.touch_speed_m_s = math.hypot(gt.ball.vx - r.vx, gt.ball.vy - r.vy)
            rec.by, self._touch_t = rid, gt.t
        if kicked:
            self._close(PassEnd.RECEIVED, gt.t, rid)

    def _close(self, end: PassEnd, t: float, by: int | None) -> None:
        rec = self._open
        assert rec is not None
        rec.end, rec.end_s = end, t - rec.t_kick
        if by is not None:
            rec.by = by
        self.records.append(rec)
        self._open = None

    def summary(self) -> dict[str, Any]:
        """The passes tried and completed, how many ended each way, and each pass's record."""
        ends = {e.value: sum(r.end is e for r in self.records) for e in PassEnd}
        return {"tried": len(self.records) + (self._open is not None),
                "completed": ends[PassEnd.RECEIVED.value],
                "ends": {k: v for k, v in ends.items() if v},
                "list": [r.to_dict() for r in self.records]}  # fmt: skip
