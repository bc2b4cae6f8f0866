"""The brain: own robots the tracker lost stay in the safety search and are stopped; a robot held
back keeps pressing on; the planner config is what its planners use; every params object of planning,
control, safety, navigation and the team checks its ranges."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from cmdragons.control import MotionParams, PathParams, TrapezoidParams
from cmdragons.messages import (
    BallState,
    Fact,
    FactEstimate,
    GameState,
    PhysicsFacts,
    RobotCommand,
    RobotState,
    WorldState,
)
from cmdragons.navigation import DynamicWindowParams, TrajectoryParams
from cmdragons.planning import (
    CollisionParams,
    CollisionWorld,
    CompiledWorld,
    DynamicPRMParams,
    ERRTParams,
    PlannerParams,
    VisGraphParams,
)
from cmdragons.planning.errt import SmoothingParams
from cmdragons.runtime.settings import load_settings
from cmdragons.safety import DSSParams, SafetyParams
from cmdragons.team import Brain, BrainParams, TeamParams
from strategy.skills import pass_speed

SETTINGS = load_settings(Path(__file__).resolve().parents[1] / "configs")
BALL = BallState(2.0, 1.0, 0.0, 0.0)


def world(t: float, *robots: RobotState) -> WorldState:
    return WorldState(t, BALL, robots)


def test_a_lost_robot_is_stopped_and_kept_where_it_brakes_to() -> None:
    brain = Brain("blue", SETTINGS)
    game = GameState(0.0)
    brain.step(world(0.0, RobotState("blue", 0, -1.0, 0.0, 0.0), RobotState("blue", 1, 0.0, 0.0, 0.0, 1.2, 0.0)),
               game)
    later = world(0.1, RobotState("blue", 0, -1.0, 0.0, 0.0))
    out = {c.id: c for c in brain.step(later, game).commands}
    assert (out[1].vx, out[1].vy, out[1].omega) == (0.0, 0.0, 0.0)
    brake = SETTINGS.control.motion.max_brake_m_s2
    (ghost,) = brain._lost_robots(later)
    # braking at full strength for 0.1 s from 1.2 m/s along +x
    assert ghost.x == pytest.approx(1.2 * 0.1 - 0.5 * brake * 0.01) and ghost.vx == pytest.approx(1.2 - brake * 0.1)
    (rest,) = brain._lost_robots(world(2.0, RobotState("blue", 0, -1.0, 0.0, 0.0)))
    assert rest.x == pytest.approx(1.2**2 / (2 * brake)) and rest.vx == pytest.approx(0.0, abs=1e-12)
    # seen again: no longer lost
    both = world(2.1, RobotState("blue", 0, -1.0, 0.0, 0.0), RobotState("blue", 1, 0.5, 0.0, 0.0))
    assert brain._lost_robots(both) == ()


def test_team_mates_do_not_drive_into_a_lost_robot() -> None:
    brain = Brain("blue", SETTINGS)
    safety = brain.safety
    ghost = RobotState("blue", 1, 0.3, 0.0, 0.0, visible=False)
    cmd = [RobotCommand("blue", 0, 2.0, 0.0), RobotCommand("blue", 1)]
    robot0 = RobotState("blue", 0, 0.0, 0.0, 0.0, 2.0, 0.0)
    blind = safety.make_safe(cmd[:1], world(0.0, robot0))
    assert blind[0].vx == pytest.approx(2.0)  # without the lost robot nothing is in the way
    seen = safety.make_safe(cmd, world(0.0, robot0, ghost))
    assert seen[0].vx < 2.0


def test_a_robot_held_back_keeps_pressing_on() -> None:
    # a robot that does not move (an opponent holds it) is told, frame after frame, to go on toward
    # its goal (the goalie's place, far away): its command grows by the acceleration limit each
    # frame, as if it moved
    def speed(brain: Brain, frames: int) -> float:
        held = RobotState("blue", 3, 0.0, 0.0, 0.0)
        cmds = [brain.step(world(k / 60, held), GameState(0.0)).commands[0] for k in range(frames)]
        return float(np.hypot(cmds[-1].vx, cmds[-1].vy))

    accel = SETTINGS.control.motion.max_accel_m_s2
    slip = SETTINGS.team.navigator_sections["trajectory"].command_slip_m_s
    assert speed(Brain("blue", SETTINGS), 10) == pytest.approx(min(10 * accel / 60, slip), rel=0.05)
    # from the measured velocity alone: one frame of acceleration from rest, each time
    no_slip = dataclasses.replace(SETTINGS.team.navigator_sections["trajectory"], command_slip_m_s=0.0)
    restarting = Brain("blue", SETTINGS, SETTINGS.team.with_section("trajectory", no_slip))
    assert speed(restarting, 10) == pytest.approx(accel / 60, rel=0.05)


@pytest.mark.parametrize(
    ("override", "expect"),
    [("planner.collision.broad_phase=aabb_tree", lambda t1, p: p.broad_phase == "aabb_tree"),
     ("planner.collision.mask_bins=7", lambda t1, p: p.mask_bins == 7),
     ("planner.horizon_s=0.4", lambda t1, p: t1 == 0.4)],
)
def test_the_brains_planners_answer_to_the_planner_config(
    monkeypatch: pytest.MonkeyPatch, override: str, expect: Callable[[float, CollisionParams], bool]
) -> None:
    # what `cmdragons play --set ...` loads is what the brain's planners compile their worlds with
    settings = load_settings(Path(__file__).resolve().parents[1] / "configs", [override])
    seen: list[tuple[float, CollisionParams]] = []
    compile_world = CollisionWorld.compile

    def spy(self: CollisionWorld, radius_m: float, t0_s: float = 0.0, t1_s: float = 0.0,
            params: CollisionParams | None = None) -> CompiledWorld:
        seen.append((t1_s, params or CollisionParams()))
        return compile_world(self, radius_m, t0_s, t1_s, params)

    brain = Brain("blue", settings)  # (its safety search compiles the static field with its own radius)
    monkeypatch.setattr(CollisionWorld, "compile", spy)
    robots = (RobotState("blue", 0, -3.0, 0.0, 0.0), RobotState("blue", 1, 0.0, 1.0, 0.0),
              RobotState("yellow", 0, -1.0, 0.0, 0.0))
    brain.step(world(0.0, *robots), GameState(0.0))
    assert seen and all(expect(t1, p) for t1, p in seen)
    assert not expect(0.0, CollisionParams())  # the override differs from the default


@pytest.mark.parametrize(
    ("cls", "field", "bad"),
    [(ERRTParams, "step_m", 0.0), (SmoothingParams, "passes", -1), (DynamicPRMParams, "work_budget", 0),
     (VisGraphParams, "arc_check_step_deg", 0.0), (CollisionParams, "grid_resolution_m", 0.0),
     (CollisionParams, "broad_phase", "octree"), (PlannerParams, "deadline_ms", 0.0),
     (PlannerParams, "planner", "astar"), (MotionParams, "max_brake_m_s2", 0.0),
     (PathParams, "corner_overshoot_m", 0.0), (TrapezoidParams, "split_iterations", 1),
     (DSSParams, "own_margin_m", -0.1), (SafetyParams, "method", "dynamic_window"),
     (TrajectoryParams, "command_slip_m_s", -1.0), (DynamicWindowParams, "directions", 2),
     (BrainParams, "navigate_deadline_ms", 0.0), (TeamParams, "navigator", "magic")],
)
def test_params_check_their_ranges_however_they_are_built(cls: type, field: str, bad: object) -> None:
    with pytest.raises(ValueError, match=field):
        cls(**{field: bad})
    cls()  # the defaults are in range


def test_the_braking_paths_dss_checked_are_kept_for_the_video() -> None:
    brain = Brain("blue", SETTINGS)
    robots = (RobotState("blue", 0, -1.0, 0.0, 0.0, 1.5, 0.0), RobotState("blue", 2, 1.0, 1.0, 0.0, 0.0, -1.0),
              RobotState("yellow", 0, 0.0, -2.0, 0.0))
    out = brain.step(world(0.0, *robots), GameState(0.0))
    assert sorted(out.braking) == [0, 2]  # our robots only
    for r in robots[:2]:
        path = out.braking[r.id]
        assert path.ndim == 2 and path.shape[1] == 2
        np.testing.assert_allclose(path[0], (r.x, r.y))  # from where the robot is ...
        # ... along its velocity to where it rests: moving at most the command's period plus braking
        reach = np.hypot(r.vx, r.vy) + 0.1
        assert np.hypot(*(path[-1] - (r.x, r.y))) <= reach**2 / (2 * SETTINGS.control.motion.max_brake_m_s2) + 0.1


def test_the_brains_output_holds_only_the_robots_in_the_frame_and_the_pass_evaluation_when_redone() -> None:
    brain = Brain("blue", SETTINGS)
    game = GameState(0.0, command="normal")
    both = (RobotState("blue", 0, -1.0, 0.0, 0.0), RobotState("blue", 1, 0.0, 1.0, 0.0),
            RobotState("yellow", 0, 1.0, 0.0, 0.0))
    first = brain.step(world(0.0, *both), game)
    assert sorted(first.plans) == [0, 1] and {c.id for c in first.commands} == {0, 1}
    assert first.pass_heat is not None  # the first frame evaluates the passes
    gone = brain.step(world(1 / 60, both[0], both[2]), game)  # robot 1 left the field (or the cameras' view)
    assert sorted(gone.plans) == [0]
    assert set(gone.last_actions) <= {0}
    assert {c.id for c in gone.commands} == {0, 1}  # (robot 1 is still told to stop)
    every = SETTINGS.strategy.support.eval_every_frames
    heats = [brain.step(world(k / 60, both[0], both[2]), game).pass_heat is not None for k in range(2, 2 + 2 * every)]
    assert sum(heats) == 2  # redone every eval_every_frames frames, and only then in the output


def test_every_planner_status_is_a_robot_plan_status_of_the_same_value() -> None:
    from cmdragons.planning import PlanStatus
    from cmdragons.team import RobotPlanStatus

    for status in PlanStatus:
        assert RobotPlanStatus.planned(status).value == status.value
    assert {s.value for s in RobotPlanStatus} - {s.value for s in PlanStatus} == {"halt", "direct", "escape"}


def _facts(*used: tuple[Fact, float]) -> PhysicsFacts:
    return PhysicsFacts(5.0, tuple(FactEstimate(f, v, 0.0, 40, 0.01, True, True) for f, v in used))


def test_a_learnt_braking_replaces_the_configured_one_in_control_and_safety() -> None:
    brain = Brain("blue", SETTINGS)
    brain.use_physics(PhysicsFacts(1.0))  # nothing in use: the configuration as it is
    assert brain.settings is SETTINGS
    brain.use_physics(_facts((Fact.ROBOT_BRAKE, 4.0)))
    assert brain.settings.control.motion.max_brake_m_s2 == 4.0
    assert brain.configured.control.motion.max_brake_m_s2 == SETTINGS.control.motion.max_brake_m_s2
    assert brain.settings.control.motion.max_accel_m_s2 == SETTINGS.control.motion.max_accel_m_s2
    game = GameState(0.0)
    brain.step(world(0.0, RobotState("blue", 0, -1.0, 0.0, 0.0), RobotState("blue", 1, 0.0, 0.0, 0.0, 1.2, 0.0)),
               game)
    (rest,) = brain._lost_robots(world(2.0, RobotState("blue", 0, -1.0, 0.0, 0.0)))
    assert rest.x == pytest.approx(1.2**2 / (2 * 4.0))  # a lost robot brakes as measured


def _arrival(kick_m_s: float, distance_m: float, acc_roll_m_s2: float) -> float:
    """The speed (m/s) a ball kicked at ``kick_m_s`` has after ``distance_m`` in our simulator with its
    rolling deceleration set to ``acc_roll_m_s2``; 0 when it stops short."""
    from cmdragons.geometry import LeagueParams
    from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World

    w = World(LeagueParams(), PhysicsParams(), RobotParams(), BallParams(acc_roll_m_s2=acc_roll_m_s2), KickerParams(),
              DribblerParams(), robots_per_team={"blue": 0, "yellow": 0})
    w.place_ball(-2.0, 0.0, vx=kick_m_s)
    for _ in range(60 * 20):
        snap = w.snapshot()
        if snap.ball[0] >= -2.0 + distance_m:
            return float(math.hypot(snap.ball[3], snap.ball[4]))
        w.step_frame()
    return 0.0


def test_the_pass_model_takes_the_ball_deceleration_learnt_in_a_slower_simulator() -> None:
    from tests.tracking.test_physics import rolled_balls

    learnt = rolled_balls(0.70).physics  # the tracker's view of a simulator whose ball rolls out at 0.70 m/s²
    brain = Brain("blue", SETTINGS)
    brain.use_physics(learnt)
    skills = brain.settings.strategy.skills
    assert skills.acc_roll_m_s2 == pytest.approx(0.70, rel=0.10)
    assert brain.strategy.p.skills == skills
    want = skills.pass_arrival_m_s
    # a 3 m pass kicked as the learnt model says arrives about as meant; as the configured one says, too slow
    assert _arrival(pass_speed(3.0, skills), 3.0, 0.70) == pytest.approx(want, abs=0.15)
    assert _arrival(pass_speed(3.0, SETTINGS.strategy.skills), 3.0, 0.70) < want - 0.3


def test_a_kickers_gain_learnt_asks_the_kicker_that_much_more() -> None:
    from strategy.skills import Intent
    from tests.tracking.test_physics import scripted_kicks

    learnt = scripted_kicks(0.75).physics  # the tracker's view of a kicker whose ball leaves at 0.75 of the kick
    brain = Brain("blue", SETTINGS)
    robot = RobotState("blue", 0, -1.0, 0.0, 0.0)
    kick = {0: Intent(-1.0, 0.0, 0.0, kick_speed=3.0)}  # at rest, the ball asked at 3 m/s
    (before,) = brain.drive(world(0.0, robot), kick, GameState(0.0))
    assert before.kick_speed == pytest.approx(3.0)
    brain.use_physics(learnt)
    assert brain.settings.control.motion.kick_gain == pytest.approx(0.75, rel=0.05)
    (after,) = brain.drive(world(0.1, robot), kick, GameState(0.0))
    assert after.kick_speed == pytest.approx(3.0 / brain.settings.control.motion.kick_gain)
