"""The estimation examples' filters (Newman's lecture notes, ch. 4-7): the linear Kalman filter of
the Mars lander, EKF localisation against known landmarks, EKF-SLAM, and a particle filter.

filterpy carries the Kalman algebra (``KalmanFilter``, ``ExtendedKalmanFilter``); the models, their
Jacobians and the particle filter are ours (:mod:`cmdragons.estimation.models`; the particle
filter's step runs in the numba kernels of :mod:`cmdragons.estimation._kernels`). Every filter also
reports its consistency: the NEES (normalised estimation error squared) of its estimate against a
truth, which for a consistent filter follows a chi-square distribution with the state's degrees of
freedom.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter, KalmanFilter
from numpy.typing import ArrayLike, NDArray

from cmdragons.estimation import _kernels as K
from cmdragons.estimation.models import (
    compose,
    compose_jacobians,
    observation_to_landmark,
    observation_to_landmark_jacobians,
    observe,
    observe_jacobians,
    velocity_steer,
    velocity_steer_jacobians,
)
from cmdragons.estimation.simulate import Sighting
from cmdragons.geometry import wrap_angle

__all__ = [
    "EKFLocalisation",
    "EKFSlam",
    "EKFSteered",
    "Lander",
    "ParticleLocalisation",
    "lander_filter",
    "nees",
    "particle_estimate",
    "pose_error",
    "simulate_lander",
]

FloatArray = NDArray[np.float64]

_ZIGGURAT = K.ziggurat_tables()  # the particle filter's normal deviates' layer tables


def nees(error: ArrayLike, cov: ArrayLike) -> float:
    """e^T P^-1 e of an estimation error ``e`` with covariance ``P``."""
    e = np.asarray(error, dtype=np.float64)
    return float(e @ np.linalg.solve(np.asarray(cov, dtype=np.float64), e))


def pose_error(estimate: ArrayLike, truth: ArrayLike) -> FloatArray:
    """estimate - truth of two poses (x, y, theta), the heading difference wrapped to [-pi, pi)."""
    e = np.asarray(estimate, dtype=np.float64) - np.asarray(truth, dtype=np.float64)
    e[2] = wrap_angle(float(e[2]))
    return e


def _residual(a: FloatArray, b: FloatArray) -> FloatArray:
    """Residual of two range-bearing column vectors (2, 1), the bearing wrapped."""
    d = np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)
    d[1, 0] = wrap_angle(float(d[1, 0]))
    return d


# --- the Mars lander: a linear Kalman filter ----------------------------------------------------


@dataclass(frozen=True)
class Lander:
    """A lander falling under gravity with its engine's thrust, its altitude measured by radar.
    State (altitude m, vertical speed m/s); the control is the engine's acceleration (m/s^2)."""

    dt_s: float = 0.1
    gravity_m_s2: float = 3.71  # Mars
    accel_sigma_m_s2: float = 0.05  # unmodelled accelerations (wind, thrust noise)
    radar_sigma_m: float = 5.0


def lander_filter(lander: Lander, altitude_m: float, speed_m_s: float) -> KalmanFilter:
    """The linear Kalman filter for ``lander``: x' = F x + B (thrust - g), z = H x."""
    dt = lander.dt_s
    kf = KalmanFilter(dim_x=2, dim_z=1, dim_u=1)
    kf.F = np.array([[1.0, dt], [0.0, 1.0]])
    kf.B = np.array([[0.5 * dt * dt], [dt]])
    kf.H = np.array([[1.0, 0.0]])
    g = np.array([[0.5 * dt * dt], [dt]])
    kf.Q = g @ g.T * lander.accel_sigma_m_s2**2
    kf.R = np.array([[lander.radar_sigma_m**2]])
    kf.x = np.array([[altitude_m], [speed_m_s]])
    kf.P = np.diag([100.0**2, 10.0**2])
    return kf


