"""``cmdragons bench league``: what a row reads from a match's log (goals in the simulator's own
vision and truth, stoppages), against sequences whose answer is known by construction; the peers
looked for and, when absent, skipped with the reason; and the served simulator's row played as the
suite plays it (two processes, our autoref refereeing), its figures checked against the served truth."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import pytest

from cmdragons.bench.league import (
    PEERS,
    Stoppages,
    ball_in_play_m,
    first_start,
    match_row,
    peer_script,
    rules_stoppage_s,
    stoppages,
    truth_clock_offset,
    truth_goals,
    vision_goals,
)
from cmdragons.messages import (
    BallDetection,
    BallState,
    BallTruth,
    DetectionFrame,
    GameStage,
    GameState,
    GroundTruth,
    RefereeCommand,
    WorldState,
)
from cmdragons.runtime.settings import load_settings

FIELD = load_settings().field_geometry()  # Division B: 9 x 6 m, goals 1 m wide
PAST_GOAL_X = FIELD.half_length + 0.1  # a ball this far out is past the goal line (radius 21.5 mm)


def _frame(t: float, x: float, y: float) -> tuple[str, DetectionFrame]:
    return "ssl/vision/0", DetectionFrame(0, round(t * 60), t, t, (BallDetection(x, y, 0.9, (0.0, 0.0)),))


def _game(t: float, command: RefereeCommand, blue_negative: bool = True) -> tuple[str, GameState]:
    return "referee", GameState(t, command, blue_defends_negative_x=blue_negative)


def test_goals_in_vision_are_crossings_between_the_posts_while_in_play_scored_by_the_sides_then() -> None:
    stream = [
        _game(0.0, RefereeCommand.NORMAL),
        _frame(1.0, 4.0, 0.1), _frame(1.1, PAST_GOAL_X, 0.1),  # into the +x goal: blue defends -x, blue scores
        _frame(1.2, PAST_GOAL_X + 0.05, 0.1),  # still in it: the same goal
        _frame(2.0, 0.0, 0.0),  # back on the centre spot
        _frame(3.0, PAST_GOAL_X, 1.5),  # past the goal line beside the post: out, no goal
        _frame(4.0, 0.0, 0.0),
        _game(4.5, RefereeCommand.STOP),
        _frame(5.0, -PAST_GOAL_X, 0.0),  # into the -x goal while play is stopped: not a goal
        _frame(6.0, 0.0, 0.0),
        _game(7.0, RefereeCommand.NORMAL, blue_negative=False),  # the sides changed: blue defends +x
        _frame(8.0, -PAST_GOAL_X, -0.3),  # into the -x goal: blue scores again
        _frame(9.0, 0.0, 0.0),
        _game(9.5, RefereeCommand.STOP, blue_negative=False),
        _game(9.6, RefereeCommand.NORMAL, blue_negative=False),
        _frame(10.0, PAST_GOAL_X, 0.2),  # into the +x goal, blue's own: yellow scores
    ]
    assert vision_goals(stream, FIELD) == {"blue": 2, "yellow": 1}


def test_a_ball_seen_in_the_goal_out_and_in_again_before_the_referee_stops_play_is_one_goal() -> None:
    """As in a served Division A match: the ball seen 2 cm past the goal line, back on it, then in for good
    (the autoref and the truth: one goal)."""
    line = FIELD.half_length + 0.0215
    stream = [
        _game(0.0, RefereeCommand.NORMAL),
        _frame(1.0, 4.0, 0.1), _frame(1.1, line + 0.02, 0.06), _frame(1.2, line - 0.05, 0.06),
        _frame(1.5, PAST_GOAL_X, 0.1),
        _game(1.6, RefereeCommand.STOP),
        _game(5.0, RefereeCommand.KICKOFF), _game(6.0, RefereeCommand.NORMAL),
        _frame(7.0, 4.0, 0.1), _frame(7.1, PAST_GOAL_X, 0.1),  # the next goal, after play stopped: counted
    ]
    assert vision_goals(stream, FIELD) == {"blue": 2, "yellow": 0}


def test_a_ball_left_in_a_goal_is_no_goal_at_the_restart_for_a_stray_detection_on_the_field() -> None:
    """As in an ER-Force row: the ball pushed into the +x goal while play was stopped lay there into the
    second half; at the kickoff (the sides changed) a stray detection at a robot's front on the field,
    then the ball in the goal again: no goal (it did not come from the field). The next real goal
    counts."""
    stream = [
        _game(0.0, RefereeCommand.BALL_PLACEMENT),
        _frame(1.0, 4.3, 0.2), _frame(1.1, PAST_GOAL_X, 0.2),  # pushed in while stopped: no goal
        _frame(2.0, PAST_GOAL_X, 0.2),
        _game(3.0, RefereeCommand.STOP, blue_negative=False),
        _game(3.5, RefereeCommand.KICKOFF, blue_negative=False),
        _frame(3.50, -1.0, 1.5),  # a stray detection on the field ...
        _frame(3.52, PAST_GOAL_X, 0.2),  # ... and the ball still in the goal, 5.6 m away a frame later
        _frame(3.6, PAST_GOAL_X, 0.2),
        _game(4.0, RefereeCommand.NORMAL, blue_negative=False),
        _frame(4.5, 0.0, 0.0), _frame(5.0, -4.0, 0.1), _frame(5.1, -PAST_GOAL_X, 0.1),  # blue scores at -x
    ]
    assert vision_goals(stream, FIELD) == {"blue": 1, "yellow": 0}


def test_goals_in_the_truth_are_counted_at_both_ends_once_each() -> None:
    path = [(0.0, 0.0), (PAST_GOAL_X, 0.2), (PAST_GOAL_X + 0.05, 0.2), (0.0, 0.0), (-PAST_GOAL_X, -0.2),
            (0.0, 0.0), (PAST_GOAL_X, 2.0), (0.0, 0.0)]  # two goals, then out beside the post
    truths = [GroundTruth(k, k / 60, BallTruth(x, y, 0.0, 0.0, 0.0)) for k, (x, y) in enumerate(path)]
    assert truth_goals(truths, FIELD) == 2


def test_goals_in_the_truth_count_only_while_the_referee_has_the_ball_in_play_and_within_the_match() -> None:
    path = [(0.0, 0.0), (PAST_GOAL_X, 0.2), (0.0, 0.0), (-PAST_GOAL_X, -0.2), (0.0, 0.0), (PAST_GOAL_X, 0.1),
            (0.0, 0.0), (-PAST_GOAL_X, 0.0)]  # four crossings, at 1, 3, 5 and 7 s
    truths = [GroundTruth(k, float(k), BallTruth(x, y, 0.0, 0.0, 0.0)) for k, (x, y) in enumerate(path)]
    states = [GameState(0.5, RefereeCommand.STOP),  # 1 s: play stopped
              GameState(2.0, RefereeCommand.NORMAL),  # 3 s: a goal
              GameState(4.0, RefereeCommand.STOP),  # 5 s: the ball in while stopped
              GameState(6.0, RefereeCommand.FORCE_START)]  # 7 s: after the match's last frame
    assert truth_goals(truths, FIELD) == 4
    assert truth_goals(truths, FIELD, states, until=6.5) == 1
    assert truth_goals(truths, FIELD, states) == 2
    assert truth_goals(truths, FIELD, states[1:]) == 2  # nothing before the referee's first word


def test_a_goal_in_the_truth_is_judged_by_the_referees_word_before_its_frame() -> None:
    """The referee calls a goal in the frame the ball crosses: its stop of that frame follows the goal."""
    path = [(0.0, 0.0), (4.0, 0.2), (PAST_GOAL_X, 0.2), (PAST_GOAL_X, 0.2)]
    truths = [GroundTruth(k, k / 60, BallTruth(x, y, 0.0, 0.0, 0.0)) for k, (x, y) in enumerate(path)]
    states = [GameState(0.0, RefereeCommand.NORMAL), GameState(2 / 60 - 1e-7, RefereeCommand.STOP)]  # (float rounding)
    assert truth_goals(truths, FIELD, states) == 1


def test_the_served_truths_clock_is_matched_to_ours_by_frame_number() -> None:
    """The served simulator's clock ran 3 s before our match's first frame: the offset between its
    truth and our detections of the same frame (times as read off the wire, a little rounded)."""
    truths = [GroundTruth(k, 3.0 + k / 60, BallTruth(0.0, 0.0, 0.0, 0.0, 0.0)) for k in range(180, 240)]
    ours = [DetectionFrame(0, k, k / 60 + 7e-8, k / 60, ()) for k in (150, 200, 201)]
    assert truth_clock_offset(truths, ours) == 3.0
    assert truth_clock_offset(truths, ours[:1]) == 0.0  # no frame in common


def test_stoppages_run_from_a_stop_to_the_next_start_and_the_match_end_closes_the_last() -> None:
    states = [
        GameState(0.0, RefereeCommand.KICKOFF, "blue", ready=False),  # 0-5 s: the first kickoff
        GameState(4.0, RefereeCommand.KICKOFF, "blue", ready=True),
        GameState(5.0, RefereeCommand.NORMAL),
        GameState(20.0, RefereeCommand.STOP),  # 20-32 s: a stop, a placement, a free kick
        GameState(22.0, RefereeCommand.BALL_PLACEMENT, "yellow"),
        GameState(28.0, RefereeCommand.FREE_KICK, "yellow"),
        GameState(32.0, RefereeCommand.FORCE_START),
        GameState(45.0, RefereeCommand.STOP),  # 45 s on: never restarted, the match over at 59 s
        GameState(59.0, RefereeCommand.HALT, stage=GameStage.POST_GAME),
    ]
    assert stoppages(states, 60.0, 10.0) == Stoppages(count=3, restarted=2, longest_s=14.0, over_limit=2)
    # without the match's end in the states, the stop lasts to the end given
    assert stoppages(states[:-1], 60.0, 10.0) == Stoppages(count=3, restarted=2, longest_s=15.0, over_limit=2)


def test_the_first_kickoff_is_taken_by_a_normal_start_and_forced_by_a_force_start() -> None:
    taken = [GameState(0.2, RefereeCommand.KICKOFF, "blue"), GameState(3.0, RefereeCommand.KICKOFF, "blue"),
             GameState(3.4, RefereeCommand.NORMAL), GameState(9.0, RefereeCommand.STOP),
             GameState(10.0, RefereeCommand.FORCE_START)]
    assert first_start(taken) == (pytest.approx(3.2), True)
    forced = [GameState(0.0, RefereeCommand.KICKOFF, "blue"), GameState(10.0, RefereeCommand.FORCE_START)]
    assert first_start(forced) == (10.0, False)
    assert first_start(forced[:1]) == (None, False) and first_start([]) == (None, False)


def _world(t: float, xy: tuple[float, float] | None, visible: bool = True) -> tuple[str, WorldState]:
    ball = None if xy is None else BallState(xy[0], xy[1], 0.0, 0.0, visible)
    return "world/autoref", WorldState(t, ball)


def test_the_ball_is_played_as_far_as_it_went_while_play_ran() -> None:
    stream = [
        _game(0.0, RefereeCommand.KICKOFF),
        _world(0.0, (0.0, 0.0)), _world(0.1, (0.0, 0.0)),  # lying at the kickoff: nothing
        _game(0.2, RefereeCommand.NORMAL),
        _world(0.2, (0.3, 0.4)), _world(0.3, (0.6, 0.8)),  # 0.5 m played
        _world(0.4, None), _world(0.5, (1.0, 0.8), visible=False), _world(0.6, (0.6, 1.8)),  # lost: 1 m once seen
        _game(0.7, RefereeCommand.STOP),
        _world(0.7, (-4.0, 0.0)), _world(0.8, (-4.0, 1.0)),  # placed by the referee: not played
        _game(0.9, RefereeCommand.FORCE_START),
        _world(0.9, (-4.0, 1.5)), _world(1.0, (-4.0, 2.0)),  # 0.5 m played
    ]
    assert ball_in_play_m(stream) == pytest.approx(2.0)


def test_the_rules_time_of_a_stoppage_adds_each_phase_it_may_pass_through() -> None:
    r = load_settings().sim.referee
    f = r.figures
    assert rules_stoppage_s(r) == pytest.approx(r.restart_delay_s + f.placement_time_s + f.prepare_timeout_s
                                                + max(r.restart_timeout_s, f.penalty_time_s))
    longer = dataclasses.replace(r, figures=dataclasses.replace(f, penalty_time_s=r.restart_timeout_s + 5.0))
    assert rules_stoppage_s(longer) == pytest.approx(rules_stoppage_s(r) + 5.0)


def test_a_peer_without_its_script_or_binary_is_skipped_with_the_reason(tmp_path: Path,
                                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    grsim = next(p for p in PEERS if p.name == "grsim")
    monkeypatch.delenv("GRSIM_NETNS", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    script, why = peer_script(grsim, checkout=tmp_path / "checkout")
    assert script is None and "grsim-netns.sh" in why and "GRSIM_NETNS" in why
    fake = tmp_path / "grsim-netns.sh"  # a script, but no grSim for it
    fake.write_text("#!/bin/sh\nexit 0\n")
    fake.chmod(0o755)
    monkeypatch.setenv("GRSIM", str(tmp_path / "no-grsim"))
    script, why = peer_script(grsim, checkout=tmp_path / "checkout")
    assert script is None and str(tmp_path / "no-grsim") in why
    row = match_row(load_settings(), grsim, "B", "none", 10.0, tmp_path / "out")
    assert row == {"name": "grsim_B_none", "skipped": why}


@pytest.mark.slow
def test_the_served_simulators_row_agrees_with_the_served_truth(tmp_path: Path) -> None:
    """Two processes as the suite runs them (sim --serve, play --simulator sim-protocol, our autoref
    refereeing, both colours ours): the goals our autoref called are those the served truth shows
    and those the served vision shows, the first kickoff is a stoppage restarted within the rules'
    time, and the match played its time on the served vision's clock."""
    settings = load_settings()
    served = next(p for p in PEERS if p.name == "served")
    row = match_row(settings, served, "B", "self", 15.0, tmp_path)
    assert "failed" not in row, row
    goals = row["goals_ours"] + row["goals_theirs"]
    assert goals == row["goals_truth"] == row["goals_vision_ours"] + row["goals_vision_theirs"]
    assert row["stoppages"] >= 1 and row["stoppages_restarted"] >= 1
    assert row["longest_stoppage_s"] <= rules_stoppage_s(settings.sim.referee)
    assert row["match_s"] >= 30.0 and row["frames"] > 0  # (how many: the machine's load; vision's clock counts)
    assert 0 <= row["passes_completed"] <= row["passes_tried"]
    assert row["ball_roll_simulator_m_s2"] == settings.field.ball.acc_roll_m_s2
    assert row["ball_roll_configured_m_s2"] == settings.field.ball.acc_roll_m_s2
    if row["ball_roll_windows"]:  # the served ball rolls as field.yaml says: learnt within 10 %
        assert math.isclose(row["ball_roll_learnt_m_s2"], row["ball_roll_simulator_m_s2"], rel_tol=0.10)
    assert (tmp_path / "served_B_self" / "ours" / "run.mcap").exists()


