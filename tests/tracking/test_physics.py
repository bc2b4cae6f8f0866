"""Physics facts learnt by the tracker against what our simulator was configured to do: a rolling
ball's deceleration, a robot's braking and the kicker's gain, seen through seeded noisy detections
of the simulator's true state."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cmdragons.config import override_derived
from cmdragons.geometry import LeagueParams
from cmdragons.messages import DetectionFrame, Fact, Kick, PhysicsFacts, RobotCommand
from cmdragons.tracking import Tracker, TrackerParams
from cmdragons.tracking.physics import fit_acceleration, launch_speed
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World
from tests.tracking.test_tracker import detect, params

SIGMA = 0.0005  # m: the tracker's configured vision noise


def rolled_balls(acc_roll_m_s2: float, seed: int = 1, balls: int = 12) -> Tracker:
    """Balls rolled across the empty field one after another (each 6 s), seen by the tracker."""
    w = World(LeagueParams(), PhysicsParams(), RobotParams(), BallParams(acc_roll_m_s2=acc_roll_m_s2), KickerParams(),
              DribblerParams(), robots_per_team={"blue": 0, "yellow": 0})
    tracker = Tracker(params(sigma=SIGMA))
    rng = np.random.default_rng(seed)
    for _ in range(balls):
        heading, speed = rng.uniform(-0.4, 0.4), rng.uniform(2.5, 4.0)
        w.place_ball(-3.5, rng.uniform(-1.5, 1.5), vx=speed * math.cos(heading), vy=speed * math.sin(heading))
        for _ in range(60 * 6):
            tracker.step([detect(w.snapshot(), rng, sigma=SIGMA)])
            w.step_frame()
    tracker.finish()
    return tracker


def scripted_stops(brake_m_s2: float, seed: int = 1, stops: int = 25) -> Tracker:
    """A robot driven at 2 m/s for 1.5 s and told to stop, to and fro, seen by the tracker, which
    hears its commands."""
    latency = 0.03
    w = World(LeagueParams(), PhysicsParams(), RobotParams(max_brake_m_s2=brake_m_s2, command_latency_s=latency),
              BallParams(), KickerParams(), DribblerParams(), robots_per_team={"blue": 1, "yellow": 0})
    w.place_robot("blue", 0, -3.0, 0.0, 0.0)
    w.place_ball(0.0, 2.5)
    tracker = Tracker(params(latency=latency, sigma=SIGMA))
    rng = np.random.default_rng(seed)
    for k in range(stops):
        for f in range(150):
            snap = w.snapshot()
            tracker.step([detect(snap, rng, sigma=SIGMA)])
            command = RobotCommand("blue", 0, (2.0 if k % 2 == 0 else -2.0) if f < 90 else 0.0)
            tracker.command_sent([command], snap.t)
            w.step_frame([command])
    tracker.finish()
    return tracker


def scripted_kicks(gain: float, seed: int = 1, kicks: int = 12, seconds: float = 4.0,
                   acc_roll_m_s2: float | None = None) -> Tracker:
    """A robot at rest kicks the ball at 3 m/s across the field, again and again (each ``seconds``),
    with a kicker whose ball leaves at ``gain`` of the speed asked; the tracker hears the commands."""
    latency = 0.03
    league = LeagueParams()
    ball = BallParams() if acc_roll_m_s2 is None else BallParams(acc_roll_m_s2=acc_roll_m_s2)
    w = World(league, PhysicsParams(), RobotParams(command_latency_s=latency), ball, KickerParams(gain=gain),
              DribblerParams(), robots_per_team={"blue": 1, "yellow": 0})
    tracker = Tracker(params(latency=latency, sigma=SIGMA))
    rng = np.random.default_rng(seed)
    front = league.robot.front_distance_m + league.ball.radius_m + 0.002
    for _ in range(kicks):
        y = rng.uniform(-1.5, 1.5)
        w.place_robot("blue", 0, -4.0, y, 0.0)
        w.place_ball(-4.0 + front, y)
        for f in range(round(60 * seconds)):
            snap = w.snapshot()
            tracker.step([detect(snap, rng, sigma=SIGMA)])
            command = RobotCommand("blue", 0, kick_speed=3.0 if f < 10 else 0.0)
            tracker.command_sent([command], snap.t)
            w.step_frame([command])
    tracker.finish()
    return tracker


@pytest.mark.parametrize("gain", [1.0, 0.75])  # our simulator's kicker; one like grSim's (about 0.8)
def test_the_kickers_gain_is_learnt_from_the_balls_our_kicks_roll(gain: float) -> None:
    tracker = scripted_kicks(gain)
    est = tracker.physics.estimate(Fact.KICK_GAIN)
    assert est is not None and est.confident and est.samples >= 10
    assert est.value_m_s2 == pytest.approx(gain, rel=0.05)
    assert est.used == (gain != 1.0)


def test_short_passes_in_a_world_like_grsims_teach_the_rolling_deceleration_and_the_kick_together() -> None:
    """Kicks taken away after a second each (a pass received): too short for a ball that ran free
    ``after_touch_s`` and then a rolling window, but the model has each rolling from its slide's end."""
    tracker = scripted_kicks(0.75, kicks=14, seconds=1.0, acc_roll_m_s2=0.70)
    roll, gain = tracker.physics.estimate(Fact.BALL_ROLL), tracker.physics.estimate(Fact.KICK_GAIN)
    assert roll is not None and roll.confident and roll.used and roll.value_m_s2 == pytest.approx(0.70, rel=0.10)
    assert gain is not None and gain.confident and gain.used and gain.value_m_s2 == pytest.approx(0.75, rel=0.05)
    # one window a kick: the gain is confident after kick_min_samples kicks, the rolling deceleration not yet
    # (and one more: the very first ball is new to the tracker, not a kick it saw)
    early = scripted_kicks(0.75, kicks=TrackerParams().physics.kick_min_samples + 1, seconds=1.0, acc_roll_m_s2=0.70)
    gain = early.physics.estimate(Fact.KICK_GAIN)
    assert gain is not None and gain.used and gain.value_m_s2 == pytest.approx(0.75, rel=0.08)
    assert not early.physics.estimate(Fact.BALL_ROLL).confident  # type: ignore[union-attr]


