"""``cmdragons bench estimation``: EKF localisation, EKF-SLAM and the particle filter of
:mod:`cmdragons.estimation` beside Peter Corke's Robotics Toolbox's (``roboticstoolbox-python``:
``EKF`` with and without a map, ``ParticleFilter``), on the same simulated run.

The run is ours (:func:`cmdragons.estimation.simulate.simulate_run`, seeded): a vehicle driving a
wobbly loop among 20 point landmarks, its odometry noisy in distance and heading, one range-bearing
sighting a step of a landmark drawn at random among those in range (what the toolbox's
``RangeBearingSensor`` reports). The toolbox's filters are driven with that run's data: its
``Bicycle`` model (whose odometry model, x' = x + (d cos θ, d sin θ, Δθ), is our x ⊕ (d, 0, Δθ))
replays our odometry and truth, and its ``RangeBearingSensor``, on a ``LandmarkMap`` of our
landmarks, replays our sightings. Both get the same start (off the truth by a draw from its
covariance), start covariance, noise covariances and (for the particle filters) the same number of
particles from the same start distribution.

Per method and implementation: the RMS position error over the run (m), the mean pose NEES (3 for a
consistent filter), the fraction of steps whose NEES lies inside its chi-square (3 degrees of
freedom) 95% interval, the median time of one step (predict and update, µs; the particle filters'
with their estimate, which the toolbox's step computes), and on our rows the
ratio of our RMS error to the toolbox's (target <= ``TARGET_ERROR_RATIO``) and how many times
faster our step is. The toolbox's step includes the replay of the run (a list look-up). The
particle filters' NEES uses the covariance of the particle cloud; the toolbox's state noise is
``diag(σd², σd², σθ²)`` (its filter adds the noise in the world frame), its likelihood covariance
the sensor's. Without the toolbox our rows stand alone, with the reason in a note.

``--quick``: 200 steps (full: 1000).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.stats import chi2

from cmdragons.estimation.filters import (
    EKFLocalisation,
    EKFSlam,
    ParticleLocalisation,
    nees,
    particle_estimate,
    pose_error,
)
from cmdragons.estimation.simulate import Run, simulate_run
from cmdragons.runtime.settings import Settings

__all__ = ["METHODS", "TARGET_ERROR_RATIO", "Trace", "bench_run", "ours", "run", "start_estimate", "toolbox"]

FloatArray = NDArray[np.float64]

METHODS = ("ekf_localisation", "ekf_slam", "particle_filter")
TARGET_ERROR_RATIO = 1.10  # our RMS position error at most 10% above the toolbox's (issue #18)
SEED = 0
STEPS, QUICK_STEPS = 1000, 200
# per step: distance m, sideways m (none: the toolbox's odometry is distance and heading), heading rad
ODOMETRY_SIGMA = (0.02, 0.0, 0.005)
START_COV = np.diag([0.01, 0.01, 0.001])  # m², m², rad²
PARTICLES = 500
NEES_DOF = 3
MISSING = "roboticstoolbox-python not installed (pip install -e '.[bench]')"


def bench_run(steps: int) -> Run:
    """The seeded run every filter of the bench sees."""
    return simulate_run(seed=SEED, steps=steps, odometry_sigma=ODOMETRY_SIGMA, max_sightings=1)


def start_estimate(run: Run) -> FloatArray:
    """Every filter's start: the true start off by a draw from ``START_COV`` (a filter told by its
    start covariance that it is unsure must be wrong by about that much, or its NEES reads low)."""
    return np.asarray(run.truth[0] + np.random.default_rng(SEED).multivariate_normal(np.zeros(3), START_COV))


@dataclass(frozen=True)
class Trace:
    """One filter over the run: per step its position error (m), pose NEES and step time (s)."""

    error_m: FloatArray
    nees: FloatArray
    step_s: FloatArray

    def row(self, name: str) -> dict[str, Any]:
        lo, hi = chi2.ppf([0.025, 0.975], NEES_DOF)
        return {"name": name, "rms_error_m": float(np.sqrt(np.mean(self.error_m**2))),
                "mean_nees": float(np.mean(self.nees)),
                "nees_in_95": float(np.mean((self.nees >= lo) & (self.nees <= hi))),
                "step_us": float(np.median(self.step_s) * 1e6)}


def _trace(run: Run, step: Callable[[int], None], estimate: Callable[[], tuple[FloatArray, FloatArray]]) -> Trace:
    """Runs ``step(k)`` for every step of the run, timing it, and scores ``estimate()`` (pose and
    its covariance) against the truth after each."""
    n = len(run.odometry)
    err, nis, dt = np.empty(n), np.empty(n), np.empty(n)
    for k in range(n):
        t0 = time.perf_counter()
        step(k)
        dt[k] = time.perf_counter() - t0
        pose, cov = estimate()
        e = pose_error(pose[:3], run.truth[k + 1])
        err[k] = math.hypot(e[0], e[1])
        nis[k] = nees(e, cov)
    return Trace(err, nis, dt)


def ours(method: str, run: Run) -> Trace:
    """Our filter ``method`` over ``run``."""
    x0 = start_estimate(run)
    f: EKFLocalisation | EKFSlam | ParticleLocalisation
    if method == "ekf_localisation":
        f = EKFLocalisation(run.landmarks, x0, START_COV, run.sensor_cov)
    elif method == "ekf_slam":
        f = EKFSlam(len(run.landmarks), x0, START_COV, run.sensor_cov)
    else:
        f = ParticleLocalisation(run.landmarks, x0, START_COV, run.sensor_cov, n=PARTICLES, seed=SEED)

    def step(k: int) -> None:
        if isinstance(f, ParticleLocalisation):  # its estimate is part of its step, as the toolbox's
            f.step(run.odometry[k], run.odometry_cov, run.sightings[k])
            return
        f.predict(run.odometry[k], run.odometry_cov)
        f.update(run.sightings[k])

    def estimate() -> tuple[FloatArray, FloatArray]:
        cov = f.pose_cov if isinstance(f, EKFSlam) else f.cov
        return f.pose, cov

    return _trace(run, step, estimate)


def _odometry(run: Run) -> list[FloatArray]:
    """Our odometry as the toolbox's (distance, heading change); the run has no sideways part."""
    return [np.array([u[0], u[2]]) for u in run.odometry]