def simulate_lander(lander: Lander, seed: int = 0, altitude_m: float = 10000.0, speed_m_s: float = -300.0,
                    steps: int = 5000) -> dict[str, FloatArray]:
    """A descent (the engine braking to hold a speed schedule from the filter's estimate) with its
    truth, the radar's readings and the filter's estimates and variances, per step."""
    rng = np.random.default_rng(seed)
    kf = lander_filter(lander, altitude_m + rng.normal(0, 100.0), speed_m_s + rng.normal(0, 10.0))
    x = np.array([altitude_m, speed_m_s])
    dt = lander.dt_s
    out: dict[str, list[float]] = {k: [] for k in ("t", "altitude", "speed", "radar", "est_altitude", "est_speed",
                                                   "var_altitude", "var_speed")}
    for k in range(steps):
        est_h, est_v = float(kf.x[0, 0]), float(kf.x[1, 0])
        target_v = -max(2.0, 0.02 * max(est_h, 0.0))  # slow down near the ground
        thrust = float(np.clip(lander.gravity_m_s2 + (target_v - est_v) / (5 * dt), 0.0, 3 * lander.gravity_m_s2))
        a = thrust - lander.gravity_m_s2 + rng.normal(0.0, lander.accel_sigma_m_s2)
        x = np.array([x[0] + x[1] * dt + 0.5 * a * dt * dt, x[1] + a * dt])
        z = x[0] + rng.normal(0.0, lander.radar_sigma_m)
        kf.predict(u=np.array([[thrust - lander.gravity_m_s2]]))
        kf.update(np.array([[z]]))
        for key, value in (("t", (k + 1) * dt), ("altitude", x[0]), ("speed", x[1]), ("radar", z),
                           ("est_altitude", kf.x[0, 0]), ("est_speed", kf.x[1, 0]), ("var_altitude", kf.P[0, 0]),
                           ("var_speed", kf.P[1, 1])):
            out[key].append(float(value))
        if x[0] <= 0.0:
            break
    return {k: np.array(v) for k, v in out.items()}


# --- EKF localisation against known landmarks ---------------------------------------------------


class _OdometryEKF(ExtendedKalmanFilter):  # type: ignore[misc]
    """filterpy's EKF with a vehicle motion model of the pose (the state's first three entries):
    the odometry model x' = x (+) u (F = J1, Q = J2 U J2^T), or any other by its Jacobians."""

    def predict_odometry(self, u: FloatArray, u_cov: FloatArray) -> None:
        pose = self.x[:3, 0]
        j1, j2 = compose_jacobians(pose, u)
        self.predict_pose(compose(pose, u), j1, j2, u_cov)

    def predict_pose(self, new_pose: FloatArray, f_pose: FloatArray, f_u: FloatArray, u_cov: FloatArray) -> None:
        """The pose moved to ``new_pose`` by a model with Jacobians ``f_pose`` (3, 3) and ``f_u``
        (3, m) of its noisy input of covariance ``u_cov`` (m, m); the rest of the state stays."""
        n = self.x.shape[0]
        f = np.eye(n)
        f[:3, :3] = f_pose
        q = np.zeros((n, n))
        q[:3, :3] = f_u @ u_cov @ f_u.T
        self.x[:3, 0] = new_pose
        self.F, self.Q = f, q
        self.P = f @ self.P @ f.T + q  # type: ignore[has-type]
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()


