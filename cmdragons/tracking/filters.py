"""Kalman filters for the ball and for robots (filterpy), in the field frame, SI units.

Both are linear: the ball's state is (x, y, vx, vy) and a robot's (x, y, theta, vx, vy, omega) with
velocities in the field frame, the frame our commands use too, so no extended or unscented filter
is needed; the only non-linearity, the heading's wrap-around, is handled by measuring the heading
relative to the prediction. Known accelerations (the ball's rolling or sliding deceleration, a
robot's acceleration toward its last command) enter as control inputs.

Ball model (the simulator's, after the CMDragons thesis): after a kick or a bounce the ball slides
at ``acc_slide`` until its speed falls to ``slide_to_roll_fraction`` of the speed the slide began
with, then rolls at ``acc_roll``; every touch of a robot starts a new slide. Kicks and bounces show
as innovations far outside the filter's expectation: the velocity covariance is then inflated so
the next detections re-acquire it, and the filter as it was is kept until the next detection: if
that one fits it, the odd detection was not a kick and the motion goes on as before.
"""

from __future__ import annotations

import copy
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, derived, setting
from cmdragons.geometry import wrap_angle

__all__ = [
    "BallFilter",
    "BallModelParams",
    "RobotFilter",
    "RobotModelParams",
    "SteadyUpdates",
    "predict_robots",
    "predicted_states",
]

Vec = NDArray[np.float64]


def kalman() -> Any:
    """filterpy's Kalman module, imported on first use: importing filterpy brings scipy.stats with it
    (a second or more), which a process that never tracks (the first run's compile children, the
    planning and simulator benches) should not pay."""
    from filterpy import kalman

    return kalman


@dataclass(frozen=True)
class BallModelParams(Validated):
    # vision's position noise, frame to frame, for detections that carry none of their own
    measurement_sigma_m: float = setting(0.0004, lo=1e-5, hi=1.0)
    accel_sigma_m_s2: float = setting(0.5, lo=0.0, hi=100.0)  # white-noise acceleration (model error)
    # the two-phase model: configured once, in field.yaml ball
    acc_slide_m_s2: float = derived("field.ball.acc_slide_m_s2", 3.0, lo=0.0, hi=50.0)
    acc_roll_m_s2: float = derived("field.ball.acc_roll_m_s2", 0.26, lo=0.0, hi=10.0)
    slide_to_roll_fraction: float = derived("field.ball.slide_to_roll_fraction", 0.64, lo=0.0, hi=1.0)
    initial_speed_sigma_m_s: float = setting(3.0, lo=0.01, hi=50.0)  # velocity uncertainty of a new track
    kick_gate_chi2: float = setting(25.0, lo=1.0, hi=1e6)  # innovation (2 dof) beyond this: kick or bounce
    kick_speed_sigma_m_s: float = setting(4.0, lo=0.01, hi=50.0)  # velocity uncertainty after a kick
    # a kick or bounce changes the ball's velocity by more than this; an innovation beyond the gate
    # after which the ball is found moving as before was the model's slide that ended earlier
    kick_min_velocity_change_m_s: float = setting(0.3, lo=0.0, hi=10.0)
    # next to a robot the ball may be pushed, dribbled or kicked at any moment: far less predictable
    near_robot_accel_sigma_m_s2: float = setting(8.0, lo=0.0, hi=500.0)
    near_robot_m: float = setting(0.15, lo=0.0, hi=2.0)  # ball centre to robot centre counted as next to it
    # ball centre to robot centre counted as touching (robot radius plus ball radius plus the
    # trackers' noise): every touch starts a new slide from the speed the ball leaves with
    touch_m: float = setting(0.12, lo=0.0, hi=2.0)
    switch_band: float = setting(0.12, lo=0.0, hi=1.0)  # +- share of the switch speed where the phase is unsure