def _replay(run: Run) -> tuple[Any, Any, Any]:
    """The toolbox's vehicle and sensor replaying ``run``, and its map of the run's landmarks."""
    from roboticstoolbox import Bicycle, LandmarkMap, RangeBearingSensor

    odometry = _odometry(run)
    v = np.diag([run.odometry_cov[0, 0], run.odometry_cov[2, 2]])

    class ReplayVehicle(Bicycle):
        """The toolbox's bicycle model whose steps are the run's truth and odometry."""

        def init(self, *args: Any, **kwargs: Any) -> None:
            super().init(*args, **kwargs)
            self._k = 0

        def step(self, u: Any = None, animate: bool = False, pause: bool = False) -> FloatArray:
            self._x = run.truth[self._k + 1].copy()
            self._x_hist.append(tuple(self._x))
            self._t += self._dt
            self._k += 1
            return odometry[self._k - 1].copy()

    class ReplaySensor(RangeBearingSensor):
        """The toolbox's range-bearing sensor whose readings are the run's sightings."""

        def init(self) -> None:
            super().init()
            self._k = 0

        def reading(self) -> tuple[FloatArray | None, int | None]:
            seen = run.sightings[self._k]
            self._k += 1
            return (seen[0].z.copy(), seen[0].landmark) if seen else (None, None)

    vehicle = ReplayVehicle(covar=v, x0=run.truth[0], dt=run.dt_s)
    lmap = LandmarkMap(run.landmarks.T.copy(), workspace=float(np.max(np.abs(run.landmarks))) + 1.0)
    sensor = ReplaySensor(vehicle, lmap, covar=run.sensor_cov)
    return vehicle, sensor, lmap


def toolbox(method: str, run: Run) -> Trace:
    """The Robotics Toolbox's filter ``method`` over ``run`` (raises ImportError without it)."""
    from roboticstoolbox import EKF, ParticleFilter

    vehicle, sensor, lmap = _replay(run)
    v = np.diag([run.odometry_cov[0, 0], run.odometry_cov[2, 2]])
    if method in ("ekf_localisation", "ekf_slam"):
        kwargs = {"map": lmap} if method == "ekf_localisation" else {}
        ekf = EKF(robot=(vehicle, v), sensor=(sensor, run.sensor_cov), P0=START_COV, x0=start_estimate(run),
                  animate=False, history=False, **kwargs)
        ekf.init()
        return _trace(run, lambda k: ekf.step(), lambda: (ekf.x_est, ekf.P_est[:3, :3]))
    sd, sth = math.sqrt(run.odometry_cov[0, 0]), math.sqrt(run.odometry_cov[2, 2])
    start = np.random.default_rng(SEED + 1).multivariate_normal(start_estimate(run), START_COV, size=PARTICLES)
    pf = ParticleFilter(vehicle, sensor, R=np.diag([sd, sd, sth]) ** 2, L=run.sensor_cov, nparticles=PARTICLES,
                        seed=SEED, x0=start, animate=False, history=False)
    pf._init(x0=start)  # what its run() does first; stepping it ourselves times each step

    equal = np.full(PARTICLES, 1.0 / PARTICLES)  # its cloud after resampling, as its own estimate takes it
    return _trace(run, lambda k: pf._step(), lambda: particle_estimate(pf.x, equal))


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    steps = QUICK_STEPS if quick else STEPS
    data = bench_run(steps)
    try:
        import roboticstoolbox  # noqa: F401

        missing = None
    except ImportError:
        missing = MISSING
    rows: list[dict[str, Any]] = []
    for method in METHODS:
        mine = ours(method, data).row(method)
        if missing is not None:
            rows.append({**mine, "error_ratio": None, "speedup": None, "peer": missing})
            continue
        peer = toolbox(method, data).row(f"{method}_toolbox")
        mine["error_ratio"] = mine["rms_error_m"] / peer["rms_error_m"]
        mine["speedup"] = peer["step_us"] / mine["step_us"]
        rows += [mine, {**peer, "error_ratio": None, "speedup": None}]
    return rows
