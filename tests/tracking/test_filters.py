"""The batched robot filter paths against one filterpy call per robot."""

from __future__ import annotations

import math

import numpy as np

from cmdragons.tracking.filters import (
    BallFilter,
    BallModelParams,
    RobotFilter,
    RobotModelParams,
    SteadyUpdates,
    predict_robots,
    predicted_states,
)

DT = 1.0 / 60.0


def test_batched_robots_equal_one_call_per_robot() -> None:
    p = RobotModelParams(steady_after_updates=10)
    rng = np.random.default_rng(3)
    starts = rng.uniform(-2.0, 2.0, (5, 3))
    one = [RobotFilter(p, *s, t=0.0) for s in starts]
    batched = [RobotFilter(p, *s, t=0.0) for s in starts]
    updates = SteadyUpdates()
    steady: list[tuple[RobotFilter, tuple[float, float, float]]] = []
    entered = False
    for k in range(1, 80):
        t = k * DT
        for f in one:
            f.predict(t)
        predict_robots(batched, t)
        for i, (a, b) in enumerate(zip(one, batched, strict=True)):
            if k % 17 == 5 and i == 1:  # a missed frame: robot 1 leaves steady-state mode
                a.miss()
                b.miss()
                continue
            # moving at 1 m/s and turning through the wrap-around at +-pi
            z = starts[i] + np.array([t, -0.5 * t, 3.0 * t]) + rng.normal(0.0, 0.0005, 3)
            z[2] = math.remainder(z[2], 2.0 * math.pi)
            entered |= b.steady_pending
            a.update(z)
            if b.steady_pending:
                steady.append((b, (float(z[0]), float(z[1]), float(z[2]))))
            else:
                b.update(z)
        taken = updates.take([f for f, _ in steady], [z for _, z in steady], gate_chi2=60.0)
        assert taken.all()
        steady.clear()
        for a, b in zip(one, batched, strict=True):
            assert np.allclose(a.kf.x, b.kf.x, rtol=0.0, atol=1e-12)
    assert entered
    states = predicted_states(batched, 80 * DT + 0.03, [()] * len(batched))
    for a, row in zip(one, states, strict=True):
        assert np.allclose(a.predicted_state(80 * DT + 0.03), row, rtol=0.0, atol=1e-12)


def test_batched_gate_rejects_as_one_robot_does() -> None:
    p = RobotModelParams(steady_after_updates=5)
    filters = [RobotFilter(p, 0.0, float(i), 0.0, t=0.0) for i in range(3)]
    for k in range(1, 12):
        predict_robots(filters, k * DT)
        for f in filters:
            f.update(np.array([0.0, f.kf.x[1], 0.0]))
    predict_robots(filters, 12 * DT)
    assert all(f.steady_pending for f in filters)
    z = [(0.0, 0.0, 0.0), (0.3, 1.0, 0.0), (0.0, 2.0, 2.0)]  # robot 1 a far jump, robot 2 turned round
    gate = 60.0
    expected = [f.nis(zi) <= gate for f, zi in zip(filters, z, strict=True)]
    assert expected == [True, False, False]
    taken = SteadyUpdates().take(filters, z, gate)
    assert taken.tolist() == expected
    assert not filters[0].steady_pending and filters[1].steady_pending and filters[2].steady_pending


def test_ball_steady_state_mode_agrees_with_full_updates() -> None:
    # once the gain has settled, filterpy's steady-state mode gives the full filter's estimates
    settled = BallFilter(BallModelParams(measurement_sigma_m=0.0016, steady_after_updates=30), -2.0, 0.0, t=0.0)
    full = BallFilter(BallModelParams(measurement_sigma_m=0.0016, steady_after_updates=100000), -2.0, 0.0, t=0.0)
    rng = np.random.default_rng(4)
    entered = False
    for k in range(1, 150):
        t = k * DT
        # kicked at 2 m/s at t = 0: the two-phase model, sliding at 3 m/s^2 down to 0.64 x 2 m/s, then rolling
        x = -2.0 + 2.0 * t - 1.5 * t * t if t < 0.24 else -1.6064 + 1.28 * (t - 0.24) - 0.13 * (t - 0.24) ** 2
        z = np.array([x, 0.0]) + rng.normal(0.0, 0.0016, 2)
        for f in (settled, full):
            f.predict(t, near_robot=20 <= k < 25)  # a robot passes by: a different model for 5 frames
            f.update(z)
        entered |= settled._steady is not None
        assert np.allclose(settled.position, full.position, rtol=0.0, atol=1e-6)
        assert np.allclose(settled.velocity, full.velocity, rtol=0.0, atol=1e-4)
    assert entered and full._steady is None


def test_a_second_view_of_one_instant_that_does_not_fit_is_dropped() -> None:
    # a ball at rest seen by two cameras: the second camera's view 10 mm off (the ball cut by its
    # image's edge) cannot be a kick, since the first camera saw the ball where it was
    ball = BallFilter(BallModelParams(), 1.0, 0.5, t=0.0)
    rng = np.random.default_rng(2)
    for k in range(1, 60):
        ball.predict(k * DT)
        ball.update(np.array([1.0, 0.5]) + rng.normal(0.0, 0.0004, 2))
    t = 60 * DT
    ball.predict(t)
    assert not ball.update(np.array([1.0, 0.5]))
    assert not ball.update(np.array([1.01, 0.5]))
    assert np.allclose(ball.position, [1.0, 0.5], atol=0.001)
    assert np.linalg.norm(ball.velocity) < 0.05
    # a kick seen first by one camera and then by the other: both views fit the kick, kept
    ball.predict(t + DT)
    assert ball.update(np.array([1.03, 0.5]))
    assert not ball.update(np.array([1.03, 0.5]))
    assert np.allclose(ball.position, [1.03, 0.5], atol=0.001)