@dataclass(frozen=True)
class RobotModelParams(Validated):
    measurement_sigma_m: float = setting(0.0005, lo=1e-5, hi=1.0)  # vision's robot position noise
    measurement_sigma_rad: float = setting(0.01, lo=1e-5, hi=3.0)
    accel_sigma_m_s2: float = setting(8.0, lo=0.0, hi=100.0)  # model error around the commanded motion
    alpha_sigma_rad_s2: float = setting(20.0, lo=0.0, hi=1000.0)
    # what our commands can ask of the motors: configured once, in field.yaml robot
    max_accel_m_s2: float = derived("field.robot.max_accel_m_s2", 3.0, lo=0.0, hi=50.0)
    max_alpha_rad_s2: float = derived("field.robot.max_alpha_rad_s2", 60.0, lo=0.0, hi=1000.0)
    initial_speed_sigma_m_s: float = setting(1.0, lo=0.01, hi=20.0)
    # after this many regular frames (one detection each, the same time step) the gain has settled
    # and the filter runs in filterpy's steady-state mode (a third of the cost) until a frame differs
    steady_after_updates: int = setting(30, lo=1, hi=100000)
    # the gate's floor: robots pushing each other move a few centimetres outside the model, and
    # vision is so precise that the filter's own covariance would reject that; a wrong id is at
    # least a robot diameter (0.18 m) away and stays rejected (sqrt(robot_gate_chi2) x floor = 7.7 cm)
    gate_floor_m: float = setting(0.01, lo=0.0, hi=1.0)
    gate_floor_rad: float = setting(0.1, lo=0.0, hi=3.2)


def _cv_matrices(n: int, dt: float, sigmas: tuple[float, ...]) -> tuple[Vec, Vec, Vec]:
    """Constant-velocity F, control B (accelerations) and white-noise-acceleration Q for ``n``
    position coordinates followed by their ``n`` velocities."""
    eye = np.eye(n)
    zero = np.zeros((n, n))
    f = np.block([[eye, dt * eye], [zero, eye]])
    b = np.vstack([0.5 * dt * dt * eye, dt * eye])
    q = np.zeros((2 * n, 2 * n))
    for i, s in enumerate(sigmas):
        s2 = s * s
        q[i, i] = s2 * dt**4 / 4.0
        q[i, n + i] = q[n + i, i] = s2 * dt**3 / 2.0
        q[n + i, n + i] = s2 * dt * dt
    return f, b, q


class _Cache:
    """F, B, Q per time step: frames come at a few fixed intervals, so these repeat."""

    def __init__(self, n: int, sigmas: tuple[float, ...]) -> None:
        self.n, self.sigmas = n, sigmas
        self._by_dt: dict[float, tuple[Vec, Vec, Vec]] = {}

    def get(self, dt: float) -> tuple[Vec, Vec, Vec]:
        key = round(dt, 7)
        m = self._by_dt.get(key)
        if m is None:
            if len(self._by_dt) > 64:
                self._by_dt.clear()
            m = self._by_dt[key] = _cv_matrices(self.n, key, self.sigmas)
        return m


