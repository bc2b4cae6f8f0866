"""The pass record against scripted passes in the simulator: its times against the true frames
(within a frame), the ball model's prediction against the simulated ball, and how each pass ended."""

from __future__ import annotations

import math

import pytest

from cmdragons.control.motion import relative_kick
from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import GroundTruth, Kick, KickPurpose, PassReport, RobotCommand, RobotReport, TeamReport
from cmdragons.runtime.pass_record import PassEnd, PassRecord, PassRecorder
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World
from strategy.passing import PassRecordParams
from strategy.skills import SkillParams

LEAGUE = LeagueParams()
FRAME_S = 1.0 / 60.0
TOUCH_M = PassRecordParams().touch_m  # the ball this near the receiver's face: there
FRONT = LEAGUE.robot.front_distance_m + LEAGUE.ball.radius_m  # robot centre to the ball on its kicker face
TARGET = (2.0, 0.0)


def scripted_pass(receiver_at: tuple[float, float], opponent_at: tuple[float, float],
                  kick_m_s: float, drive_m_s: float = 0.0) -> tuple[PassRecord, list[GroundTruth]]:
    """Blue 0 at the centre kicks along +x at ``kick_m_s`` over the ground toward ``TARGET`` (driving
    onto the ball at ``drive_m_s``, the kick sent relative to it), blue 1 waiting at ``receiver_at``
    facing it with its dribbler on, yellow 0 standing at ``opponent_at``; the record of that pass and
    the true frames."""
    w = World(LEAGUE, PhysicsParams(), RobotParams(), BallParams(), KickerParams(), DribblerParams(),
              robots_per_team={"blue": 2, "yellow": 1})
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_robot("blue", 1, *receiver_at, math.pi)
    w.place_robot("yellow", 0, *opponent_at, math.pi)
    w.place_ball(FRONT + 0.003 + 0.3 * drive_m_s, 0.0)
    recorder = PassRecorder("blue", Field(LEAGUE), LEAGUE.robot, LEAGUE.ball.radius_m, SkillParams().ball_model,
                            PassRecordParams(), timeout_s=3.0)
    frames: list[GroundTruth] = []
    kicked = False
    for n in range(300):
        gt = w.ground_truth()
        frames.append(gt)
        recorder.truth(gt)
        if recorder.records:
            break
        armed = n < 5 or (drive_m_s > 0.0 and not kicked)
        kick = RobotCommand("blue", 0, vx=drive_m_s if armed else 0.0, kick_speed=kick_m_s if armed else 0.0)
        recorder.report(TeamReport("blue", n, gt.t, (RobotReport(0, "direct", (TARGET[0], 0.0, 0.0), command=kick),),
                                   actions={0: KickPurpose.PASS}, passing=PassReport(0, 1, TARGET, kicked=n > 0)))
        kicker = next(r for r in gt.robots if r.team == "blue" and r.id == 0)
        commands = [relative_kick(kick, 0.0, (kicker.vx, kicker.vy), LEAGUE.robot),
                    RobotCommand("blue", 1, dribbler=1.0)]
        for e in w.step_frame(commands):
            if isinstance(e, Kick):
                kicked = True
                recorder.kick(e, KickPurpose.PASS, gt)
    assert len(recorder.records) == 1
    return recorder.records[0], frames


def test_a_received_pass_is_timed_within_a_frame_of_the_true_frames() -> None:
    rec, frames = scripted_pass(receiver_at=TARGET, opponent_at=(0.0, -2.5), kick_m_s=2.5)
    assert rec.end is PassEnd.RECEIVED and rec.by == 1
    assert rec.receiver == 1 and rec.target == TARGET and not rec.one_touch
    assert rec.speed_asked_m_s == 2.5 and rec.kicker_m_s == 2.5  # standing still: the kicker fires as asked
    assert rec.speed_m_s == pytest.approx(2.5, abs=0.1)  # measured on the frame after the kick (sliding)
    assert rec.off_line_rad < 0.01
    # the ball at the target: the first true frame it touches the face of a robot standing there
    arrival = next(gt.t for gt in frames if gt.t > rec.t_kick and gt.ball.x >= TARGET[0] - FRONT - TOUCH_M) - rec.t_kick
    assert rec.ball_s is not None and abs(rec.ball_s - arrival) <= FRAME_S + 1e-9
    # the two-phase model predicted it from the frame after the kick within two frames (the kick came
    # between frames, the slide began at the kick speed, not the speed measured a frame on)
    assert rec.ball_model_s is not None and abs(rec.ball_model_s - arrival) <= 2 * FRAME_S + 1e-9
    assert rec.receiver_s is not None and rec.receiver_s <= FRAME_S + 1e-9  # it waited there
    assert rec.opponent_s is not None and rec.opponent_s > arrival  # the opponent far off: too late


def test_a_pass_kicked_driving_onto_the_ball_records_the_speed_asked_over_the_ground() -> None:
    """Driving onto the ball at 0.5 m/s, the kicker fires 0.5 m/s slower than the ball's speed over the
    ground asked: the record keeps both, and the ball leaves at the speed asked (measured on the frame
    after the kick, which came between frames, the slide since taken back: within 5 mm/s)."""
    rec, frames = scripted_pass(receiver_at=TARGET, opponent_at=(0.0, -2.5), kick_m_s=2.5, drive_m_s=0.5)
    assert rec.speed_asked_m_s == 2.5
    assert rec.kicker_m_s == pytest.approx(2.0)
    after = next(gt for gt in frames if gt.t > rec.t_kick)
    assert after.t - rec.t_kick > 0.002  # the kick between two frames: the ball slid a while before it
    assert rec.speed_m_s == pytest.approx(rec.speed_asked_m_s, abs=0.005)


def test_a_pass_the_receiver_is_not_at_ends_late() -> None:
    rec, _ = scripted_pass(receiver_at=(2.0, 1.5), opponent_at=(0.0, -2.5), kick_m_s=2.5)
    assert rec.end is PassEnd.LATE and rec.receiver_s is None and rec.ball_s is not None


def test_a_pass_through_an_opponent_ends_intercepted_and_was_predicted() -> None:
    rec, frames = scripted_pass(receiver_at=(2.1, 0.0), opponent_at=(1.0, 0.0), kick_m_s=2.5)
    assert rec.end is PassEnd.INTERCEPTED and rec.by == 0
    assert rec.opponent_s is not None and rec.end_s is not None and rec.opponent_s <= rec.end_s + FRAME_S


def test_a_pass_too_soft_dies_short() -> None:
    rec, _ = scripted_pass(receiver_at=(2.1, 0.0), opponent_at=(0.0, -2.5), kick_m_s=0.8)
    assert rec.end is PassEnd.TOO_SLOW and rec.ball_s is None