class EKFLocalisation:
    """The vehicle's pose from odometry and range-bearing sightings of landmarks at known places."""

    def __init__(self, landmarks: ArrayLike, start: ArrayLike, start_cov: ArrayLike, sensor_cov: ArrayLike) -> None:
        self.landmarks = np.asarray(landmarks, dtype=np.float64)
        self.ekf = _OdometryEKF(dim_x=3, dim_z=2)
        self.ekf.x = np.asarray(start, dtype=np.float64).reshape(3, 1).copy()
        self.ekf.P = np.asarray(start_cov, dtype=np.float64).copy()
        self.R = np.asarray(sensor_cov, dtype=np.float64)

    @property
    def pose(self) -> FloatArray:
        return np.array(self.ekf.x[:, 0], dtype=np.float64)

    @property
    def cov(self) -> FloatArray:
        return np.asarray(self.ekf.P, dtype=np.float64).copy()

    def predict(self, odometry: ArrayLike, odometry_cov: ArrayLike) -> None:
        self.ekf.predict_odometry(np.asarray(odometry, dtype=np.float64), np.asarray(odometry_cov, dtype=np.float64))

    def update(self, sightings: list[Sighting]) -> None:
        for s in sightings:
            lm = self.landmarks[s.landmark]
            self.ekf.update(s.z.reshape(2, 1), lambda x, lm=lm: observe_jacobians(x[:, 0], lm)[0],
                            lambda x, lm=lm: observe(x[:, 0], lm).reshape(2, 1), R=self.R,
                            residual=_residual)
            self.ekf.x[2, 0] = wrap_angle(float(self.ekf.x[2, 0]))

    def nees(self, truth: ArrayLike) -> float:
        return nees(pose_error(self.pose, truth), self.cov)


class EKFSteered(EKFLocalisation):
    """EKF localisation of a velocity-steered vehicle (notes §6.1-6.2): predicted from its
    odometry's measured speed and steering angle through :func:`velocity_steer` (the measurement
    noise carried into the pose by the model's Jacobian), corrected by sightings of known landmarks."""

    def __init__(self, landmarks: ArrayLike, start: ArrayLike, start_cov: ArrayLike, sensor_cov: ArrayLike,
                 dt_s: float, wheelbase_m: float) -> None:
        if dt_s <= 0.0 or wheelbase_m <= 0.0:
            raise ValueError(f"dt_s and wheelbase_m must be positive, got {dt_s} and {wheelbase_m}")
        super().__init__(landmarks, start, start_cov, sensor_cov)
        self.dt_s, self.wheelbase_m = dt_s, wheelbase_m

    def predict(self, odometry: ArrayLike, odometry_cov: ArrayLike) -> None:
        """``odometry``: the measured speed (m/s) and steering angle (rad) over the step;
        ``odometry_cov`` their (2, 2) covariance."""
        pose, u = self.ekf.x[:3, 0].copy(), np.asarray(odometry, dtype=np.float64)
        fx, fu = velocity_steer_jacobians(pose, u, self.dt_s, self.wheelbase_m)
        self.ekf.predict_pose(velocity_steer(pose, u, self.dt_s, self.wheelbase_m), fx, fu,
                              np.asarray(odometry_cov, dtype=np.float64))


# --- EKF-SLAM -----------------------------------------------------------------------------------


