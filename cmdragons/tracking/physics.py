"""Physics facts measured from what the team sees: the ball's deceleration and the robots' reach.

The configured ball model and robot limits (field.yaml ``ball`` and ``robot``) are what our own
simulator does; another simulator or a real field differs (grSim's ball rolls out at 0.70 m/s²,
its robots brake at about 4 m/s²). The tracker measures them from raw detections, field frame,
metres and seconds:

* the ball's rolling deceleration from free-rolling balls: detections of the tracked ball with no
  robot within ``clear_m`` since ``after_touch_s`` (the slide after a kick or touch is over), in
  consecutive windows of ``window_s`` (and the kick gain's windows below, which the model has
  rolling); each window's quadratic fit of position over time gives one deceleration (the
  acceleration against the direction of travel), kept when the fit is tight (no bounce) and the
  ball still rolls at its end;
* the ball's sliding deceleration likewise, from the first ``slide_window_s`` a kicked ball runs
  clear of the robots (shots: their slide lasts that long; slow passes mix in some rolling);
* the kicker's gain (the ball's launch speed over the kick asked) from a window of ``gain_window_s``
  once the model has a kick of ours rolling, the ball clear of the robots: the window's speed taken
  back to the kick through the two-phase model (configured slide, the fraction at which rolling
  starts, the rolling deceleration as measured so far),
  over the ball's speed the kick asked (the kicker's speed sent plus the robot's own along the
  ball's run, as a kick is relative to the robot). What a pass needs: the ball rolls on as the model
  of the kick asked says; a kicker that sends it slower by a share (grSim's kick leaves at about 0.8
  of the speed asked and slides off a fifth of it at once) is asked that much more;
* the kick's retention across the heading (the share of the ball's velocity across the kicker's
  heading, relative to the robot, that the kick keeps: strategy.onetouch's model, which aims a
  one-touch kick with it) from our kicks of a ball that came in across the heading faster than
  ``retention_min_across_m_s``: the ball's velocity across the heading as it left, from the slide
  window above (its run keeps its direction while it slows; its speed taken back to the kick at the
  sliding deceleration measured so far), less the robot's, over the incoming ball's across the
  heading relative to the robot as it came in (tracked clear of the robots, as a one-touch aim
  reckons with it). Our simulator's kicker keeps 0.3 of it; grSim's keeps all of it, and none when
  its dribbler caught the ball first.
  Judged in shares: confident after ``retention_min_samples`` kicks with the median's standard
  error within ``retention_max_error``, used when off the configured share by ``retention_use_margin``;
* each robot's reachable acceleration and braking from our own robots' detections while the
  command in force asks for a velocity change the robot cannot make at once (more than
  ``saturated_m_s`` from the velocity tracked) and no other robot is within ``robot_clear_m``: the
  robot then gives all it can, and the fitted acceleration's magnitude is its limit. Braking as our
  simulator's motors tell it: the change points against the motion and the commanded speed is lower.

Each fact is the median of its windows (robust to the odd push or bounce), its spread the
median absolute deviation scaled to a standard deviation; it is *confident* after ``min_samples``
windows with the median's standard error within ``max_relative_error`` of it, and *used* (handed to
planning, passing, the kick model and safety instead of the configured value) only when also
allowed by ``learn`` and off the configured value by more than ``use_margin``: where the
configuration is right, nothing changes.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, derived, setting
from cmdragons.messages import Fact, FactEstimate, PhysicsFacts

__all__ = ["OurKick", "PhysicsEstimator", "PhysicsFactsParams", "fit_acceleration"]

Array = NDArray[np.float64]


FactName = Literal["ball_roll", "ball_slide", "robot_accel", "robot_brake", "kick_gain", "kick_retention"]


@dataclass(frozen=True)
class PhysicsFactsParams(Validated):
    """configs/tracker.yaml ``physics``."""

    measure: bool = setting(True)  # measure at all
    # the facts whose measured value may replace the configured one
    learn: tuple[FactName, ...] = setting(("ball_roll", "robot_accel", "robot_brake", "kick_gain", "kick_retention"))
    min_samples: int = setting(10, lo=1, hi=100000)  # windows before a fact can be confident ...
    kick_min_samples: int = setting(5, lo=1, hi=100000)  # ... the kicker's gain and retention (one a kick: fewer)
    max_relative_error: float = setting(0.05, lo=0.0, hi=1.0)  # the median's standard error, of the median
    use_margin: float = setting(0.15, lo=0.0, hi=10.0)  # used only this share off the configured value
    retune_change: float = setting(0.05, lo=0.0, hi=10.0)  # a used value handed on again: moved by this share
    update_period_s: float = setting(1.0, lo=0.0, hi=600.0)  # the facts are summed up this often
    samples_kept: int = setting(400, lo=1, hi=1000000)  # the newest windows per fact
    max_gap_s: float = setting(0.1, lo=0.0, hi=10.0)  # detections further apart break a window
    # the ball
    clear_m: float = setting(0.2, lo=0.0, hi=5.0)  # no robot centre this near the ball: it runs free
    after_touch_s: float = setting(0.8, lo=0.0, hi=60.0)  # free this long since a touch or kick: rolling
    window_s: float = setting(0.4, lo=0.01, hi=10.0)  # a rolling window's length
    min_speed_m_s: float = setting(0.3, lo=0.0, hi=20.0)  # the ball at least this fast all through it
    max_residual_m: float = setting(0.01, lo=0.0, hi=1.0)  # the fit's RMS residual: more is a bounce
    slide_clear_m: float = setting(0.15, lo=0.0, hi=5.0)  # a kicked ball this far from the robots ...
    slide_within_s: float = setting(0.15, lo=0.0, hi=5.0)  # ... this soon after the kick starts a slide window
    slide_window_s: float = setting(0.1, lo=0.01, hi=5.0)
    kick_within_s: float = setting(0.2, lo=0.0, hi=5.0)  # a kick of ours: its kicker armed this recently ...
    kick_near_m: float = setting(0.3, lo=0.0, hi=5.0)  # ... on a robot centre this near the ball
    gain_after_s: float = setting(0.1, lo=0.0, hi=5.0)  # ... its gain window starts this after the model's slide
    gain_window_s: float = setting(0.4, lo=0.01, hi=5.0)
    retention_min_across_m_s: float = setting(0.5, lo=0.0, hi=20.0)  # the ball came in this fast across the heading
    retention_incoming_s: float = setting(0.3, lo=0.0, hi=5.0)  # ... clear of the robots this recently before the kick
    retention_min_samples: int = setting(3, lo=1, hi=100000)  # the retention: kicks before it can be confident ...
    retention_max_error: float = setting(0.05, lo=0.0, hi=1.0)  # ... its median's standard error at most (a share)
    retention_use_margin: float = setting(0.1, lo=0.0, hi=1.0)  # used only this far off the configured share
    # our robots
    robot_window_s: float = setting(0.15, lo=0.01, hi=10.0)
    saturated_m_s: float = setting(0.3, lo=0.0, hi=10.0)  # commanded velocity this far off the tracked one
    robot_max_residual_m: float = setting(0.01, lo=0.0, hi=1.0)
    robot_clear_m: float = setting(0.3, lo=0.0, hi=5.0)  # no other robot centre this near (it could push or block)
    # what is configured: field.yaml, configured once
    acc_roll_m_s2: float = derived("field.ball.acc_roll_m_s2", 0.26, lo=0.0, hi=10.0)
    acc_slide_m_s2: float = derived("field.ball.acc_slide_m_s2", 3.0, lo=0.0, hi=50.0)
    max_accel_m_s2: float = derived("field.robot.max_accel_m_s2", 3.0, lo=0.0, hi=50.0)
    max_brake_m_s2: float = derived("field.robot.max_brake_m_s2", 6.0, lo=0.0, hi=50.0)
    slide_to_roll_fraction: float = derived("field.ball.slide_to_roll_fraction", 0.64, lo=0.0, hi=1.0)
    kick_gain: float = derived("field.robot.kick_gain", 1.0, lo=0.1, hi=3.0)
    kick_retention: float = derived("field.robot.kick_retention", 0.3, lo=0.0, hi=1.5)

    def configured(self, fact: Fact) -> float:
        return {Fact.BALL_ROLL: self.acc_roll_m_s2, Fact.BALL_SLIDE: self.acc_slide_m_s2,
                Fact.ROBOT_ACCEL: self.max_accel_m_s2, Fact.ROBOT_BRAKE: self.max_brake_m_s2,
                Fact.KICK_GAIN: self.kick_gain, Fact.KICK_RETENTION: self.kick_retention}[fact]


@dataclass(frozen=True)
class OurKick:
    """A kick of ours just seen: the ball's speed over the ground it asked (m/s), the kicking
    robot's heading (rad) and velocity and the ball's velocity before the kick (m/s, field frame;
    None: not known, the ball new to the tracker)."""

    asked_m_s: float
    heading: float
    robot_v: tuple[float, float]
    ball_v: tuple[float, float] | None


class _Fit(NamedTuple):
    """A window's fit: its middle time (s), the ball's mean speed (m/s), deceleration (m/s²) and
    direction of travel (a unit vector, field frame) over it."""

    t_mid: float
    speed: float
    decel: float
    direction: tuple[float, float]


def _across_in(kick: OurKick) -> float:
    """The incoming ball's velocity relative to the kicking robot, across its heading (m/s; 0 unknown)."""
    if kick.ball_v is None:
        return 0.0
    return (-math.sin(kick.heading) * (kick.ball_v[0] - kick.robot_v[0])
            + math.cos(kick.heading) * (kick.ball_v[1] - kick.robot_v[1]))