class BallFilter:
    """One ball hypothesis: (x, y, vx, vy) with the two-phase deceleration as control input."""

    def __init__(self, p: BallModelParams, x: float, y: float, t: float) -> None:
        self.p = p
        kf = kalman().KalmanFilter(dim_x=4, dim_z=2)
        kf.x = np.array([x, y, 0.0, 0.0])
        kf.P = np.diag([p.measurement_sigma_m**2] * 2 + [p.initial_speed_sigma_m_s**2] * 2)
        kf.H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
        kf.R = np.eye(2) * p.measurement_sigma_m**2
        self.kf = kf
        self.t = t
        self.cache = _Cache(2, (p.accel_sigma_m_s2, p.accel_sigma_m_s2))
        # process noise by what may move the ball besides the model: nothing, the slide-to-roll
        # switch (one deceleration for the other), a robot next to it
        switch_sigma = max(p.accel_sigma_m_s2, abs(p.acc_slide_m_s2 - p.acc_roll_m_s2))
        self.caches = (self.cache, _Cache(2, (switch_sigma, switch_sigma)),
                       _Cache(2, (p.near_robot_accel_sigma_m_s2, p.near_robot_accel_sigma_m_s2)))
        # a ball first seen may have just been kicked: sliding until its speed is known (as after a kick)
        self.slide_start_speed = math.inf
        self.t_kick = t
        self.kicked = False
        # the velocity before the last detected kick, while the filter had the ball sliding; None
        # once the velocity after it is known, or when the filter had it rolling
        self.sliding_before_kick: Vec | None = None
        # after a detection far outside the expectation, the filter as it was before it, kept until
        # the next detection tells a kick (which it does not fit) from a single bad detection (which
        # it does: a ball seen at the edge of a camera, a reflection)
        self.held: BallFilter | None = None
        self._updated_at = math.nan  # time of the last update
        # the predicted position and its covariance (x, y, var x, cov xy, var y) before this
        # instant's first update: a second camera's view of the instant is gated against it
        self._prior = (0.0, 0.0, 0.0, 0.0, 0.0)
        self._first_var = 0.0  # the measurement variance of that first update

    def _decel(self, v: Vec, dt: float) -> Vec:
        speed = math.hypot(v[0], v[1])
        if speed < 1e-6 or dt <= 0.0:
            return np.zeros(2)
        sliding = speed > self.p.slide_to_roll_fraction * self.slide_start_speed
        a = self.p.acc_slide_m_s2 if sliding else self.p.acc_roll_m_s2
        a = min(a, speed / dt)  # friction stops the ball; it never reverses it
        return -a * v[:2] / speed

    def predicted(self, t: float) -> tuple[Vec, Vec]:
        """State and covariance at time ``t`` (no change to the filter)."""
        dt = t - self.t
        if dt <= 0.0:
            return self.kf.x.copy(), self.kf.P.copy()
        f, b, q = self.cache.get(dt)
        x = f @ self.kf.x + b @ self._decel(self.kf.x[2:], dt)
        return x, f @ self.kf.P @ f.T + q

    def predict(self, t: float, robot_m: float = math.inf) -> None:
        """Advance to ``t``; ``robot_m``: the distance from the ball to the nearest robot's centre (a
        robot next to the ball may move it at any moment; one touching it starts a new slide)."""
        dt = t - self.t
        if dt <= 0.0:
            return
        near_robot = robot_m < self.p.near_robot_m
        # the slide-to-roll switch is only known to within the slide's start speed: around it, the
        # filter follows the detections rather than the model
        speed = math.hypot(self.kf.x[2], self.kf.x[3])
        switch = self.p.slide_to_roll_fraction * self.slide_start_speed
        near_switch = math.isfinite(switch) and abs(speed - switch) < self.p.switch_band * switch
        f, b, q = self.caches[2 if near_robot else 1 if near_switch else 0].get(dt)
        self.kf.predict(u=self._decel(self.kf.x[2:], dt), B=b, F=f, Q=q)
        self.t = t
        if robot_m < self.p.touch_m:
            # every touch of a robot starts a new slide (as a kick does) from the speed it leaves with
            self.slide_start_speed = math.inf
            self.t_kick = t
        if self.held is not None:
            self.held.predict(t, robot_m)

    def _position(self) -> tuple[float, float, float, float, float]:
        """The filter's position and its covariance (x, y, var x, cov xy, var y), plain floats (2 x 2
        algebra: numpy's per-call cost would be most of it)."""
        x0, x1 = cast(list[float], self.kf.x[:2].tolist())
        (a, b), (_, d) = cast(list[list[float]], self.kf.P[:2, :2].tolist())
        return x0, x1, a, b, d

    @staticmethod
    def _nis(z: Vec, position: tuple[float, float, float, float, float], r_var: float) -> float:
        return BallFilter._nis_nll(z, position, r_var)[0]

    @staticmethod
    def _nis_nll(z: Vec, position: tuple[float, float, float, float, float], r_var: float) -> tuple[float, float]:
        """The normalised innovation squared of ``z`` and the negative log of its density under the
        predicted position (2-d Gaussian, innovation covariance S): nis / 2 + ln(2 pi) + ln(det S) / 2."""
        x0, x1, a, b, d = position
        a, d = a + r_var, d + r_var
        y0, y1 = float(z[0]) - x0, float(z[1]) - x1
        det = a * d - b * b
        nis = (d * y0 * y0 - 2.0 * b * y0 * y1 + a * y1 * y1) / det
        return nis, 0.5 * nis + math.log(2.0 * math.pi) + 0.5 * math.log(det)

    def measurement_var(self, sigma_m: float = math.nan) -> float:
        """The measurement variance (m^2 per axis) of a detection whose own standard deviation is
        ``sigma_m`` (NaN: not known, the configured one)."""
        s = sigma_m if math.isfinite(sigma_m) and sigma_m > 0.0 else self.p.measurement_sigma_m
        return s * s

    def nis(self, z: Vec, sigma_m: float = math.nan) -> float:
        """Normalised innovation squared of a detection (its standard deviation ``sigma_m``, NaN: the
        configured one) against the current prediction."""
        return self._nis(z, self._position(), self.measurement_var(sigma_m))

    def nis_nll(self, z: Vec, sigma_m: float = math.nan) -> tuple[float, float]:
        """A detection's normalised innovation squared (as :meth:`nis`) and the negative log of its
        density under the prediction: the likelihood that tells which of two hypotheses explains it
        better. The normalised error alone flatters the less certain one (a ball held unseen in a
        robot's mouth, its position known to centimetres, "fits" a detection 0.4 m away better than
        the ball tracked to a millimetre fits one 4 mm off its prediction)."""
        return self._nis_nll(z, self._position(), self.measurement_var(sigma_m))

    def update(self, z: Vec, nis: float | None = None, sigma_m: float = math.nan) -> bool:
        """Take a detection (``nis``: its :meth:`nis`, when already known; ``sigma_m``: its standard
        deviation per axis, NaN for the configured one, the measurement noise R of this update);
        returns True when it looked like a kick or bounce. A second camera's view of one instant is
        judged against the prediction before that instant, not after the first view: no kick
        happens between two views of one instant, so one that fits is no kick even where the two
        cameras disagree by more than their sigmas (their calibrations differ a little). One that
        does not fit while the first view fitted is dropped, unless it is more certain than the
        first: a kick cannot show in one camera and not in the other (it is a ball cut by the
        image's edge or half hidden by a robot), but the first may have been the partly hidden one."""
        r_var = self.measurement_var(sigma_m)
        if self._updated_at == self.t:
            fits_prior = self._nis(z, self._prior, r_var) <= self.p.kick_gate_chi2
            if not (fits_prior or self.kicked or r_var < self._first_var):
                return False
            if fits_prior:
                nis = 0.0  # no kick between two views of one instant: cameras that disagree a little
        else:
            self._prior = self._position()
            self._first_var = r_var
        if self.held is not None:
            held, self.held = self.held, None
            held_nis, held_nll = held.nis_nll(z, sigma_m)
            if held_nis <= self.p.kick_gate_chi2 and held_nll <= self.nis_nll(z, sigma_m)[1]:
                # the motion goes on as before the odd detection: that one was not a kick. Only where
                # the motion before explains this detection better than the one after the odd
                # detection does: an uncertain filter (a ball held unseen in a robot's mouth) fits a
                # detection far off, and taking it from there makes a velocity of that whole jump
                vars(self).update(vars(held))
                nis = None
        kicked = (self.nis(z, sigma_m) if nis is None else nis) > self.p.kick_gate_chi2
        if kicked:
            self.held = copy.deepcopy(self)
            speed = math.hypot(self.kf.x[2], self.kf.x[3])
            sliding = speed > self.p.slide_to_roll_fraction * self.slide_start_speed
            self.sliding_before_kick = self.kf.x[2:].copy() if sliding else None
            # the velocity is unknown after a kick: forget it, keep the position's certainty
            self.kf.P[2:, :] = 0.0
            self.kf.P[:, 2:] = 0.0
            self.kf.P[2:, 2:] = np.eye(2) * self.p.kick_speed_sigma_m_s**2
            self.kf.P[:2, :2] += np.eye(2) * float(np.sum((z - self.kf.x[:2]) ** 2))
            self.slide_start_speed = math.inf  # sliding until the new speed is known
            self.t_kick = self.t
        self.kf.R[0, 0] = self.kf.R[1, 1] = r_var  # in place: a new matrix per update costs more than the update
        self.kf.update(z)
        self._updated_at = self.t
        if self.slide_start_speed == math.inf and self.kf.P[2, 2] < 0.25:
            # the speed is known now, some frames after the kick: the slide began faster than that
            speed = math.hypot(self.kf.x[2], self.kf.x[3])
            self.slide_start_speed = speed + self.p.acc_slide_m_s2 * max(0.0, self.t - self.t_kick)
            before = self.sliding_before_kick
            if before is not None and math.hypot(*(self.kf.x[2:] - before)) < self.p.kick_min_velocity_change_m_s:
                # no kick: the ball moves on as before, ahead of the slide the filter had it in,
                # so that slide had ended: it rolls (and a rolling ball only slows down)
                self.slide_start_speed = speed / max(self.p.slide_to_roll_fraction, 1e-9)
            self.sliding_before_kick = None
        self.kicked = kicked
        return kicked

    @property
    def position(self) -> Vec:
        return cast(Vec, self.kf.x[:2])

    @property
    def velocity(self) -> Vec:
        return cast(Vec, self.kf.x[2:])

    def hold(self, x: float, y: float, vx: float, vy: float, sigma_m: float) -> None:
        """The ball in a robot's mouth, out of the cameras' sight: where the robot carries it (field
        frame, m and m/s), its position known to ``sigma_m``, its velocity the robot's; a new slide
        starts when it leaves."""
        self.kf.x[:] = (x, y, vx, vy)
        self.kf.P[:] = 0.0
        self.kf.P[0, 0] = self.kf.P[1, 1] = sigma_m * sigma_m
        self.kf.P[2, 2] = self.kf.P[3, 3] = self.p.kick_speed_sigma_m_s**2
        self.slide_start_speed = math.inf
        self.held = None