def _grsim_found() -> str | None:
    script, why = peer_script(next(p for p in PEERS if p.name == "grsim"))
    return None if script is not None else why


@pytest.mark.slow
@pytest.mark.skipif(_grsim_found() is not None, reason=f"grSim not found: {_grsim_found()}")
def test_the_grsim_row_plays_in_grsim_and_its_goals_are_those_grsims_vision_shows(tmp_path: Path) -> None:
    """Against grSim's idle robots, two halves of 10 s (the second half's kickoff is theirs, forced
    after the rules' 10 s): our first kickoff is taken (it once ran out before our team's first
    frame), the ball is played, and the goals our autoref called are those grSim's vision shows."""
    row = match_row(load_settings(), next(p for p in PEERS if p.name == "grsim"), "B", "none", 10.0, tmp_path)
    assert "failed" not in row, row
    assert row["first_kickoff_taken"], row
    assert row["ball_in_play_m"] > 1.0, row  # (a ball never moved would make the goals' check 0 = 0)
    assert row["goals_ours"] + row["goals_theirs"] == row["goals_vision_ours"] + row["goals_vision_theirs"]
    assert row["goals_truth"] is None and row["match_s"] >= 20.0
    assert os.path.exists(tmp_path / "grsim_B_none" / "ours" / "summary.json")
