"""Trapezoidal profiles (Bruce 2006 B.4) against closed forms, a dense search over peak velocities
and step-by-step integration.

``duration_s`` is the profile's planned travel time (the robot's, in the simulated world), the
quantity the profile minimises; nothing here measures how long the code takes to run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.control import _reference as R
from cmdragons.control import trapezoid_1d, trapezoid_2d


def triangle_s(d: float, a: float = 3.0, b: float = 6.0) -> float:
    """Rest to rest over |d| without reaching the speed limit: peak v with v^2/2a + v^2/2b = |d|."""
    v = math.sqrt(2.0 * abs(d) * a * b / (a + b))
    return v / a + v / b


@pytest.mark.parametrize(
    ("d", "v0", "vmax", "a", "b", "expected_s"),
    [
        # rest to rest, the speed limit reached: accelerate, cruise, brake
        (4.0, 0.0, 3.0, 3.0, 6.0, 3.0 / 3.0 + 3.0 / 6.0 + (4.0 - 9.0 / 6.0 - 9.0 / 12.0) / 3.0),
        # rest to rest, a triangle: peak v with v^2/2a + v^2/2b = d
        (0.5, 0.0, 3.0, 3.0, 6.0, triangle_s(0.5)),
        (-0.5, 0.0, 3.0, 3.0, 6.0, triangle_s(0.5)),
        # already cruising at the limit: cruise then brake
        (5.0, 3.0, 3.0, 3.0, 6.0, (5.0 - 9.0 / 12.0) / 3.0 + 0.5),
        # moving away from the target: brake to zero, come back as a triangle
        (0.0, -2.0, 3.0, 3.0, 6.0, 2.0 / 6.0 + triangle_s(4.0 / 12.0)),
        # too fast to stop in time: brake through the target and come back
        (0.1, 3.0, 3.0, 3.0, 6.0, 0.5 + triangle_s(0.75 - 0.1)),
        # nothing to do
        (0.0, 0.0, 3.0, 3.0, 6.0, 0.0),
    ],
)
def test_1d_time_equals_the_closed_form(
    d: float, v0: float, vmax: float, a: float, b: float, expected_s: float
) -> None:
    p = trapezoid_1d(d, v0, 0.0, vmax, a, b)
    assert p.duration_s == pytest.approx(expected_s, abs=1e-9)
    x, v = p.state(p.duration_s)
    assert x == pytest.approx(d, abs=1e-9)
    assert v == pytest.approx(0.0, abs=1e-9)


def test_1d_is_time_optimal_reaches_target_and_keeps_limits() -> None:
    rng = np.random.default_rng(3)
    for _ in range(150):
        d, v0 = rng.uniform(-5, 5), rng.uniform(-4, 4)
        vmax, a, b = rng.uniform(0.3, 3), rng.uniform(0.5, 6), rng.uniform(0.5, 8)
        vt = 0.0 if rng.random() < 0.5 else rng.uniform(-vmax, vmax)
        p = trapezoid_1d(d, v0, vt, vmax, a, b)
        ref = R.profile_time(d, v0, vt, vmax, a, b, n=20001)
        # no peak velocity of the dense grid does better; the grid's best is within its resolution
        assert p.duration_s <= ref + 1e-9
        assert ref <= p.duration_s + 0.01 * max(1.0, p.duration_s)
        # integrated with small steps, the phases end at the target with the target velocity
        used = p.phases[p.phases[:, 0] > 0]
        left, v_end, _ = R.simulate_1d(d, v0, used, 4000)
        assert abs(left) < 1e-6 and abs(v_end - vt) < 1e-9
        # every phase keeps its limit: speeding up at most a, slowing down at most b, |v| <= vmax
        v = v0
        for duration, acc in used:
            v_next = v + acc * duration
            speeding_up = abs(v_next) > abs(v) + 1e-12 and (v * v_next >= 0 or abs(v) < 1e-9)
            assert abs(acc) <= (a if speeding_up else b) + 1e-9
            assert abs(v_next) <= max(vmax, abs(v0)) + 1e-9
            v = v_next


def test_zero_limits_mean_never_unless_already_there() -> None:
    assert trapezoid_1d(1.0, 0.0, 0.0, 3.0, 0.0, 6.0).duration_s == math.inf
    assert trapezoid_1d(0.0, 0.0, 0.0, 0.0, 0.0, 0.0).duration_s == 0.0


@pytest.mark.parametrize(
    ("delta", "v0", "vt"),
    [((3.0, 1.0), (0.0, 0.0), (0.0, 0.0)), ((-2.0, 2.5), (1.5, -1.0), (0.0, 0.0)),
     ((0.2, -4.0), (2.0, 0.0), (0.0, 0.0)), ((1.0, 1.0), (0.0, 0.0), (1.0, 0.5)),
     ((0.0, 2.0), (1.0, 0.0), (0.0, 0.0))],
)
def test_2d_axes_arrive_together_at_the_target(
    delta: tuple[float, float], v0: tuple[float, float], vt: tuple[float, float]
) -> None:
    p = trapezoid_2d(delta, v0, vt, 3.0, 3.0, 6.0)
    assert p.x.duration_s == pytest.approx(p.y.duration_s, rel=1e-6)
    dx, dy, vx, vy = p.state(p.duration_s)
    assert (dx, dy, vx, vy) == pytest.approx((*delta, *vt), abs=1e-6)
    # the split keeps the 2D speed limit and never beats the unsplit 1D time of the longer axis
    c, s = math.cos(p.theta), math.sin(p.theta)
    assert math.hypot(3.0 * c, 3.0 * s) == pytest.approx(3.0)
    assert p.duration_s >= max(trapezoid_1d(delta[0], v0[0], vt[0], 3, 3, 6).duration_s,
                               trapezoid_1d(delta[1], v0[1], vt[1], 3, 3, 6).duration_s) - 1e-9
