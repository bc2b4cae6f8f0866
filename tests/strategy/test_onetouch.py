"""One-touch aiming against the kick model."""

from __future__ import annotations

import math

import pytest

from strategy.onetouch import aim_heading, redirected_velocity


@pytest.mark.parametrize("v_in", [(0.0, -2.0), (-3.0, 1.0), (1.0, 2.5), (0.0, 0.0)])
@pytest.mark.parametrize("target", [0.0, 0.6, -1.2])
def test_aimed_kick_leaves_toward_the_target(v_in: tuple[float, float], target: float) -> None:
    h = aim_heading(target, v_in, kick_speed=5.0, retention=0.3)
    vx, vy = redirected_velocity(h, v_in, 5.0, 0.3)
    assert abs(math.remainder(math.atan2(vy, vx) - target, 2 * math.pi)) < 1e-5
    naive = redirected_velocity(target, v_in, 5.0, 0.3)
    across = -math.sin(target) * v_in[0] + math.cos(target) * v_in[1]
    if abs(across) > 0.1:  # aiming straight at the target would miss it
        assert abs(math.remainder(math.atan2(naive[1], naive[0]) - target, 2 * math.pi)) > 0.01


def test_no_retention_means_aim_straight() -> None:
    assert aim_heading(0.7, (1.0, -2.0), 5.0, 0.0) == 0.7
