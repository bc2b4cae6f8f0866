"""Vehicle and sensor models of the estimation examples (Newman's lecture notes, ch. 5-7).

Poses are (x, y, theta): metres, radians, in a fixed world frame. Odometry reports the pose change
in the vehicle's own frame since the last report; poses compose with the head-to-tail operator
``compose`` (x1 (+) x2) and its inverse ``invert`` ((-) x). The sensor measures range and bearing to
point landmarks, the bearing relative to the vehicle's heading. A velocity-steered vehicle (notes
§6.1, a front-wheel-steered car) moves by its speed and steering angle instead (``velocity_steer``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.geometry import wrap_angle

__all__ = [
    "compose",
    "compose_jacobians",
    "invert",
    "observe",
    "observe_jacobians",
    "observation_to_landmark",
    "observation_to_landmark_jacobians",
    "velocity_steer",
    "velocity_steer_jacobians",
]

FloatArray = NDArray[np.float64]


def compose(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """a (+) b: the pose b, given in a's frame, in a's parent frame."""
    xa, ya, ta = np.asarray(a, dtype=np.float64)
    xb, yb, tb = np.asarray(b, dtype=np.float64)
    c, s = math.cos(ta), math.sin(ta)
    return np.array([xa + c * xb - s * yb, ya + s * xb + c * yb, wrap_angle(ta + tb)])


def compose_jacobians(a: ArrayLike, b: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """d(a (+) b)/da and d(a (+) b)/db, each (3, 3)."""
    _, _, ta = np.asarray(a, dtype=np.float64)
    xb, yb, _ = np.asarray(b, dtype=np.float64)
    c, s = math.cos(ta), math.sin(ta)
    j1 = np.array([[1.0, 0.0, -s * xb - c * yb], [0.0, 1.0, c * xb - s * yb], [0.0, 0.0, 1.0]])
    j2 = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return j1, j2


def invert(a: ArrayLike) -> FloatArray:
    """(-) a: the parent frame's origin seen from a."""
    x, y, t = np.asarray(a, dtype=np.float64)
    c, s = math.cos(t), math.sin(t)
    return np.array([-c * x - s * y, s * x - c * y, wrap_angle(-t)])


def observe(pose: ArrayLike, landmark: ArrayLike) -> FloatArray:
    """Range (m) and bearing (rad, relative to the heading) from ``pose`` to ``landmark`` (x, y)."""
    x, y, t = np.asarray(pose, dtype=np.float64)
    lx, ly = np.asarray(landmark, dtype=np.float64)
    dx, dy = lx - x, ly - y
    return np.array([math.hypot(dx, dy), wrap_angle(math.atan2(dy, dx) - t)])


def observe_jacobians(pose: ArrayLike, landmark: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """d observe / d pose (2, 3) and d observe / d landmark (2, 2)."""
    x, y, _ = np.asarray(pose, dtype=np.float64)
    lx, ly = np.asarray(landmark, dtype=np.float64)
    dx, dy = lx - x, ly - y
    q = max(dx * dx + dy * dy, 1e-12)
    r = math.sqrt(q)
    jl = np.array([[dx / r, dy / r], [-dy / q, dx / q]])
    jx = np.hstack([-jl, np.array([[0.0], [-1.0]])])
    return jx, jl


def observation_to_landmark(pose: ArrayLike, z: ArrayLike) -> FloatArray:
    """Where a landmark seen at range and bearing ``z`` from ``pose`` lies (x, y)."""
    x, y, t = np.asarray(pose, dtype=np.float64)
    r, b = np.asarray(z, dtype=np.float64)
    return np.array([x + r * math.cos(t + b), y + r * math.sin(t + b)])


def observation_to_landmark_jacobians(pose: ArrayLike, z: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """d landmark / d pose (2, 3) and d landmark / d z (2, 2) of :func:`observation_to_landmark`."""
    _, _, t = np.asarray(pose, dtype=np.float64)
    r, b = np.asarray(z, dtype=np.float64)
    c, s = math.cos(t + b), math.sin(t + b)
    gx = np.array([[1.0, 0.0, -r * s], [0.0, 1.0, r * c]])
    gz = np.array([[c, -r * s], [s, r * c]])
    return gx, gz


def velocity_steer(pose: ArrayLike, control: ArrayLike, dt_s: float, wheelbase_m: float) -> FloatArray:
    """The velocity steer model: the pose after ``dt_s`` of driving at speed ``v`` (m/s) with the
    front wheel steered ``phi`` (rad) from the heading, the wheels ``wheelbase_m`` apart:
    x' = x + dt v cos(theta + phi), y' = y + dt v sin(theta + phi), theta' = theta + dt v sin(phi) / L."""
    x, y, t = np.asarray(pose, dtype=np.float64)
    v, phi = np.asarray(control, dtype=np.float64)
    return np.array([x + dt_s * v * math.cos(t + phi), y + dt_s * v * math.sin(t + phi),
                     wrap_angle(t + dt_s * v * math.sin(phi) / wheelbase_m)])


def velocity_steer_jacobians(pose: ArrayLike, control: ArrayLike, dt_s: float,
                             wheelbase_m: float) -> tuple[FloatArray, FloatArray]:
    """d velocity_steer / d pose (3, 3) and d velocity_steer / d (v, phi) (3, 2)."""
    _, _, t = np.asarray(pose, dtype=np.float64)
    v, phi = np.asarray(control, dtype=np.float64)
    c, s = math.cos(t + phi), math.sin(t + phi)
    fx = np.array([[1.0, 0.0, -dt_s * v * s], [0.0, 1.0, dt_s * v * c], [0.0, 0.0, 1.0]])
    fu = np.array([[dt_s * c, -dt_s * v * s], [dt_s * s, dt_s * v * c],
                   [dt_s * math.sin(phi) / wheelbase_m, dt_s * v * math.cos(phi) / wheelbase_m]])
    return fx, fu