@pytest.mark.parametrize("v0", [1.0, 2.5, 5.0])
@pytest.mark.parametrize("after_s", [0.05, 0.9, 1.6])
def test_the_launch_speed_back_through_the_two_phase_model(v0: float, after_s: float) -> None:
    slide, roll, fraction = 3.0, 0.7, 0.64
    t_roll = (1.0 - fraction) * v0 / slide
    speed = v0 - slide * after_s if after_s < t_roll else fraction * v0 - roll * (after_s - t_roll)
    if speed > 0.0:
        assert launch_speed(speed, roll, after_s, slide, fraction) == pytest.approx(v0, rel=1e-9)


@pytest.mark.parametrize("acc_roll", [0.26, 0.70])  # our simulator's configured value; grSim's
def test_rolling_deceleration_is_learnt_within_ten_percent(acc_roll: float) -> None:
    tracker = rolled_balls(acc_roll)
    est = tracker.physics.estimate(Fact.BALL_ROLL)
    assert est is not None and est.confident
    assert est.value_m_s2 == pytest.approx(acc_roll, rel=0.10)
    configured = LeagueParams().ball.acc_roll_m_s2
    assert est.configured_m_s2 == configured
    # used only where it differs from the configuration: our own simulator's ball changes nothing
    assert est.used == (acc_roll != configured)
    handed = tracker.handed.in_use().get(Fact.BALL_ROLL.source)  # the value the tracker's ball model took
    assert tracker.p.ball.acc_roll_m_s2 == (handed if est.used else configured)
    assert handed is None or handed == pytest.approx(acc_roll, rel=0.10)


@pytest.mark.parametrize("brake", [6.0, 4.0])  # configured; about grSim's
def test_robot_braking_is_learnt_from_scripted_stops(brake: float) -> None:
    tracker = scripted_stops(brake)
    est = tracker.physics.estimate(Fact.ROBOT_BRAKE)
    assert est is not None and est.confident
    assert est.value_m_s2 == pytest.approx(brake, rel=0.10)
    assert est.used == (brake != LeagueParams().robot.max_brake_m_s2)
    accel = tracker.physics.estimate(Fact.ROBOT_ACCEL)
    assert accel is not None and accel.value_m_s2 == pytest.approx(LeagueParams().robot.max_accel_m_s2, rel=0.10)


def test_nothing_measured_is_nothing_used() -> None:
    tracker = Tracker(TrackerParams())
    tracker.finish()
    assert tracker.physics.in_use() == {}
    assert all(e.samples == 0 and not e.used for e in tracker.physics.estimates)
    assert tracker.p == tracker.configured


def test_a_fact_not_allowed_to_be_learnt_is_measured_but_not_used() -> None:
    p = params(sigma=SIGMA)
    tracker = Tracker(dataclasses.replace(p, physics=dataclasses.replace(p.physics, learn=("robot_brake",))))
    tracker.estimator.samples[Fact.BALL_ROLL].extend([0.7] * 40)  # type: ignore[union-attr]
    facts = tracker.estimator.facts(0.0)  # type: ignore[union-attr]
    roll = facts.estimate(Fact.BALL_ROLL)
    assert roll is not None and roll.confident and not roll.used


