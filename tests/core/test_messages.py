"""Messages: dict round trips, the JSONL forms of DESIGN.md, clear errors on bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cmdragons.messages import (
    BallDetection,
    BallState,
    BallTruth,
    DetectionFrame,
    GameEvent,
    GameEvents,
    GameState,
    GroundTruth,
    MessageError,
    RobotCommand,
    RobotDetection,
    RobotState,
    RobotTruth,
    TeamInfo,
    WorldState,
)

DET = DetectionFrame(
    camera_id=1, frame_number=42, t_capture=0.7, t_sent=0.702,
    balls=(BallDetection(0.5, -0.25, 0.9, (100.5, 200.25)), BallDetection(-1.0, 2.0, 0.4, (5.0, 6.0), 0.004)),
    robots=(RobotDetection("blue", 3, 1.0, 2.0, 0.5, 0.99, (10.0, 20.0)),
            RobotDetection("yellow", 15, -1.0, -2.0, -3.0, 0.5, (30.0, 40.0))),
)
WORLD = WorldState(
    t=1.5, ball=BallState(0.1, 0.2, 1.0, -1.0, True),
    robots=(RobotState("blue", 0, 1.0, 1.0, 0.1, 0.5, 0.25, 1.0, True), RobotState("yellow", 7, -1.0, 0.0, 3.0)),
)
TRUTH = GroundTruth(
    frame_number=9, t=0.15, ball=BallTruth(0.0, 0.1, 0.0215, 1.0, 0.0, 0.0, {0: (10.0, 20.0, 0.75)}),
    robots=(RobotTruth("blue", 1, 1.0, 2.0, 0.3, 0.1, 0.2, 0.3, {0: (5.0, 6.0), 1: (7.0, 8.0)}),),
)
COMMAND = RobotCommand("yellow", 4, 1.0, -0.5, 2.0, 3.5, True, 0.5)
GAME = GameState(3.0, "free_kick", "yellow", 2, 1, False, (1.0, -2.8))
# everything the league's Referee message carries: a placement for blue, a card running for yellow
RULES_GAME = GameState(
    41.5, "ball_placement", "blue", 1, 0, True, (-2.0, 1.5), ready=True, stage="second_half",
    stage_time_left_s=187.25, command_counter=17, command_t=40.0, action_time_left_s=28.5,
    next_command="free_kick", next_for_team="blue",
    blue_team=TeamInfo(fouls=2, goalkeeper=1, placement_failures=1, max_robots=6),
    yellow_team=TeamInfo(red_cards=1, yellow_cards=2, yellow_card_times_s=(75.5, 3.25), fouls=6, goalkeeper=0,
                         timeouts=3, timeout_time_s=120.0, can_place_ball=False, max_robots=3),
)
EVENTS = GameEvents(12.0, (GameEvent(11.98, "crash", "yellow", 4, 1.61, 1.5, "m/s", "free_kick", "blue"),
                           GameEvent(12.0, "placement_succeeded", "blue", None, 7.5, 30.0, "s")))


@pytest.mark.parametrize("msg", [DET, WORLD, TRUTH, COMMAND, GAME, RULES_GAME, EVENTS], ids=lambda m: type(m).__name__)
def test_dict_round_trip_through_json(msg: object) -> None:
    d = json.loads(json.dumps(msg.to_dict()))  # type: ignore[attr-defined]
    assert type(msg).from_dict(d) == msg  # type: ignore[attr-defined]


def test_jsonl_forms_match_the_design() -> None:
    d = DET.to_dict()
    assert set(d) == {"camera_id", "frame_number", "t_capture", "t_sent", "balls", "robots"}
    assert set(d["balls"][0]) == {"x", "y", "confidence", "pixel"}
    assert set(d["balls"][1]) == {"x", "y", "confidence", "pixel", "sigma"}  # the optional key, when vision knows it
    assert set(d["robots"][0]) == {"team", "id", "x", "y", "theta", "confidence", "pixel"}
    t = TRUTH.to_dict()
    assert {"frame_number", "t", "ball", "robots"} <= set(t)
    assert {"x", "y", "z", "vx", "vy"} <= set(t["ball"])
    assert {"team", "id", "x", "y", "theta", "vx", "vy", "omega"} <= set(t["robots"][0])
    w = WORLD.to_dict()
    assert set(w["ball"]) == {"x", "y", "vx", "vy", "visible"}
    assert set(w["robots"][0]) == {"team", "id", "x", "y", "theta", "vx", "vy", "omega", "visible"}


def test_ball_sigma_is_optional() -> None:
    # a detection without the key (older logs, other vision systems) has no sigma: NaN
    d = DET.to_dict()
    del d["balls"][1]["sigma"]
    assert math.isnan(DetectionFrame.from_dict(d).balls[1].sigma_m)
    assert DetectionFrame.from_dict(DET.to_dict()).balls[1].sigma_m == 0.004


def test_nan_survives_json_as_null() -> None:
    c = RobotCommand("blue", 1, vx=math.nan)
    d = json.loads(json.dumps(c.to_dict(), allow_nan=False))
    assert math.isnan(RobotCommand.from_dict(d).vx)


@pytest.mark.parametrize(
    "bad",
    [
        {"camera_id": 0, "frame_number": 1, "t_capture": 0.0, "robots": [{"team": "red", "id": 1, "x": 0, "y": 0,
                                                                           "theta": 0}]},
        {"camera_id": 0, "t_capture": 0.0},
        {"camera_id": 0, "frame_number": 1, "t_capture": "soon"},
    ],
)
def test_bad_dicts_raise_message_error(bad: dict[str, object]) -> None:
    with pytest.raises(MessageError):
        DetectionFrame.from_dict(bad)


def test_unknown_game_command_raises_message_error() -> None:
    with pytest.raises(MessageError):
        GameState("t", "dance")  # type: ignore[arg-type]


def test_covariance_is_kept_in_memory_only() -> None:
    b = BallState(0.0, 0.0, 0.0, 0.0, True, covariance=np.eye(4))
    assert "covariance" not in WorldState(0.0, b).to_dict()["ball"]
