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


def _ball_at_rest(sigma_m: float = 0.0003, frames: int = 60) -> BallFilter:
    """A ball at rest at (1.0, 0.5) tracked for ``frames`` frames of detections with noise ``sigma_m``."""
    ball = BallFilter(BallModelParams(), 1.0, 0.5, t=0.0)
    rng = np.random.default_rng(2)
    for k in range(1, frames):
        ball.predict(k * DT)
        ball.update(np.array([1.0, 0.5]) + rng.normal(0.0, sigma_m, 2), sigma_m=sigma_m)
    return ball


def test_a_detections_sigma_is_its_measurement_noise() -> None:
    # the same 3 mm jump moves the estimate far less when the detection says it is uncertain
    # (its sigma the update's R); without a sigma the configured one (0.4 mm) applies
    jumps = {}
    for sigma in (0.0003, 0.004, math.nan):
        ball = _ball_at_rest()
        ball.predict(60 * DT)
        ball.update(np.array([1.003, 0.5]), sigma_m=sigma)
        jumps[sigma] = float(ball.position[0]) - 1.0
    assert jumps[0.004] < 0.2 * jumps[0.0003]
    assert _ball_at_rest().measurement_var() == BallModelParams().measurement_sigma_m ** 2
    assert _ball_at_rest().measurement_var(0.004) == 0.004**2


def test_an_edge_cut_balls_jump_within_its_sigma_is_no_kick() -> None:
    # a ball at rest seen by one camera only, cut by its image's edge: 6 mm off, but vision says its
    # sigma is 5 mm; it is no kick and hardly moves the estimate. The same view without a sigma
    # (the configured 0.4 mm) is taken for a kick.
    ball = _ball_at_rest()
    ball.predict(60 * DT)
    assert not ball.update(np.array([1.006, 0.5]), sigma_m=0.005)
    assert abs(float(ball.position[0]) - 1.0) < 0.0005
    ball = _ball_at_rest()
    ball.predict(60 * DT)
    assert ball.update(np.array([1.006, 0.5]))


def test_a_more_certain_second_view_can_show_a_kick() -> None:
    # the first camera sees the ball half behind the kicker, uncertain and barely moved; the second
    # sees it clearly 15 mm on, kicked: the second view is not dropped, the kick is taken at once
    ball = _ball_at_rest()
    ball.predict(60 * DT)
    assert not ball.update(np.array([1.002, 0.5]), sigma_m=0.004)
    assert ball.update(np.array([1.015, 0.5]), sigma_m=0.0003)
    assert abs(float(ball.position[0]) - 1.015) < 0.001


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


def test_only_a_touching_robot_starts_a_new_slide() -> None:
    # a rolling ball passing a robot 0.14 m away (next to it: more process noise, no touch) keeps
    # rolling; one 0.11 m away touches it (0.09 m robot + 0.0215 m ball radius) and starts a slide
    p = BallModelParams()
    for robot_m, slides in ((0.14, False), (0.11, True), (math.inf, False)):
        ball = BallFilter(p, 0.0, 0.0, t=0.0)
        for k in range(1, 40):
            t = k * DT
            ball.predict(t)
            ball.update(np.array([0.8 * t - 0.13 * t * t, 0.0]), sigma_m=0.0003)
        rolling_from = ball.slide_start_speed
        assert math.isfinite(rolling_from)
        ball.predict(40 * DT, robot_m)
        assert (ball.slide_start_speed == math.inf) == slides


def test_a_kick_after_which_the_ball_moves_on_as_before_ends_the_slide() -> None:
    # a ball first seen rolling at 1.8 m/s: the filter has it sliding (a ball first seen may have
    # just been kicked) and falls behind, takes that for a kick, and then finds the ball moving
    # as before: the slide had ended, the ball rolls, and no further kicks follow
    ball = BallFilter(BallModelParams(), -1.0, 0.3, t=0.0)
    rng = np.random.default_rng(9)
    kicks = []
    for k in range(1, 240):
        t = k * DT
        ball.predict(t)
        z = np.array([-1.0 + 1.8 * t - 0.13 * t * t, 0.3]) + rng.normal(0.0, 0.0002, 2)
        if ball.update(z, sigma_m=0.0002):
            kicks.append(k)
    assert len(kicks) <= 1
    assert ball.slide_start_speed * BallModelParams().slide_to_roll_fraction >= math.hypot(*ball.velocity)
    assert abs(float(ball.velocity[0]) - (1.8 - 0.26 * 239 * DT)) < 0.02