@pytest.mark.parametrize("accel", [(0.0, 0.0), (-0.7, 0.2), (6.0, -3.0)])
def test_fit_acceleration_of_a_parabola(accel: tuple[float, float]) -> None:
    t = np.arange(30) / 60.0 + 12.0
    v0, a = np.array([2.0, -1.0]), np.array(accel)
    xy = np.array([1.0, 0.5]) + np.outer(t - t[0], v0) + 0.5 * np.outer((t - t[0]) ** 2, a)
    got_a, got_v0, got_v1, rms = fit_acceleration(t, xy)
    assert got_a == pytest.approx(a, abs=1e-6)
    assert got_v0 == pytest.approx(v0, abs=1e-6)
    assert got_v1 == pytest.approx(v0 + a * (t[-1] - t[0]), abs=1e-6)
    assert rms < 1e-9


def test_facts_round_trip_and_the_keys_they_replace() -> None:
    tracker = scripted_stops(4.0, stops=10)
    facts = tracker.physics
    assert PhysicsFacts.from_dict(facts.to_dict()) == facts
    used = facts.in_use()
    assert set(used) <= {f.source for f in Fact}
    # the one object a consumer overrides its configured facts with: here the tracker's robot model
    tuned = override_derived(TrackerParams(), {Fact.ROBOT_ACCEL.source: 1.5})
    assert tuned.robot.max_accel_m_s2 == 1.5 and tuned.ball == TrackerParams().ball


def test_a_used_value_is_handed_on_again_only_when_it_moved_enough() -> None:
    tracker = Tracker(params(sigma=SIGMA))
    samples = tracker.estimator.samples[Fact.ROBOT_BRAKE]  # type: ignore[union-attr]
    change = tracker.p.physics.retune_change

    def at(t: float, brake: float) -> PhysicsFacts:
        samples.clear()
        samples.extend([brake] * 40)
        tracker.step([DetectionFrame(0, int(t), t, t)])
        return tracker.handed

    first = at(0.0, 4.0)
    assert first.in_use() == {Fact.ROBOT_BRAKE.source: 4.0} and tracker.p.robot == tracker.configured.robot
    assert at(2.0, 4.0 * (1 + 0.5 * change)) is first  # a small drift: the models keep what they took
    moved = at(4.0, 4.0 * (1 + 2 * change))
    assert moved is not first and moved.in_use()[Fact.ROBOT_BRAKE.source] == pytest.approx(4.0 * (1 + 2 * change))
    assert at(6.0, 6.0).in_use() == {}  # back at the configured value: nothing in use


def scripted_one_touch(retention: float, seed: int = 1, kicks: int = 8) -> Tracker:
    """A ball rolled at 2.5 m/s onto the front of a robot at rest facing along +x from 45° to its
    left (or right, in turn), the robot's kicker armed: a one-touch kick at 3 m/s whose kicker keeps
    ``retention`` of the ball's velocity across the heading. The tracker hears the commands."""
    latency = 0.03
    league = LeagueParams()
    w = World(league, PhysicsParams(), RobotParams(command_latency_s=latency), BallParams(),
              KickerParams(tangential_retention=retention), DribblerParams(), robots_per_team={"blue": 1, "yellow": 0})
    tracker = Tracker(params(latency=latency, sigma=SIGMA))
    rng = np.random.default_rng(seed)
    front = league.robot.front_distance_m + league.ball.radius_m
    for k in range(kicks):
        side = 1.0 if k % 2 == 0 else -1.0
        y = rng.uniform(-1.0, 1.0)
        w.place_robot("blue", 0, -2.0, y, 0.0)
        w.place_ball(-2.0 + front + 0.9, y + side * 0.9, vx=-2.5 / math.sqrt(2.0), vy=-side * 2.5 / math.sqrt(2.0))
        kicked = False
        for _ in range(60 * 2):
            snap = w.snapshot()
            tracker.step([detect(snap, rng, sigma=SIGMA)])
            command = RobotCommand("blue", 0, kick_speed=0.0 if kicked else 3.0)
            tracker.command_sent([command], snap.t)
            events = w.step_frame([command])
            kicked = kicked or any(isinstance(e, Kick) for e in events)
        assert kicked
    tracker.finish()
    return tracker


@pytest.mark.parametrize("retention", [0.3, 1.0])  # our simulator's kicker; grSim's (its kick keeps all of it)
def test_the_kicks_retention_across_the_heading_is_learnt_from_one_touch_kicks(retention: float) -> None:
    tracker = scripted_one_touch(retention)
    est = tracker.physics.estimate(Fact.KICK_RETENTION)
    assert est is not None and est.confident and est.samples == 8  # each kick one sample
    assert est.value_m_s2 == pytest.approx(retention, abs=0.05)
    assert est.used == (retention != 0.3)

