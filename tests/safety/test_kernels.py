"""Every safety kernel against its plain-numpy reference (cmdragons/safety/_reference.py)."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.control import acceleration as CK
from cmdragons.planning import collision as PK
from cmdragons.planning.world import CollisionWorld
from cmdragons.safety import _kernels as K
from cmdragons.safety import _reference as R
from cmdragons.safety import static_check

DT, ACCEL, BRAKE = 1 / 60, 3.0, 6.0


def random_trajectory(rng: np.random.Generator, spread: float = 1.0) -> np.ndarray:
    p = rng.uniform(-spread, spread, 2)
    v = rng.normal(0.0, 1.5, 2)
    a = rng.normal(0.0, 3.0, 2)
    return K.trajectory(p[0], p[1], v[0], v[1], a[0], a[1], DT, ACCEL, BRAKE)


def test_trajectory_reaches_the_command_holds_it_then_brakes_to_rest() -> None:
    # speeding up by 0.05 m/s at 3 m/s^2 takes the whole period
    tr = K.trajectory(0.0, 0.0, 2.0, 0.0, 3.0, 0.0, DT, ACCEL, BRAKE)
    v1 = 2.0 + 3.0 * DT
    assert tr[2, 0] == pytest.approx(DT) and tr[2, 1] == pytest.approx(DT + v1 / BRAKE)
    rest = 2.0 * DT + 1.5 * DT * DT + v1 * v1 / (2 * BRAKE)
    assert tr[3, 2] == pytest.approx(rest) and tr[3, 3] == 0.0
    np.testing.assert_allclose(R.positions(tr, np.array([tr[2, 1] + 1.0])), [[rest, 0.0]], atol=1e-12)
    # a small change is reached early and then held
    tr = K.trajectory(0.0, 0.0, 2.0, 0.0, 0.6, 0.0, DT, ACCEL, BRAKE)
    assert tr[0, 1] == pytest.approx(0.6 * DT / ACCEL) and tr[1, 4] == pytest.approx(2.0 + 0.6 * DT)
    # the stop brakes at full strength from the first instant: the rest point is v^2 / 2 brake away
    tr = K.trajectory(0.0, 0.0, 2.0, 0.0, *K.stop_accel(2.0, 0.0, DT), DT, ACCEL, BRAKE)
    assert tr[3, 2] == pytest.approx(4.0 / (2 * BRAKE))
    tr = K.trajectory(0.0, 0.0, 0.03, 0.04, *K.stop_accel(0.03, 0.04, DT), DT, ACCEL, BRAKE)
    np.testing.assert_allclose(tr[3, 2:4], np.array([0.03, 0.04]) * 0.05 / (2 * BRAKE), atol=1e-12)


def test_quartic_minimum_agrees_with_polynomial_roots() -> None:
    rng = np.random.default_rng(0)
    for _ in range(500):
        c = rng.normal(0.0, 1.0, 5)
        T = rng.uniform(0.01, 3.0)
        assert K.quartic_min(c, T) == pytest.approx(R.quartic_min(c, T), abs=1e-9)


@pytest.mark.parametrize("growth", [0.0, 0.3])
def test_pair_check_agrees_with_dense_sampling(growth: float) -> None:
    rng = np.random.default_rng(1)
    checked = 0
    for _ in range(600):
        ta, tb = random_trajectory(rng), random_trajectory(rng)
        radius = 0.21
        # a pair already closer only fails when it gets closer still; the kept distance grows at
        # ``growth`` until both rest, but never beyond the starting distance
        gap = R.pair_min_gap(ta, tb, radius, growth)
        if abs(gap) < 2e-3:
            continue  # sampling cannot decide grazing contacts
        assert K.pair_hits(ta, tb, radius, growth) == (gap < 0.0), gap
        checked += 1
    assert checked > 500


def test_opponent_check_agrees_with_dense_sampling() -> None:
    rng = np.random.default_rng(2)
    for _ in range(400):
        tr = random_trajectory(rng)
        opp = np.concatenate([rng.uniform(-1.5, 1.5, 2), rng.normal(0.0, 1.5, 2)])
        radius, accel = 0.23, rng.uniform(0.0, 4.0)
        start = float(np.hypot(*(tr[0, 2:4] - opp[:2])))
        limit = min(radius, start)
        gap = R.opponent_min_gap(tr, opp, accel)
        if abs(gap - limit) < 2e-3:
            continue
        assert K.opponent_hits(tr, *opp, radius, accel) == (gap < limit)


def test_static_check_is_conservative_by_at_most_one_step() -> None:
    # the check asks the collision world (boxes and circles grown by the robot radius)
    rng = np.random.default_rng(3)
    world = CollisionWorld((-1.49, -1.09, 1.49, 1.09), circles=np.array([[0.0, -0.5, 0.11], [-0.4, 0.6, 0.06]]),
                           boxes=np.array([[0.2, 0.2, 0.6, 0.5], [-0.9, -0.8, -0.5, -0.3]]))
    cw = world.compile(0.09)
    margin, step = 0.01, 0.02
    for _ in range(400):
        tr = random_trajectory(rng)
        c0 = PK.clearance(cw.obs, cw.inner, tr[0, 2], tr[0, 3])
        low = static_check.static_min_clearance(tr, cw.obs, cw.inner)
        need = min(margin, c0)
        hit = static_check.static_hits(tr, cw.obs, cw.inner, margin, step)
        if low < need - 1e-3:
            assert hit  # a real intrusion is always caught
        if low > need + step + 1e-3:
            assert not hit  # and the check is never stricter than one step
        start = np.array([[0, np.inf, *tr[0, 2:4], 0, 0, 0, 0]])
        assert c0 == pytest.approx(static_check.static_min_clearance(start, cw.obs, cw.inner, n=1))


def test_trajectory_state_follows_the_segments() -> None:
    rng = np.random.default_rng(4)
    for _ in range(100):
        tr = random_trajectory(rng)
        t = np.concatenate([rng.uniform(0.0, tr[3, 0] * 1.2, 20), [0.0, tr[3, 0] + 1.0]])
        got = np.array([CK.trajectory_state(tr, float(ti))[:2] for ti in t])
        np.testing.assert_allclose(got, R.positions(tr, t), atol=1e-12)