class RobotFilter:
    """One robot: (x, y, theta, vx, vy, omega); the last command in force is the control input."""

    def __init__(self, p: RobotModelParams, x: float, y: float, theta: float, t: float) -> None:
        self.p = p
        kf = kalman().KalmanFilter(dim_x=6, dim_z=3)
        kf.x = np.array([x, y, theta, 0.0, 0.0, 0.0])
        kf.P = np.diag([p.measurement_sigma_m**2] * 2 + [p.measurement_sigma_rad**2]
                       + [p.initial_speed_sigma_m_s**2] * 2 + [(4 * p.initial_speed_sigma_m_s) ** 2])
        kf.H = np.hstack([np.eye(3), np.zeros((3, 3))])
        kf.R = np.diag([p.measurement_sigma_m**2] * 2 + [p.measurement_sigma_rad**2])
        self.kf = kf
        self.t = t
        self.cache = _Cache(3, (p.accel_sigma_m_s2, p.accel_sigma_m_s2, p.alpha_sigma_rad_s2))
        self.command: tuple[float, float, float] | None = None  # (vx, vy, omega) in force
        self._steady: Vec | None = None  # inverse innovation covariance while in steady-state mode
        self._steady_list: list[float] = []  # the same, row by row, as floats
        self._gate_floor = np.diag([p.gate_floor_m**2, p.gate_floor_m**2, p.gate_floor_rad**2])
        self._steady_dt = 0.0
        self._steady_epoch = 0  # tells one settled gain from the next (caches of stacked gains)
        self._dt = 0.0
        self._regular = 0  # consecutive regular frames
        self._pending_update = False  # predicted, not yet updated at this time

    def _accel(self, state: Vec, dt: float) -> Vec:
        """Accelerations toward the commanded velocity, as far as the motors allow in ``dt``."""
        return np.array(self._accel_tuple(float(state[3]), float(state[4]), float(state[5]), dt, self.command))

    def _accel_tuple(self, vx: float, vy: float, w: float, dt: float,
                     command: tuple[float, float, float] | None) -> tuple[float, float, float]:
        if command is None or dt <= 0.0:
            return (0.0, 0.0, 0.0)
        ax, ay = (command[0] - vx) / dt, (command[1] - vy) / dt
        norm = math.hypot(ax, ay)
        if norm > self.p.max_accel_m_s2:
            ax, ay = ax * self.p.max_accel_m_s2 / norm, ay * self.p.max_accel_m_s2 / norm
        a_ang = min(max((command[2] - w) / dt, -self.p.max_alpha_rad_s2), self.p.max_alpha_rad_s2)
        return (ax, ay, a_ang)

    def predicted_state(self, t: float,
                        commands: Sequence[tuple[float, tuple[float, float, float]]] = ()) -> Vec:
        """State at time ``t`` (no change to the filter; robots hand on no covariance). ``commands``
        (time they take effect, (vx, vy, omega)), in time order, are followed as they come into force
        between now and ``t``: the look-ahead must see the commands already sent."""
        # plain floats: this runs for every robot every frame, and numpy's per-call cost on
        # 6-vectors would dominate it
        x = [float(v) for v in self.kf.x]
        now, command = self.t, self.command
        for t_effect, cmd in commands:
            if t_effect <= now:
                command = cmd
                continue
            if t_effect >= t:
                break
            x = self._advance(x, t_effect - now, command)
            now, command = t_effect, cmd
        if t > now:
            x = self._advance(x, t - now, command)
        x[2] = wrap_angle(x[2])
        return np.array(x)

    def _advance(self, x: list[float], dt: float, command: tuple[float, float, float] | None) -> list[float]:
        """Constant acceleration toward ``command`` for ``dt`` seconds (the filter's motion model)."""
        a = self._accel_tuple(x[3], x[4], x[5], dt, command)
        h = 0.5 * dt * dt
        return [x[0] + x[3] * dt + a[0] * h, x[1] + x[4] * dt + a[1] * h, x[2] + x[5] * dt + a[2] * h,
                x[3] + a[0] * dt, x[4] + a[1] * dt, x[5] + a[2] * dt]

    def steady_step(self, t: float) -> bool:
        """Whether the step to ``t`` is a regular one in steady-state mode (the settled gain holds)."""
        return (self._steady is not None and not self._pending_update
                and abs(t - self.t - self._steady_dt) < 1e-6)

    @property
    def steady_pending(self) -> bool:
        """Predicted in steady-state mode and waiting for this frame's detection."""
        return self._steady is not None and self._pending_update

    def predict(self, t: float) -> None:
        dt = t - self.t
        if dt <= 0.0:
            return
        f, b, q = self.cache.get(dt)
        u = self._accel(self.kf.x, dt)
        if self._steady is not None and abs(dt - self._steady_dt) < 1e-6 and not self._pending_update:
            self.kf.F = f
            self.kf.predict_steadystate(u=u, B=b)
        else:
            self._leave_steady()
            self.kf.predict(u=u, B=b, F=f, Q=q)
            self._dt = dt
        self.kf.x[2] = wrap_angle(self.kf.x[2])
        self.t = t
        self._pending_update = True

    def innovation(self, z: Vec) -> Vec:
        y = cast(Vec, z - self.kf.x[:3])
        y[2] = wrap_angle(y[2])
        return y

    def nis(self, z: Vec | tuple[float, float, float]) -> float:
        if self._steady is not None and self._pending_update:
            # the settled gate: y' S^-1 y in plain floats (called for every detection, every frame)
            x0, x1, x2 = cast(list[float], self.kf.x[:3].tolist())
            y0, y1, y2 = z[0] - x0, z[1] - x1, wrap_angle(z[2] - x2)
            si = self._steady_list
            return (y0 * (si[0] * y0 + si[1] * y1 + si[2] * y2) + y1 * (si[3] * y0 + si[4] * y1 + si[5] * y2)
                    + y2 * (si[6] * y0 + si[7] * y1 + si[8] * y2))
        y = self.innovation(np.asarray(z, dtype=float))
        s = self.kf.P[:3, :3] + self.kf.R + self._gate_floor
        return float(y @ np.linalg.solve(s, y))

    def update(self, z: Vec | tuple[float, float, float]) -> None:
        # the heading measured next to the prediction, so the filter never sees the wrap
        zz = self.kf.x[:3] + self.innovation(np.asarray(z, dtype=float))
        if self._steady is not None and self._pending_update:
            self.kf.update_steadystate(zz)
        else:
            self._leave_steady()  # a second view in the same frame: the settled gain does not apply
            self.kf.update(zz)
            self._regular = self._regular + 1 if self._pending_update else 0
            if self._regular >= self.p.steady_after_updates:
                self._enter_steady()
        self.kf.x[2] = wrap_angle(self.kf.x[2])
        self._pending_update = False

    def miss(self) -> None:
        """No detection this frame: the settled gain no longer holds."""
        self._leave_steady()
        self._regular = 0

    def _enter_steady(self) -> None:
        # filterpy's last full update left the settled gain in kf.K and the settled posterior in kf.P;
        # the gate needs the innovation covariance of the settled prior
        f, _, q = self.cache.get(self._dt)
        prior = f @ self.kf.P @ f.T + q
        self._steady = np.linalg.inv(prior[:3, :3] + self.kf.R + self._gate_floor)
        self._steady_list = [float(v) for v in self._steady.ravel()]
        self._steady_dt = self._dt
        self._steady_epoch = next(_EPOCHS)

    def _leave_steady(self) -> None:
        if self._steady is not None:
            self._steady = None
            self._regular = 0