def launch_speed(speed: float, decel: float, after_s: float, acc_slide: float, fraction: float) -> float:
    """The speed a ball rolling at ``speed`` (m/s, slowing by ``decel`` m/s²) ``after_s`` after its
    kick was kicked at, by the two-phase model: it slid at ``acc_slide`` from the launch speed v0 until
    it rolled at ``fraction`` v0, then rolled; so speed = fraction v0 - decel (after_s - (1 - fraction)
    v0 / acc_slide), solved for v0 (if that still puts the ball in its slide, the slide's own answer)."""
    v0 = (speed + decel * after_s) / (fraction + decel * (1.0 - fraction) / max(acc_slide, 1e-9))
    if after_s < (1.0 - fraction) * v0 / max(acc_slide, 1e-9):
        return speed + acc_slide * after_s
    return v0


def fit_acceleration(t: Array, xy: Array) -> tuple[Array, Array, Array, float]:
    """Least-squares quadratic fit of positions ``xy`` (n, 2) m over times ``t`` (n,) s: the
    acceleration (2,) m/s², the velocity at the first and at the last time (2,) m/s each, and the
    fit's RMS residual (m)."""
    t0 = t[0]
    tau = t - t0
    coef = np.polynomial.polynomial.polyfit(tau, xy, 2)  # (3, 2): constant, linear, quadratic terms
    fitted = coef[0] + np.outer(tau, coef[1]) + np.outer(tau * tau, coef[2])
    rms = float(np.sqrt(np.mean(np.sum((xy - fitted) ** 2, axis=1))))
    accel = 2.0 * coef[2]
    return accel, coef[1].copy(), coef[1] + accel * tau[-1], rms


