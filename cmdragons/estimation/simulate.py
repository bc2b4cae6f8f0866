"""A simulated run for the estimation examples: a vehicle driving a loop among point landmarks,
its noisy odometry and its noisy range-bearing sightings (seeded: the same run every time).

Metres, radians, seconds. The vehicle is velocity-steered: speed ``v`` and turn rate ``omega``;
odometry reports each step's pose change in the vehicle frame with Gaussian noise of ``odometry_sigma``
(x, y, theta per step); sightings of every landmark within ``max_range_m`` carry Gaussian noise of
``sensor_sigma`` (range m, bearing rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.estimation.models import compose, observe, velocity_steer

__all__ = ["Run", "Sighting", "simulate_run", "simulate_steered_run"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Sighting:
    landmark: int  # which landmark (known association)
    z: FloatArray  # range (m), bearing (rad)


@dataclass(frozen=True)
class Run:
    dt_s: float
    landmarks: FloatArray  # (m, 2)
    truth: FloatArray  # (n + 1, 3) true poses, the first the known start
    odometry: list[FloatArray]  # n noisy pose changes in the vehicle frame (steered: measured speed, steer angle)
    sightings: list[list[Sighting]]  # per step, after moving
    odometry_cov: FloatArray  # (3, 3) per step (steered: (2, 2))
    sensor_cov: FloatArray  # (2, 2)


def simulate_run(seed: int = 0, steps: int = 600, dt_s: float = 0.1, n_landmarks: int = 20,
                 area_m: float = 20.0, speed_m_s: float = 1.5, max_range_m: float = 8.0,
                 odometry_sigma: tuple[float, float, float] = (0.02, 0.01, 0.005),
                 sensor_sigma: tuple[float, float] = (0.1, 0.01),
                 max_sightings: int | None = None) -> Run:
    """The vehicle circles the area's centre at radius ``area_m / 3``, wobbling, among landmarks
    scattered over the square area. ``max_sightings``: at most that many sightings a step, drawn
    at random among the landmarks in range (one, as the Robotics Toolbox's RangeBearingSensor
    reports); None: every landmark in range."""
    if max_sightings is not None and max_sightings < 1:
        raise ValueError(f"max_sightings must be at least 1 or None, got {max_sightings}")
    rng = np.random.default_rng(seed)
    landmarks, pose, turn_rates = _loop(rng, n_landmarks, area_m, speed_m_s, steps)
    truth = [pose]
    odometry, sightings = [], []
    q = np.diag(np.square(odometry_sigma))
    r = np.diag(np.square(sensor_sigma))
    for omega in turn_rates:
        step = np.array([speed_m_s * dt_s, 0.0, omega * dt_s])
        pose = compose(pose, step)
        truth.append(pose)
        odometry.append(step + rng.normal(0.0, odometry_sigma))
        sightings.append(_sightings(pose, landmarks, rng, max_range_m, sensor_sigma, max_sightings))
    return Run(dt_s, landmarks, np.array(truth), odometry, sightings, q, r)


def _loop(rng: np.random.Generator, n_landmarks: int, area_m: float, speed_m_s: float,
          steps: int) -> tuple[FloatArray, FloatArray, list[float]]:
    """The landmarks scattered over the square area, the start pose on the loop (radius
    ``area_m / 3`` about the centre, heading along it) and each step's turn rate (rad/s): the
    circle's, wobbling."""
    landmarks = rng.uniform(-area_m / 2, area_m / 2, size=(n_landmarks, 2))
    radius = area_m / 3
    start = np.array([radius, 0.0, math.pi / 2])
    return landmarks, start, [speed_m_s / radius + 0.2 * math.sin(0.05 * k) for k in range(steps)]


def _sightings(pose: FloatArray, landmarks: FloatArray, rng: np.random.Generator, max_range_m: float,
               sensor_sigma: tuple[float, float], max_sightings: int | None) -> list[Sighting]:
    """Noisy sightings of the landmarks within range of ``pose`` (at most ``max_sightings``, drawn
    at random)."""
    seen = []
    for i, lm in enumerate(landmarks):
        z = observe(pose, lm)
        if z[0] <= max_range_m:
            seen.append(Sighting(i, z + rng.normal(0.0, sensor_sigma)))
    if max_sightings is not None and len(seen) > max_sightings:
        keep = np.sort(rng.choice(len(seen), size=max_sightings, replace=False))
        seen = [seen[j] for j in keep]
    return seen


def simulate_steered_run(seed: int = 0, steps: int = 600, dt_s: float = 0.1, n_landmarks: int = 20,
                         area_m: float = 20.0, speed_m_s: float = 1.5, wheelbase_m: float = 0.5,
                         max_range_m: float = 8.0, control_sigma: tuple[float, float] = (0.1, 0.02),
                         sensor_sigma: tuple[float, float] = (0.1, 0.01)) -> Run:
    """A velocity-steered vehicle (:func:`velocity_steer`, wheels ``wheelbase_m`` apart) on the loop
    of :func:`simulate_run`: it steers to circle the area's centre, wobbling; its odometry reports
    the speed (m/s) and steering angle (rad) it drove with, each with Gaussian noise of
    ``control_sigma``, held over the step."""
    rng = np.random.default_rng(seed)
    landmarks, pose, turn_rates = _loop(rng, n_landmarks, area_m, speed_m_s, steps)
    truth = [pose]
    odometry, sightings = [], []
    for omega in turn_rates:
        control = np.array([speed_m_s, math.asin(float(np.clip(omega * wheelbase_m / speed_m_s, -1.0, 1.0)))])
        pose = velocity_steer(pose, control, dt_s, wheelbase_m)
        truth.append(pose)
        odometry.append(control + rng.normal(0.0, control_sigma))
        sightings.append(_sightings(pose, landmarks, rng, max_range_m, sensor_sigma, None))
    q = np.diag(np.square(control_sigma))
    return Run(dt_s, landmarks, np.array(truth), odometry, sightings, q, np.diag(np.square(sensor_sigma)))
