"""The match report and the summary's warnings, from a run's own MCAP log or gathered as the match runs."""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from cmdragons.messages import (
    BallState,
    BallTruth,
    GameState,
    Goal,
    GroundTruth,
    Kick,
    KickPurpose,
    RobotState,
    RobotTruth,
    SimEvents,
    TeamReport,
    WorldState,
)
from cmdragons.runtime.log import RunLog, read_log
from cmdragons.runtime.match import Match
from cmdragons.runtime.report import ReportStage, load_run, run_warnings, write_report
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.stages import LoggerStage, Tap


def write_log(path: Path, frames: int, ball_visible_every: int, robot_1_visible: bool, hidden: bool = False) -> None:
    """A play log as the match's bus writes it; the ball unseen in all but every ``ball_visible_every``-th
    frame: lost (no ball in the world state) or, ``hidden``, tracked unseen (in a robot's mouth)."""
    with RunLog(path) as log:
        for i in range(frames):
            t = i / 60
            robots = tuple(RobotTruth("blue", k, -1.0 + k, 0.0, 0.0, 0.0, 0.0, 0.0) for k in (0, 1)) + (
                RobotTruth("yellow", 0, 2.0, 0.5, 0.0, 0.0, 0.0, 0.0),)
            ball_truth = BallTruth(-0.9 + 0.01 * i, 0.0, 0.0215, 0.0, 0.0)
            log.write("/truth", t, GroundTruth(i, t, ball_truth, robots))
            log.write("/referee", t, GameState(t, score_blue=int(i > frames // 2)))
            seen = (RobotState("blue", 0, -1.0, 0.0, 0.0),) + ((RobotState("blue", 1, 0.0, 0.0, 0.0),)
                                                               if robot_1_visible else ())
            visible = i % ball_visible_every == 0
            ball = BallState(0.0, 0.0, 0.0, 0.0, visible=visible) if visible or hidden else None
            log.write("/world/blue", t, WorldState(t, ball, seen, i))
            log.write("/report/blue", t, TeamReport("blue", i, t, actions={0: KickPurpose.SHOT}))
            kicks = (Kick(t, "blue", 0, 3.0, False),) if i == 30 else ()
            log.write("/events", t, SimEvents(i, t, (0.0, 0.0), kicks))


def test_ball_seldom_and_a_robot_never_seen_are_warned(tmp_path: Path) -> None:
    write_log(tmp_path / "run.mcap", 120, ball_visible_every=4, robot_1_visible=False)
    run = load_run(tmp_path / "run.mcap")
    assert run.frames == 120
    assert run.ball_seen == pytest.approx(0.25)
    assert run.robot_seen == {0: 1.0, 1: 0.0}
    assert run.possession[0] == "blue" and run.kicks[0]["action"] == "shot"
    summary = {"perception": "vision", "command_faults": {"clamped": 1}, "realtime_factor": 0.8}
    warnings = run_warnings(run, summary)
    assert any("ball seldom (25 % of the frames) (seen in 25 %)" in w for w in warnings)
    assert any("robot 1 never" in w for w in warnings)
    assert not any("robot 0" in w for w in warnings)
    assert any(w.startswith("1 command was clamped") for w in warnings)
    assert any("slower than real time (0.8x)" in w for w in warnings)  # nothing compiled: no compile named
    compiled = run_warnings(run, {**summary, "compile_seconds": 20.0})
    assert any("slower than real time (0.8x, not counting the first-run compile)" in w for w in compiled)


def test_a_ball_hidden_in_a_robots_mouth_is_no_warning(tmp_path: Path) -> None:
    write_log(tmp_path / "run.mcap", 120, ball_visible_every=4, robot_1_visible=True, hidden=True)
    run = load_run(tmp_path / "run.mcap")
    assert run.ball_seen == pytest.approx(0.25) and run.ball_tracked == 1.0
    summary = {"perception": "vision", "command_faults": {"clamped": 0}, "realtime_factor": 1.5}
    assert run_warnings(run, summary) == []


def test_a_clean_run_has_no_warning(tmp_path: Path) -> None:
    write_log(tmp_path / "run.mcap", 60, ball_visible_every=1, robot_1_visible=True)
    run = load_run(tmp_path / "run.mcap")
    summary = {"perception": "vision", "command_faults": {"clamped": 0}, "realtime_factor": 1.5}
    assert run_warnings(run, summary) == []


def test_report_png_is_one_page(tmp_path: Path) -> None:
    write_log(tmp_path / "run.mcap", 120, ball_visible_every=1, robot_1_visible=True)
    summary = json.loads(json.dumps({
        "score": {"blue": 1, "yellow": 0}, "seconds": 2.0, "opponent": "simple", "perception": "vision", "seed": 1,
        "passes": {"tried": 1, "completed": 0, "ends": {"late": 1},
                   "list": [{"t_kick": 0.5, "passer": 1, "receiver": 2, "target": [1.0, 1.0], "speed_m_s": 2.0,
                             "ball_s": 0.6, "receiver_s": None, "opponent_s": 0.9, "end": "late"}]},
        "realtime_factor": 1.2, "compile_seconds": 0.0,
        "cycle_ms": {"vision": {"median": 1.5, "p95": 2.0}, "brain": {"median": 2.0, "p95": 4.0}},
    }))
    path = write_report(load_run(tmp_path / "run.mcap"), summary, tmp_path / "report.png")
    img = cv2.imread(str(path))
    assert img is not None and img.shape == (1400, 1400, 3)


@pytest.mark.slow
def test_the_report_stage_gathers_what_the_log_reads_back(tmp_path: Path) -> None:
    settings = load_settings(Path(__file__).resolve().parents[2] / "configs")
    log = RunLog(tmp_path / "run.mcap")
    report = ReportStage("blue")
    Match(settings, "simple", "truth", seed=2, extra=[LoggerStage(log), report]).run(3.0)
    log.close()
    live, back = report.collector.result(), load_run(tmp_path / "run.mcap")
    assert live.frames == back.frames == 180
    np.testing.assert_array_equal(live.t, back.t)
    np.testing.assert_array_equal(live.ball, back.ball)
    assert live.traces.keys() == back.traces.keys()
    for key, trace in live.traces.items():
        np.testing.assert_array_equal(trace, back.traces[key])
    assert (live.possession, live.kicks, live.goals, live.score_t) == (back.possession, back.kicks, back.goals,
                                                                       back.score_t)
    assert (live.ball_seen, live.ball_tracked, live.robot_seen) == (back.ball_seen, back.ball_tracked, back.robot_seen)
    assert live.kicks  # the match kicked: the comparison covers the kick events


@pytest.mark.parametrize(("side", "scorer"), [(-1.0, "blue"), (1.0, "yellow")])
def test_a_goal_after_half_time_is_the_scorers_in_summary_report_and_log(tmp_path: Path, side: float,
                                                                         scorer: str) -> None:
    # halves of 1 s: blue defends -x in the first, +x in the second (the sides change); in the second
    # the ball is rolled into the goal at x of sign ``side``, away from every robot
    settings = load_settings(Path(__file__).resolve().parents[2] / "configs",
                             ["sim.referee.figures.half_s=1.0", "sim.referee.figures.half_time_s=0.5"])
    log = RunLog(tmp_path / "run.mcap")
    report = ReportStage("blue")
    match = Match(settings, "none", "truth", seed=1, extra=[LoggerStage(log), report])
    games: list[GameState] = []
    match.bus.add(Tap("test:referee", ("referee",), lambda _t, g: games.append(g)))
    while not games or games[-1].stage != "second_half":
        match.step()
    assert not games[-1].blue_defends_negative_x  # blue defends +x now
    match.sim.world.place_ball(side * (match.sim.world.field.half_length - 0.1), 0.3, vx=side * 3.0)
    match.run(0.5)
    summary = match.summary()
    log.close()
    assert summary["score"] == {"blue": int(scorer == "blue"), "yellow": int(scorer == "yellow")}
    goals = [e for _topic, _t, ev in read_log(tmp_path / "run.mcap", {"/events"}) for e in ev.events
             if isinstance(e, Goal)]
    assert [(g.scoring_team, math.copysign(1.0, g.x)) for g in goals] == [(scorer, side)]
    for run in (report.collector.result(), load_run(tmp_path / "run.mcap")):
        assert [g["scoring_team"] for g in run.goals] == [scorer]
        assert run.score_t[-1][1:] == (summary["score"]["blue"], summary["score"]["yellow"])
