"""The batched robot filter paths against one filterpy call per robot."""

from __future__ import annotations

import math

import numpy as np

from cmdragons.tracking.filters import (
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
