"""The pass state machine: a pass from the attacker's decision to its reception.

A pass is planned when the attacker decides it (passer, receiver, the point the receiver waits
at); it is kicked once the ball runs toward that point; it is over when the receiver has the ball,
the ball dies, the receiver is gone, or ``timeout_s`` passes (from the decision, and again from
the kick). Field frame, metres, seconds.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

from cmdragons.config import Validated, setting
from cmdragons.messages import BallState, RobotState
from strategy.ballmodel import BallModel

__all__ = ["Pass", "PassPlay", "PassPlayParams", "PassRecordParams"]


@dataclass(frozen=True)
class PassPlayParams(Validated):
    timeout_s: float = setting(3.0, lo=0.1, hi=30.0)  # a pass not received by then is over
    kicked_speed_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # a ball faster than this toward the point: kicked ...
    kicked_cos: float = setting(0.8, lo=-1.0, hi=1.0)  # ... heading at least this straight at it (cosine)
    dead_speed_m_s: float = setting(0.2, lo=0.0, hi=10.0)  # a kicked ball slower than this has died: over
    received_m: float = setting(0.3, lo=0.0, hi=3.0)  # the ball this near the receiver, off its way: received ...
    arriving_m_s: float = setting(0.2, lo=0.0, hi=10.0)  # ... unless one-touch, still closing on it this fast


@dataclass(frozen=True)
class PassRecordParams(Validated):
    """How a pass is judged after the fact (the match statistics' pass record, from the true state)."""

    touch_m: float = setting(0.01, lo=0.0, hi=0.5)  # a robot's body this near the ball's touches it
    control_s: float = setting(0.3, lo=0.01, hi=5.0)  # after a team-mate's touch: kicked on or held within this ...
    hold_m: float = setting(0.15, lo=0.05, hi=1.0)  # ... held: the ball's centre this near the robot's
    at_target_m: float = setting(0.15, lo=0.01, hi=2.0)  # the receiver's centre this near the target: there
    past_m: float = setting(0.5, lo=0.0, hi=5.0)  # the ball this far past the target, untouched: missed
    dead_m_s: float = setting(0.2, lo=0.0, hi=5.0)  # the ball slower than this, untouched: over
    horizon_s: float = setting(4.0, lo=0.1, hi=30.0)  # the opponents' interception predicted this far ahead ...
    step_s: float = setting(0.02, lo=0.001, hi=1.0)  # ... in steps of this


@dataclass(frozen=True)
class Pass:
    """A pass decided (``kicked`` False) or under way."""

    passer: int
    receiver: int
    point: tuple[float, float]  # where the receiver waits
    t_start: float  # when it was decided, then when it was kicked
    kicked: bool = False
    shoot_at: tuple[float, float] | None = None  # the receiver's one-touch aim; None: trap the ball


class PassPlay:
    """The team's one pass, followed from frame to frame; with a ball ``model``, a ball that cannot
    reach the point (rolling from its speed now, it stops more than ``received_m`` short) is not the
    pass, or no longer: the pass is over and the new attacker takes over (such a ball, played along
    the lane by a contest's kick, kept its receiver waiting and the team without an attacker until
    the ball died)."""

    def __init__(self, params: PassPlayParams, model: BallModel | None = None) -> None:
        self.p = params
        self.model = model
        self.current: Pass | None = None

    def plan(self, t: float, passer: int, receiver: int, point: tuple[float, float],
             shoot_at: tuple[float, float] | None) -> None:
        """The passer decides a pass; the one it decided before to the same receiver is kept as it was."""
        ps = self.current
        if ps is None or (ps.receiver, ps.passer) != (receiver, passer):
            self.current = Pass(passer, receiver, point, t, shoot_at=shoot_at)

    def cancel(self) -> None:
        self.current = None

    def planned_by(self, passer: int, own: Mapping[int, RobotState]) -> Pass | None:
        """The pass ``passer`` decided and has not kicked yet, while its receiver is on the field."""
        ps = self.current
        if ps is not None and not ps.kicked and ps.passer == passer and ps.receiver in own:
            return ps
        return None

    def follow(self, t: float, own: Mapping[int, RobotState], ball: BallState) -> Pass | None:
        """The pass this frame: kicked once the ball runs toward the point; None once it is over."""
        ps = self.current
        if ps is None:
            return None
        p = self.p
        if ps.receiver not in own or t - ps.t_start > p.timeout_s:
            self.current = None
            return None
        speed = math.hypot(ball.vx, ball.vy)
        to_point = (ps.point[0] - ball.x, ps.point[1] - ball.y)
        along = ball.vx * to_point[0] + ball.vy * to_point[1]
        heading_there = speed > p.kicked_speed_m_s and along > p.kicked_cos * speed * math.hypot(*to_point)
        if heading_there and self.model is not None:
            reach = speed**2 / (2.0 * max(self.model.acc_roll_m_s2, 1e-9))  # rolling from now: the farthest
            if reach < math.hypot(*to_point) - p.received_m:
                if ps.kicked:
                    self.current = None  # it stops short: over
                    return None
                heading_there = False
        if not ps.kicked and heading_there:
            ps = self.current = dataclasses.replace(ps, kicked=True, t_start=t)  # the timeout runs from the kick
        elif ps.kicked and (speed < p.dead_speed_m_s or not heading_there):
            receiver = own[ps.receiver]
            gap_x, gap_y = receiver.x - ball.x, receiver.y - ball.y
            gap = math.hypot(gap_x, gap_y)
            # a one-touch ball that passes by the point runs off its way before it reaches the receiver
            # there: while it still closes on the receiver the pass (its kick armed) goes on
            closing = ((ball.vx - receiver.vx) * gap_x + (ball.vy - receiver.vy) * gap_y) / max(gap, 1e-9)
            arriving = ps.shoot_at is not None and closing > p.arriving_m_s
            if (gap < p.received_m and not arriving) or speed < p.dead_speed_m_s:
                self.current = None  # received (or died): the new attacker takes over
                return None
        return ps
