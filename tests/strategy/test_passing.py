"""The pass state machine: planned, kicked, over (received, died, lost receiver, timed out)."""

from __future__ import annotations

import math

import pytest

from cmdragons.messages import BallState, RobotState
from strategy.passing import PassPlay, PassPlayParams
from strategy.skills import SkillParams

P = PassPlayParams()
POINT = (2.0, 0.0)


def _own(receiver_at: tuple[float, float] = POINT) -> dict[int, RobotState]:
    return {1: RobotState("blue", 1, 0.0, 0.0, 0.0), 2: RobotState("blue", 2, *receiver_at, 0.0)}


def _planned(t: float = 0.0) -> PassPlay:
    play = PassPlay(P)
    play.plan(t, passer=1, receiver=2, point=POINT, shoot_at=None)
    return play


def test_a_pass_stays_planned_while_the_ball_lies() -> None:
    play = _planned()
    ps = play.follow(0.5, _own(), BallState(0.1, 0.0, 0.0, 0.0))
    assert ps is not None and not ps.kicked and ps.t_start == 0.0
    assert play.planned_by(1, _own()) is ps
    assert play.planned_by(2, _own()) is None  # only its passer kicks it
    assert play.planned_by(1, {1: _own()[1]}) is None  # nor once its receiver is gone


@pytest.mark.parametrize(("vx", "vy", "kicked"), [
    (3.0, 0.0, True),  # straight at the point
    (3.0, 1.0, True),  # cos 0.95 > 0.8
    (3.0, 3.0, False),  # cos 0.71: not toward the point
    (0.4, 0.0, False),  # too slow to be a pass
    (-3.0, 0.0, False),  # away from it
])
def test_kicked_once_the_ball_runs_toward_the_point(vx: float, vy: float, kicked: bool) -> None:
    play = _planned()
    ps = play.follow(1.0, _own(), BallState(0.1, 0.0, vx, vy))
    assert ps is not None and ps.kicked is kicked
    assert ps.t_start == (1.0 if kicked else 0.0)  # the timeout runs from the kick


def test_over_when_received_or_died() -> None:
    play = _planned()
    play.follow(0.1, _own(), BallState(0.1, 0.0, 3.0, 0.0))
    # the ball goes past the point, off its way, but far from the receiver: still under way
    ps = play.follow(0.5, _own(receiver_at=(2.0, 1.0)), BallState(2.5, 0.0, 2.0, 0.0))
    assert ps is not None and ps.kicked
    # at the receiver, and no longer heading for the point: received
    assert play.follow(0.6, _own(), BallState(2.1, 0.0, 1.0, 0.0)) is None
    assert play.current is None
    died = _planned()
    died.follow(0.1, _own(), BallState(0.1, 0.0, 3.0, 0.0))
    assert died.follow(0.9, _own(receiver_at=(3.0, 2.0)), BallState(1.0, 0.0, 0.1, 0.0)) is None


def test_a_ball_passing_by_the_point_is_not_received_while_it_still_closes_on_the_receiver() -> None:
    """A one-touch pass runs past the point a few centimetres off it (no longer heading for it)
    toward the receiver standing just beyond: not yet received (its kick stays armed) until it meets
    the receiver and leaves it. A pass to be trapped is received there as before."""
    trap = _planned()
    trap.follow(0.1, _own(), BallState(0.1, 0.0, 3.0, 0.0))
    assert trap.follow(0.7, _own(receiver_at=(2.1, 0.0)), BallState(1.95, 0.06, 1.0, -0.2)) is None
    play = PassPlay(P)
    play.plan(0.0, passer=1, receiver=2, point=POINT, shoot_at=(4.5, 0.0))
    play.follow(0.1, _own(), BallState(0.1, 0.0, 3.0, 0.0))
    receiver = _own(receiver_at=(2.1, 0.0))
    ball = BallState(1.95, 0.06, 1.0, -0.2)  # 8 cm from the point, 16 cm from the receiver, closing at 1 m/s
    to_point = (POINT[0] - ball.x, POINT[1] - ball.y)
    cos = (ball.vx * to_point[0] + ball.vy * to_point[1]) / (math.hypot(ball.vx, ball.vy) * math.hypot(*to_point))
    assert cos < P.kicked_cos  # off its way to the point
    ps = play.follow(0.7, receiver, ball)
    assert ps is not None and ps.kicked
    # kicked on by the receiver: away from it, received
    assert play.follow(0.75, receiver, BallState(2.0, 0.03, -1.0, 2.0)) is None


def test_over_on_timeout_and_without_its_receiver() -> None:
    play = _planned()
    assert play.follow(P.timeout_s - 0.01, _own(), BallState(0.1, 0.0, 0.0, 0.0)) is not None
    assert play.follow(P.timeout_s + 0.01, _own(), BallState(0.1, 0.0, 0.0, 0.0)) is None
    lost = _planned()
    assert lost.follow(0.1, {1: _own()[1]}, BallState(0.1, 0.0, 0.0, 0.0)) is None


def test_planning_again_keeps_the_pass_to_the_same_receiver() -> None:
    play = _planned(t=0.0)
    first = play.current
    play.plan(0.5, passer=1, receiver=2, point=(2.5, 0.3), shoot_at=(4.5, 0.0))
    assert play.current is first  # its receiver already waits at the first point
    play.plan(0.6, passer=1, receiver=3, point=(1.0, 1.0), shoot_at=None)
    assert play.current is not None and (play.current.receiver, play.current.point) == (3, (1.0, 1.0))
    assert play.current.t_start == 0.6
    play.cancel()
    assert play.current is None


MODEL = SkillParams().ball_model


@pytest.mark.parametrize(("speed", "kicked"), [
    (2.0, True),  # rolls some 7.7 m: reaches the point 1.9 m off
    (0.8, False),  # rolls 1.2 m: stops short of the point (more than received_m)
])
def test_a_ball_that_stops_short_of_the_point_is_not_the_pass(speed: float, kicked: bool) -> None:
    play = PassPlay(P, MODEL)
    play.plan(0.0, passer=1, receiver=2, point=POINT, shoot_at=None)
    ps = play.follow(0.1, _own(), BallState(0.1, 0.0, speed, 0.0))
    assert ps is not None and ps.kicked is kicked
    rolled = speed**2 / (2 * MODEL.acc_roll_m_s2)
    assert (rolled >= POINT[0] - 0.1 - P.received_m) is kicked  # the rolling ball's reach decides


def test_a_kicked_pass_that_slows_short_of_the_point_is_over() -> None:
    play = PassPlay(P, MODEL)
    play.plan(0.0, passer=1, receiver=2, point=POINT, shoot_at=None)
    assert play.follow(0.1, _own(), BallState(0.1, 0.0, 2.0, 0.0)).kicked  # type: ignore[union-attr]
    # later, at 0.7 m/s 1.4 m from the point it rolls 0.94 m more: short of it, the attacker takes over
    assert play.follow(1.0, _own(), BallState(0.6, 0.0, 0.7, 0.0)) is None
    assert play.current is None