class _Window:
    """Detections (t, x, y) gathered for one fit."""

    def __init__(self) -> None:
        self.t: list[float] = []
        self.xy: list[tuple[float, float]] = []

    def add(self, t: float, x: float, y: float, max_gap_s: float) -> None:
        if self.t and (t - self.t[-1] > max_gap_s or t <= self.t[-1]):
            if t <= self.t[-1]:
                return  # a second camera's view of the same instant
            self.clear()
        self.t.append(t)
        self.xy.append((x, y))

    def span(self) -> float:
        return self.t[-1] - self.t[0] if self.t else 0.0

    def clear(self) -> None:
        self.t.clear()
        self.xy.clear()

    def arrays(self) -> tuple[Array, Array]:
        return np.asarray(self.t, dtype=np.float64), np.asarray(self.xy, dtype=np.float64)


class _RobotRun(_Window):
    def __init__(self) -> None:
        super().__init__()
        self.braking: bool | None = None


class PhysicsEstimator:
    """Collects deceleration and acceleration windows frame by frame and sums them up (see the
    module docstring)."""

    def __init__(self, params: PhysicsFactsParams) -> None:
        self.p = params
        self.samples: dict[Fact, deque[float]] = {f: deque(maxlen=params.samples_kept) for f in Fact}
        self._roll = _Window()
        self._slide = _Window()
        self._touched = -math.inf  # a robot near the ball or a kick, last
        self._kicked = -math.inf
        self._slide_done = True
        self._kick: tuple[float, float] | None = None  # our last kick no robot touched since: (t, speed asked)
        self._across: tuple[float, OurKick] | None = None  # our last kick of a ball that came in across: (t, kick)
        self._gain = _Window()
        self._robots: dict[Any, _RobotRun] = {}

    # --- the ball -----------------------------------------------------------------------------------------
    def ball(self, t: float, x: float, y: float, robot_m: float, kicked: bool, kick: OurKick | None = None) -> None:
        """A detection of the tracked ball at ``t``; ``robot_m``: the nearest robot centre's distance,
        ``kicked``: the tracker took it as a kick or bounce, ``kick``: and it was one of our robots'
        kicks (None: not a kick of ours)."""
        p = self.p
        if kicked:
            self._kicked, self._slide_done = t, False
            self._slide.clear()
            self._kick = (t, kick.asked_m_s) if kick is not None else None
            across = kick is not None and abs(_across_in(kick)) >= p.retention_min_across_m_s
            self._across = (t, kick) if kick is not None and across else None
            self._gain.clear()
        if kicked or robot_m < p.clear_m:
            self._touched = t
            self._roll.clear()
        if not self._slide_done:
            if t - self._kicked > p.slide_within_s and not self._slide.t:
                self._slide_done = True
            elif robot_m >= p.slide_clear_m:
                self._slide.add(t, x, y, p.max_gap_s)
                if self._slide.span() >= p.slide_window_s:
                    fit = self._ball_sample(Fact.BALL_SLIDE, self._slide)
                    if fit is not None and self._across is not None:
                        self._retention_sample(*self._across, fit)
                    self._slide_done = True
            elif self._slide.t:
                self._slide_done = True  # back at a robot before the window was full
        if t - self._touched >= p.after_touch_s:
            self._roll.add(t, x, y, p.max_gap_s)
            if self._roll.span() >= p.window_s:
                self._ball_sample(Fact.BALL_ROLL, self._roll)
        if self._kick is not None:
            self._gain_sample(self._kick, t, x, y, robot_m)

    def _gain_sample(self, kick: tuple[float, float], t: float, x: float, y: float, robot_m: float) -> None:
        """The kicker's gain window: from when the model has our kicked ball rolling (its slide at the
        speed asked over, and ``gain_after_s`` more), ``gain_window_s`` of a ball clear of the robots;
        its deceleration one rolling sample, its speed halfway through taken back to the kick at the
        rolling deceleration known now (the window's own until the rolling one has its windows)."""
        p = self.p
        t_kick, asked = kick
        if t - t_kick < (1.0 - p.slide_to_roll_fraction) * asked / max(p.acc_slide_m_s2, 1e-9) + p.gain_after_s:
            return
        if robot_m < p.clear_m:
            self._kick = None
            self._gain.clear()
            return
        self._gain.add(t, x, y, p.max_gap_s)
        if self._gain.span() < p.gain_window_s:
            return
        self._kick = None  # one window a kick
        # the model has the ball rolling: a rolling window too (passes rarely run free longer)
        fit = self._ball_sample(Fact.BALL_ROLL, self._gain)
        if fit is None:
            return
        t_mid, speed = fit.t_mid, fit.speed
        decel = self._known(Fact.BALL_ROLL, fit.decel)
        launch = launch_speed(speed, decel, t_mid - t_kick, p.acc_slide_m_s2, p.slide_to_roll_fraction)
        self.samples[Fact.KICK_GAIN].append(launch / asked)

    def _retention_sample(self, t_kick: float, kick: OurKick, fit: _Fit) -> None:
        """One sample of the kick's retention across the heading from the slide window's ``fit`` after
        ``kick``: the ball left along the window's direction (the slide slows it along its run) at
        the window's speed taken back to the kick at the sliding deceleration known now (the
        configured one until its windows are ``min_samples``: grSim's ball does not slide, it rolls
        from the kick); its velocity across the heading less the robot's, over the incoming ball's
        relative to the robot."""
        nx, ny = -math.sin(kick.heading), math.cos(kick.heading)
        slide = self._known(Fact.BALL_SLIDE, self.p.acc_slide_m_s2)
        launch = fit.speed + slide * max(0.0, fit.t_mid - t_kick)
        across_out = launch * (fit.direction[0] * nx + fit.direction[1] * ny) - (kick.robot_v[0] * nx
                                                                                 + kick.robot_v[1] * ny)
        self.samples[Fact.KICK_RETENTION].append(across_out / _across_in(kick))

    def _known(self, fact: Fact, otherwise: float) -> float:
        """``fact`` as measured so far (the median of its windows, once they are ``min_samples``), else
        ``otherwise``: what a window taken back to its kick reckons with."""
        values = self.samples[fact]
        return float(np.median(values)) if len(values) >= self.p.min_samples else otherwise

    def _ball_sample(self, fact: Fact, window: _Window) -> _Fit | None:
        """The window's deceleration as one sample of ``fact``, and the window's fit (None: too few
        detections, a bounce, or too slow)."""
        t, xy = window.arrays()
        window.clear()
        if len(t) < 4:
            return None
        accel, v0, v1, rms = fit_acceleration(t, xy)
        speed0, speed1 = float(np.hypot(*v0)), float(np.hypot(*v1))
        if rms > self.p.max_residual_m or min(speed0, speed1) < self.p.min_speed_m_s:
            return None
        heading = (v0 + v1) / max(float(np.hypot(*(v0 + v1))), 1e-9)
        decel = -float(accel @ heading)
        self.samples[fact].append(decel)
        return _Fit(0.5 * (t[0] + t[-1]), 0.5 * (speed0 + speed1), decel, (float(heading[0]), float(heading[1])))

    # --- our robots ---------------------------------------------------------------------------------------
    def robot(self, key: Any, t: float, x: float, y: float, velocity: tuple[float, float],
              command: tuple[float, float] | None) -> None:
        """A detection of our robot ``key`` at ``t``, its tracked ``velocity`` and the velocity its
        command in force asks (None: no command of ours)."""
        run = self._robots.setdefault(key, _RobotRun())
        braking = None
        if command is not None:
            vx, vy = velocity
            dvx, dvy = command[0] - vx, command[1] - vy
            if math.hypot(dvx, dvy) > self.p.saturated_m_s:
                braking = dvx * vx + dvy * vy < 0.0 and math.hypot(*command) < math.hypot(vx, vy)
        if braking is None or braking != run.braking:
            run.clear()
            run.braking = braking
            if braking is None:
                return
        run.add(t, x, y, self.p.max_gap_s)
        if run.span() >= self.p.robot_window_s:
            times, xy = run.arrays()
            run.clear()
            if len(times) >= 4:
                accel, _, _, rms = fit_acceleration(times, xy)
                if rms <= self.p.robot_max_residual_m:
                    self.samples[Fact.ROBOT_BRAKE if braking else Fact.ROBOT_ACCEL].append(float(np.hypot(*accel)))

    def forget_robot(self, key: Any) -> None:
        self._robots.pop(key, None)

    # --- summing up ---------------------------------------------------------------------------------------
    def facts(self, t: float) -> PhysicsFacts:
        p = self.p
        learn = {Fact(name) for name in p.learn}
        out = []
        for fact in Fact:
            values = np.asarray(self.samples[fact], dtype=np.float64)
            configured = p.configured(fact)
            n = len(values)
            if n == 0:
                out.append(FactEstimate(fact, math.nan, configured, 0, math.nan, False, False))
                continue
            median = float(np.median(values))
            spread = 1.4826 * float(np.median(np.abs(values - median)))
            # the median's standard error: sqrt(pi / 2) times the mean's
            error = 1.2533 * spread / math.sqrt(n)
            if fact is Fact.KICK_RETENTION:  # a share of the incoming ball's across velocity: judged in shares
                confident = n >= p.retention_min_samples and error <= p.retention_max_error
                used = confident and fact in learn and abs(median - configured) > p.retention_use_margin
            else:
                need = p.kick_min_samples if fact is Fact.KICK_GAIN else p.min_samples
                confident = n >= need and median > 0.0 and error <= p.max_relative_error * median
                used = confident and fact in learn and abs(median - configured) > p.use_margin * configured
            out.append(FactEstimate(fact, median, configured, n, spread, confident, used))
        return PhysicsFacts(t, tuple(out))