class EKFSlam:
    """Pose and landmark map together: state (x, y, theta, l1x, l1y, ...); a landmark joins the
    state the first time it is seen (its mean by the inverse sensor model, its covariance and its
    correlation with the pose through the model's Jacobians, lecture notes §7.6)."""

    def __init__(self, n_landmarks: int, start: ArrayLike, start_cov: ArrayLike, sensor_cov: ArrayLike) -> None:
        n = 3 + 2 * n_landmarks
        self.ekf = _OdometryEKF(dim_x=n, dim_z=2)
        self.ekf.x = np.zeros((n, 1))
        self.ekf.x[:3, 0] = np.asarray(start, dtype=np.float64)
        self.ekf.P = np.zeros((n, n))
        self.ekf.P[:3, :3] = np.asarray(start_cov, dtype=np.float64)
        self.known = np.zeros(n_landmarks, dtype=bool)
        self.R = np.asarray(sensor_cov, dtype=np.float64)

    @property
    def pose(self) -> FloatArray:
        return np.array(self.ekf.x[:3, 0], dtype=np.float64)

    @property
    def pose_cov(self) -> FloatArray:
        return np.asarray(self.ekf.P[:3, :3], dtype=np.float64).copy()

    def landmark(self, i: int) -> FloatArray:
        return np.array(self.ekf.x[3 + 2 * i : 5 + 2 * i, 0], dtype=np.float64)

    def landmark_cov(self, i: int) -> FloatArray:
        s = slice(3 + 2 * i, 5 + 2 * i)
        return np.asarray(self.ekf.P[s, s], dtype=np.float64).copy()

    def predict(self, odometry: ArrayLike, odometry_cov: ArrayLike) -> None:
        self.ekf.predict_odometry(np.asarray(odometry, dtype=np.float64), np.asarray(odometry_cov, dtype=np.float64))

    def _add(self, i: int, z: FloatArray) -> None:
        pose = self.ekf.x[:3, 0]
        s = slice(3 + 2 * i, 5 + 2 * i)
        self.ekf.x[s, 0] = observation_to_landmark(pose, z)
        gx, gz = observation_to_landmark_jacobians(pose, z)
        p = self.ekf.P
        cross = gx @ p[:3, :]  # the new landmark's correlation with every state, through the pose
        p[s, :] = cross
        p[:, s] = cross.T
        p[s, s] = gx @ p[:3, :3] @ gx.T + gz @ self.R @ gz.T
        self.known[i] = True

    def update(self, sightings: list[Sighting]) -> None:
        n = self.ekf.x.shape[0]
        for sgt in sightings:
            i = sgt.landmark
            if not self.known[i]:
                self._add(i, sgt.z)
                continue
            s = slice(3 + 2 * i, 5 + 2 * i)

            def jac(x: FloatArray, s: slice = s) -> FloatArray:
                jx, jl = observe_jacobians(x[:3, 0], x[s, 0])
                h = np.zeros((2, n))
                h[:, :3], h[:, s] = jx, jl
                return h

            self.ekf.update(sgt.z.reshape(2, 1), jac, lambda x, s=s: observe(x[:3, 0], x[s, 0]).reshape(2, 1),
                            R=self.R, residual=_residual)
            self.ekf.x[2, 0] = wrap_angle(float(self.ekf.x[2, 0]))

    def nees(self, truth: ArrayLike) -> float:
        """The pose's NEES."""
        return nees(pose_error(self.pose, truth), self.pose_cov)


# --- particle filter localisation ---------------------------------------------------------------