_EPOCHS = itertools.count(1)


def predict_robots(filters: Sequence[RobotFilter], t: float) -> None:
    """Advance every robot filter to ``t``. Those in steady-state mode on a regular step advance
    together, their states the columns of one matrix through one filterpy call (per-robot calls
    cost far more than the algebra); the others one by one."""
    groups: dict[float, list[RobotFilter]] = {}
    for f in filters:
        if f.steady_step(t):
            groups.setdefault(round(t - f.t, 7), []).append(f)
        else:
            f.predict(t)
    for dt, group in groups.items():
        fm, bm, _ = group[0].cache.get(dt)
        x = np.array([f.kf.x for f in group]).T
        u = np.zeros((3, len(group)))
        for i, f in enumerate(group):
            if f.command is not None:  # the accelerations toward our command; none for the opponents
                u[:, i] = f._accel_tuple(float(x[3, i]), float(x[4, i]), float(x[5, i]), dt, f.command)
        x = kalman().predict_steadystate(x, F=fm, u=u, B=bm)
        x[2] = wrap_angle(x[2])
        rows = np.ascontiguousarray(x.T)
        for f, row in zip(group, rows, strict=True):
            f.kf.x = row
            f.t = t
            f._pending_update = True


class SteadyUpdates:
    """One detection each for robots predicted in steady-state mode, gated and taken together: the
    gates (Mahalanobis distance with each robot's settled innovation covariance) as one array
    operation, the accepted detections in one filterpy steady-state update, the states stacked into
    one vector and the settled gains into a block-diagonal gain. The same result as one
    :meth:`RobotFilter.nis` and :meth:`RobotFilter.update` per robot, for a fraction of the calls."""

    def __init__(self) -> None:
        self._gate_key: tuple[int, ...] = ()
        self._s_inv: Vec = np.zeros((0, 3, 3))
        self._gain_key: tuple[int, ...] = ()
        self._gain: Vec = np.zeros((0, 0))
        self._h: Vec = np.zeros((0, 0))

    def take(self, robots: Sequence[RobotFilter], z: Sequence[tuple[float, float, float]],
             gate_chi2: float) -> NDArray[np.bool_]:
        """Update each of ``robots`` (all :attr:`RobotFilter.steady_pending`) with its detection in
        ``z`` whose Mahalanobis distance squared is within ``gate_chi2``; returns which were taken."""
        if not robots:
            return np.zeros(0, dtype=bool)
        x = np.array([f.kf.x for f in robots])
        y = np.array(z) - x[:, :3]
        y[:, 2] = wrap_angle(y[:, 2])  # the heading next to the prediction
        key = tuple(f._steady_epoch for f in robots)
        if key != self._gate_key:
            self._s_inv = np.array([f._steady for f in robots])
            self._gate_key = key
        ok: NDArray[np.bool_] = np.einsum("ni,nij,nj->n", y, self._s_inv, y) <= gate_chi2
        taken = [f for f, good in zip(robots, ok.tolist(), strict=True) if good]
        if not taken:
            return ok
        key = tuple(f._steady_epoch for f in taken)
        if key != self._gain_key:
            self._gain = _block_diag([f.kf.K for f in taken])
            self._h = _block_diag([f.kf.H for f in taken])
            self._gain_key = key
        xs = kalman().update_steadystate(x[ok].ravel(), (x[ok, :3] + y[ok]).ravel(), self._gain, self._h)
        n = x.shape[1]
        xs[2::n] = wrap_angle(xs[2::n])
        for i, f in enumerate(taken):
            f.kf.x = xs[i * n : (i + 1) * n]
            f._pending_update = False
        return ok


