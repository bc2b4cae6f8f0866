"""The dynamic window (Bruce 2006 §5.2): the kernel against its plain-numpy reference, its choice
admissible among robots standing still, and a match driven by it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from cmdragons.control import ControlParams
from cmdragons.control import acceleration as CK
from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import RobotState
from cmdragons.navigation import Arrival, DynamicWindowNavigator, DynamicWindowParams
from cmdragons.navigation import _dynamic_window_kernels as K
from cmdragons.navigation import _dynamic_window_reference as R
from cmdragons.navigation.dynamic_window import window_points
from cmdragons.planning import deadline, field_world
from cmdragons.runtime.match import Match
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.stages import TeamStage
from cmdragons.safety import _reference as SR

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
CONTROL = ControlParams()
M = CONTROL.motion
FIELD = Field(LeagueParams())
RADIUS = 0.09
PARAMS = DynamicWindowParams()
CFG = K.WindowConfig(M.period_s, PARAMS.margin_m, PARAMS.step_m, PARAMS.clearance_weight_1_s, PARAMS.clearance_cap_m)


@pytest.mark.slow
def test_kernel_agrees_with_the_reference() -> None:
    # every candidate the reference finds admissible with a step to spare is admissible to the kernel,
    # none it finds inadmissible is; the kernel's choice scores at least the best of the former
    rng = np.random.default_rng(0)
    window = window_points(PARAMS)
    checked = 0
    for _ in range(60):
        others = rng.uniform(-1.5, 1.5, (5, 2))
        cw = field_world(FIELD, others).compile(RADIUS)
        p = rng.uniform(-1.5, 1.5, 2)
        if cw.clearance(*p) < 0.0:
            continue
        v, want = rng.normal(0.0, 1.0, 2), rng.normal(0.0, 1.5, 2)
        vel, slack, score = R.window_scores(cw.obs, cw.inner, *p, *v, *want, window, M.limits(), CFG)
        vx, vy, evaluated, chosen = K.dynamic_window(cw.obs, cw.inner, *p, *v, *want, window, M.limits(), CFG, 10**6)
        assert evaluated == len(window) + 1
        sure = slack > PARAMS.step_m + 1e-3
        if chosen < 0:
            assert not sure.any() and (vx, vy) == (0.0, 0.0)
        else:
            assert slack[chosen] >= -1e-3  # admissible by dense sampling
            np.testing.assert_allclose((vx, vy), vel[chosen])
            if sure.any():
                assert score[chosen] >= score[sure].max() - 1e-9
        checked += 1
    assert checked > 40
    # a work budget of k candidates evaluates k, the wanted velocity first
    _, _, evaluated, chosen = K.dynamic_window(cw.obs, cw.inner, *p, *v, *want, window, M.limits(), CFG, 1)
    assert evaluated == 1 and chosen in (-1, 0)


def test_the_choice_stops_short_of_robots_standing_still() -> None:
    rng = np.random.default_rng(1)
    for _ in range(40):
        others = rng.uniform(-1.2, 1.2, (4, 2))
        world = field_world(FIELD, others)
        nav = DynamicWindowNavigator(PARAMS, CONTROL, RADIUS)
        p = rng.uniform(-1.2, 1.2, 2)
        gaps = np.hypot(*(others - p).T) - 2 * RADIUS
        if gaps.min() < PARAMS.margin_m:
            continue
        nav.set_plan(np.array([p, p + rng.normal(0.0, 2.0, 2)]), Arrival(0.0))
        robot = RobotState("blue", 0, float(p[0]), float(p[1]), 0.0, *rng.normal(0.0, 1.0, 2))
        vx, vy, _ = nav.command(robot, world, deadline(60.0))
        if nav.last_choice < 0:
            continue
        tr = CK.trajectory(*p, vx, vy, 0.0, 0.0, M.period_s, M.max_accel_m_s2, M.max_brake_m_s2)
        path = SR.positions(tr, SR.sample_times(tr))
        nearest = np.min(np.hypot(path[:, None, 0] - others[None, :, 0], path[:, None, 1] - others[None, :, 1]))
        assert nearest - 2 * RADIUS >= PARAMS.margin_m - 1e-3


def test_a_robot_in_front_is_not_sped_into() -> None:
    nav = DynamicWindowNavigator(PARAMS, CONTROL, RADIUS)
    nav.set_plan(np.array([(0.0, 0.0), (2.0, 0.0)]), Arrival(0.0))
    free = field_world(FIELD)
    vx, vy, _ = nav.command(RobotState("blue", 0, 0.0, 0.0, 0.0), free, deadline(60.0))
    assert vx == pytest.approx(M.max_accel_m_s2 * M.period_s) and vy == pytest.approx(0.0, abs=1e-9)
    assert nav.last_choice == 0  # the wanted velocity itself
    blocked = field_world(FIELD, [(0.6, 0.0)])
    vx, _, _ = nav.command(RobotState("blue", 0, 0.0, 0.0, 0.0, 2.5, 0.0), blocked, deadline(60.0))
    assert vx < 2.5 - 0.05


@pytest.mark.slow
def test_a_match_driven_by_the_dynamic_window_has_no_own_collision() -> None:
    # what `cmdragons play --set team.navigator=dynamic_window` runs (on truth, for speed)
    settings = load_settings(CONFIGS, ["team.navigator=dynamic_window"])
    match = Match(settings, "simple", "truth", seed=2)
    summary = match.run(15.0)
    assert summary["collisions"]["own"] == 0
    team = next(s for s in match.bus.stages if isinstance(s, TeamStage) and s.team == "blue")
    assert isinstance(next(iter(team.brain.navigators.values())), DynamicWindowNavigator)
    assert dataclasses.replace(settings.team, navigator="trajectory") == load_settings(CONFIGS).team