def particle_estimate(particles: ArrayLike, weights: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """The weighted mean pose of particles (n, 3) (the heading's circular mean) and their weighted
    covariance about it (headings wrapped); ``weights`` sum to 1."""
    p, w = np.asarray(particles, dtype=np.float64), np.asarray(weights, dtype=np.float64)
    theta = math.atan2(float(np.sum(w * np.sin(p[:, 2]))), float(np.sum(w * np.cos(p[:, 2]))))
    mean = np.array([float(np.sum(w * p[:, 0])), float(np.sum(w * p[:, 1])), theta])
    e = p - mean
    e[:, 2] = wrap_angle(e[:, 2])
    return mean, np.asarray((w[:, None] * e).T @ e, dtype=np.float64)


class ParticleLocalisation:
    """Monte Carlo localisation: particles moved by sampled odometry, weighted by the sightings'
    likelihood, resampled systematically when the effective sample size drops below half, and then
    regularised (Musso, Oudjane and Le Gland 2001): each copy moved by a draw from a Gaussian kernel
    of the cloud's covariance before resampling, scaled by ``bandwidth_share`` of the bandwidth that
    is optimal for a Gaussian density, (4 / (n (d + 2)))^(1 / (d + 4)). Without it a sharp sighting
    leaves a few distinct poses copied many times, whose spread understates the error (the filter
    reads overconfident: mean NEES about 3.6 for 3 at 500 particles on the bench's run).

    The work is done by the numba kernels of :mod:`cmdragons.estimation._kernels`: :meth:`step`
    (predict, update and estimate in one call) or :meth:`predict` and :meth:`update` apart. Their
    noise comes from a random stream of the filter's own, seeded from ``seed``'s generator."""

    def __init__(self, landmarks: ArrayLike, start: ArrayLike, start_cov: ArrayLike, sensor_cov: ArrayLike,
                 n: int = 500, seed: int = 0, bandwidth_share: float = 0.6) -> None:
        if bandwidth_share < 0.0:
            raise ValueError(f"bandwidth_share must be >= 0 (0: no regularisation), not {bandwidth_share}")
        self.bandwidth_share = bandwidth_share
        self.rng = np.random.default_rng(seed)
        self.landmarks = np.asarray(landmarks, dtype=np.float64)
        poses = self.rng.multivariate_normal(np.asarray(start, dtype=np.float64),
                                             np.asarray(start_cov, dtype=np.float64), size=n)
        poses[:, 2] = wrap_angle(poses[:, 2])
        # the kernels' layout: one row per quantity (x, y, theta, cos theta, sin theta), the particles along it
        # (C order: a stack of the poses' transpose would be Fortran-ordered, each row strided)
        self.cloud = np.ascontiguousarray(np.vstack([poses.T, np.cos(poses[:, 2]), np.sin(poses[:, 2])]))
        self.weights = np.full(n, 1.0 / n)
        self.R_inv = np.linalg.inv(np.asarray(sensor_cov, dtype=np.float64))
        self.stream = K.seed_stream(self.rng)
        d = 3
        self.bandwidth = bandwidth_share * (4.0 / (n * (d + 2))) ** (1.0 / (d + 4))
        self._scratch = np.empty_like(self.cloud)
        self._mean, self._cov = np.empty(3), np.empty((3, 3))
        self._estimated = False

    @property
    def particles(self) -> FloatArray:
        """The particles' poses (n, 3), a view of the cloud."""
        return self.cloud[:3].T

    def _seen(self, sightings: list[Sighting]) -> FloatArray:
        """The sightings as the kernels take them: rows (landmark x, y, range, bearing)."""
        seen = np.empty((len(sightings), 4))
        for i, sgt in enumerate(sightings):
            seen[i, :2] = self.landmarks[sgt.landmark]
            seen[i, 2:] = sgt.z
        return seen

    def predict(self, odometry: ArrayLike, odometry_cov: ArrayLike) -> None:
        low = K.psd_factor(np.asarray(odometry_cov, dtype=np.float64))
        K.move(self.cloud, np.asarray(odometry, dtype=np.float64), low, self.stream, *_ZIGGURAT)
        self._estimated = False

    def update(self, sightings: list[Sighting]) -> None:
        K.correct(self.cloud, self.weights, self._seen(sightings), self.R_inv, self.bandwidth, self.stream,
                  *_ZIGGURAT, self._scratch)
        self._estimated = False

    def step(self, odometry: ArrayLike, odometry_cov: ArrayLike, sightings: list[Sighting]) -> None:
        """:meth:`predict` then :meth:`update`, and the estimate, in one kernel call."""
        K.particle_step(self.cloud, self.weights, np.asarray(odometry, dtype=np.float64),
                        np.asarray(odometry_cov, dtype=np.float64), self._seen(sightings), self.R_inv,
                        self.bandwidth, self.stream, *_ZIGGURAT, self._scratch, self._mean, self._cov)
        self._estimated = True

    def _estimate(self) -> None:
        if not self._estimated:
            K.cloud_estimate(self.cloud, self.weights, self._mean, self._cov)
            self._estimated = True

    @property
    def pose(self) -> FloatArray:
        """The cloud's weighted mean pose (the heading's circular mean)."""
        self._estimate()
        return self._mean.copy()

    @property
    def cov(self) -> FloatArray:
        """The cloud's weighted covariance about :attr:`pose` (heading differences wrapped)."""
        self._estimate()
        return self._cov.copy()

    def nees(self, truth: ArrayLike) -> float:
        return nees(pose_error(self.pose, truth), self.cov)