def _block_diag(blocks: Sequence[Vec]) -> Vec:
    """The blocks along the diagonal of one zero matrix (scipy.linalg.block_diag's result, without
    its per-call checks: the tracker builds one for every set of detections a camera takes)."""
    out = np.zeros((sum(b.shape[0] for b in blocks), sum(b.shape[1] for b in blocks)))
    r = c = 0
    for b in blocks:
        out[r : r + b.shape[0], c : c + b.shape[1]] = b
        r += b.shape[0]
        c += b.shape[1]
    return out


def predicted_states(filters: Sequence[RobotFilter], t: float,
                     commands: Sequence[Sequence[tuple[float, tuple[float, float, float]]]]) -> Vec:
    """States (one row per filter) at time ``t``, as :meth:`RobotFilter.predicted_state` with each
    filter's ``commands``. Robots without a command (the opponents) move at constant velocity and
    are extrapolated together."""
    out = np.empty((len(filters), 6))
    free = [i for i, (f, c) in enumerate(zip(filters, commands, strict=True)) if f.command is None and not c]
    if free:
        x = np.array([filters[i].kf.x for i in free])
        dt = np.maximum(t - np.array([filters[i].t for i in free]), 0.0)
        x[:, :3] += dt[:, None] * x[:, 3:]
        x[:, 2] = wrap_angle(x[:, 2])
        out[free] = x
    if len(free) < len(filters):
        for i in sorted(set(range(len(filters))) - set(free)):
            out[i] = filters[i].predicted_state(t, commands[i])
    return out
