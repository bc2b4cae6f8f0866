"""The game controller's state machine alone: commands and their counter, which commands have the
ball in play, the stages in order with their lengths, the shootout's kickers, fouls into cards, the
game state and team info it tells."""

from __future__ import annotations

import math

import pytest

from cmdragons.geometry import TEAMS, Team
from cmdragons.messages import GameStage, GameState, RefereeCommand
from sim.game_controller import (
    Card,
    Cards,
    GameController,
    Penalty,
    Placement,
    Tally,
    shootout_kicker,
    stage_after,
    team_info,
)
from sim.rules import RulesParams

C, S = RefereeCommand, GameStage


def test_the_counter_and_time_move_only_when_the_command_changes() -> None:
    gc = GameController(RulesParams(), halves=True)
    assert (gc.command, gc.for_team, gc.ready, gc.counter) == (C.KICKOFF, "blue", True, 0)
    gc.give(1.0, C.KICKOFF, "blue")
    assert (gc.counter, gc.command_t) == (0, 0.0)
    gc.give(2.0, C.STOP, None)
    gc.give(3.0, C.STOP, None)
    assert (gc.counter, gc.command_t) == (1, 2.0)
    gc.give(4.0, C.PENALTY, "yellow", ready=False)
    gc.give(5.0, C.PENALTY, "yellow", ready=True)  # the normal start is a change
    assert (gc.counter, gc.command_t, gc.ready) == (3, 5.0, True)


@pytest.mark.parametrize(("command", "ready", "in_play", "live"), [
    (C.HALT, True, False, False), (C.STOP, True, False, False), (C.TIMEOUT, True, False, False),
    (C.BALL_PLACEMENT, True, False, False), (C.KICKOFF, False, False, True), (C.FREE_KICK, True, False, True),
    (C.NORMAL, True, True, True), (C.FORCE_START, True, True, True), (C.PENALTY, False, False, False),
    (C.PENALTY, True, True, True),
])
def test_which_commands_have_the_ball_in_play(command: RefereeCommand, ready: bool, in_play: bool,
                                              live: bool) -> None:
    gc = GameController(RulesParams(), halves=True)
    gc.give(0.0, command, None if command in (C.HALT, C.STOP, C.NORMAL, C.FORCE_START) else "blue", ready)
    assert (gc.in_play(), gc.live()) == (in_play, live)


@pytest.mark.parametrize(("stage", "half_time_s", "kicks", "always", "drawn", "after"), [
    (S.FIRST_HALF, 300.0, 0, False, True, S.HALF_TIME), (S.FIRST_HALF, 0.0, 0, False, True, S.SECOND_HALF),
    (S.HALF_TIME, 300.0, 0, False, True, S.SECOND_HALF), (S.SECOND_HALF, 300.0, 0, False, True, S.POST_GAME),
    (S.SECOND_HALF, 300.0, 5, False, True, S.PENALTY_SHOOTOUT), (S.SECOND_HALF, 300.0, 5, False, False, S.POST_GAME),
    (S.SECOND_HALF, 300.0, 5, True, False, S.PENALTY_SHOOTOUT), (S.PENALTY_SHOOTOUT, 300.0, 5, True, True, S.POST_GAME),
])
def test_the_stages_follow_in_the_rules_order(stage: GameStage, half_time_s: float, kicks: int, always: bool,
                                              drawn: bool, after: GameStage) -> None:
    rules = RulesParams(half_time_s=half_time_s, shootout_kicks=kicks, shootout_always=always)
    assert stage_after(stage, rules, drawn) is after


def test_each_stage_lasts_what_the_rules_give_it() -> None:
    rules = RulesParams(half_s=25.0, half_time_s=5.0)
    assert GameController(rules, halves=True).stage_end == 25.0
    assert GameController(rules, halves=False).stage_end == math.inf
    gc = GameController(rules, halves=True)
    assert not gc.stage_over(24.9) and gc.stage_over(25.0)
    for stage, end in ((S.HALF_TIME, 35.0), (S.SECOND_HALF, 55.0), (S.PENALTY_SHOOTOUT, math.inf),
                       (S.POST_GAME, math.inf)):
        gc.enter(stage, 30.0)
        assert (gc.stage, gc.stage_end) == (stage, end)


def _kicks(blue: tuple[int, int], yellow: tuple[int, int]) -> dict[Team, dict[str, int]]:
    return {"blue": {"taken": blue[0], "scored": blue[1]}, "yellow": {"taken": yellow[0], "scored": yellow[1]}}


@pytest.mark.parametrize(("blue", "yellow", "always", "kicker"), [
    ((0, 0), (0, 0), False, "yellow"), ((0, 0), (1, 1), False, "blue"), ((4, 2), (5, 3), False, "blue"),
    ((5, 3), (5, 3), False, "yellow"),  # drawn after five each: one each more
    ((6, 4), (6, 3), False, None), ((5, 3), (5, 2), False, None), ((5, 3), (5, 3), True, None),
    ((2, 0), (3, 3), False, "blue"),  # decided already, but not over before blue's kick
])
def test_the_shootouts_kickers_in_turn_until_decided(blue: tuple[int, int], yellow: tuple[int, int], always: bool,
                                                     kicker: Team | None) -> None:
    assert shootout_kicker(_kicks(blue, yellow), RulesParams(shootout_kicks=5, shootout_always=always)) == kicker


def test_every_third_foul_earns_a_card_and_the_third_running_is_red() -> None:
    cards = Cards(RulesParams(fouls_per_yellow_card=3, red_card_yellow_cards=3, yellow_card_s=10.0))
    assert [cards.foul("blue") for _ in range(7)] == [False, False, True, False, False, True, False]
    assert cards.fouls == {"blue": 7, "yellow": 0}
    assert not cards.next_is_red("blue")
    cards.book("blue", 3, red=False)
    cards.book("blue", 2, red=False)
    assert cards.next_is_red("blue") and not cards.next_is_red("yellow")
    assert (cards.yellow, cards.red) == ({"blue": 2, "yellow": 0}, {"blue": 0, "yellow": 0})


def test_a_card_sends_off_the_fouling_field_player_else_the_highest_id() -> None:
    cards = Cards(RulesParams(keepers={"blue": 0, "yellow": 1}))
    keys = [("blue", i) for i in range(4)] + [("yellow", i) for i in range(3)]
    assert cards.choose("blue", 2, keys) == 2
    assert cards.choose("blue", 0, keys) == 3  # the keeper stays: the highest id goes
    assert cards.choose("blue", None, keys) == 3
    cards.off[("blue", 3)] = False
    assert cards.choose("blue", 3, keys) == 2  # off already
    cards.off.update({("yellow", 0): True, ("yellow", 2): True})
    assert cards.choose("yellow", None, keys) == 1  # only the keeper is left


def test_cards_run_out_and_their_robots_come_back_unless_sent_off_for_good() -> None:
    cards = Cards(RulesParams(yellow_card_s=2.0))
    cards.book("blue", 4, red=False)
    cards.off[("blue", 4)] = False
    cards.book("yellow", 1, red=False)
    cards.off[("yellow", 1)] = True  # since sent off for good
    assert cards.times_left("blue") == (2.0,)
    assert cards.run(1.5) == [] and cards.times_left("blue") == pytest.approx((0.5,))
    out = cards.run(0.5)
    assert out == [Card("blue", 4, 0.0), Card("yellow", 1, 0.0)] and cards.running == []
    assert [cards.back(c) for c in out] == [True, False]
    assert cards.off == {("yellow", 1): True}


def test_the_tally_counts_placements_and_cuts_short_the_one_under_way() -> None:
    tally = Tally()
    tally.placed("blue", 4.0)
    tally.placed("blue", 8.0)
    tally.failed("blue")
    tally.failed("yellow")
    assert tally.may_place("blue", 2) and not tally.may_place("blue", 1)
    figures = tally.figures(under_way="yellow")
    assert figures["placements"] == {"blue": {"tried": 3, "succeeded": 2, "cut_short": 0, "median_s": 6.0},
                                     "yellow": {"tried": 1, "succeeded": 0, "cut_short": 1, "median_s": None}}
    assert tally.figures(under_way=None)["placements"]["yellow"]["cut_short"] == 0  # type: ignore[index]
    assert figures["penalties"] == figures["shootout"] == {t: {"taken": 0, "scored": 0} for t in ("blue", "yellow")}


def test_the_game_state_names_the_designated_position_and_the_time_left_of_the_action_under_way() -> None:
    r = RulesParams()
    gc = GameController(r, halves=True)
    teams = {t: team_info(t, Cards(r), Tally(), [(t, 0)], full=True) for t in TEAMS}

    def state(t: float, spot: tuple[float, float] | None = (0.5, 0.5)) -> GameState:
        return gc.state(t, {"blue": 2, "yellow": 1}, -1, spot, 7.5, (C.FREE_KICK, "blue"), teams)

    gc.give(1.0, C.BALL_PLACEMENT, "blue")
    gc.placement = Placement("blue", (1.0, 2.0), 1.0)
    g = state(4.0)
    assert g.placement == (1.0, 2.0) and g.action_time_left_s == pytest.approx(r.placement_time_s - 3.0)
    assert (g.score_blue, g.score_yellow, g.blue_defends_negative_x) == (2, 1, True)
    assert (g.next_command, g.next_for_team, g.stage_time_left_s) == (C.FREE_KICK, "blue", r.half_s - 4.0)
    assert gc.placing() == "blue"
    gc.clear_special()
    gc.give(10.0, C.PENALTY, "yellow", ready=False)
    gc.penalty = Penalty("yellow", 10.0, (3.0, 0.0))
    g = state(12.0)
    assert g.placement == (3.0, 0.0) and g.action_time_left_s == pytest.approx(r.prepare_timeout_s - 2.0)
    gc.penalty.t_run = 13.0
    assert state(15.0).action_time_left_s == pytest.approx(r.penalty_time_s - 2.0)
    assert gc.placing() is None
    gc.clear_special()
    gc.give(20.0, C.FREE_KICK, "blue")
    assert state(21.0).action_time_left_s == 7.5  # a kick restart's time is the referee's
    gc.give(22.0, C.STOP, None)
    g = state(23.0, None)
    assert g.placement is None and math.isinf(g.action_time_left_s)


def test_team_info_counts_cards_robots_off_and_whether_the_team_still_places_the_ball() -> None:
    r = RulesParams(placement_failures_max=2)
    keys: list[tuple[Team, int]] = [("blue", 0), ("blue", 1), ("blue", 2), ("yellow", 0)]
    cards, tally = Cards(r), Tally()
    cards.book("blue", 2, red=False)
    cards.off[("blue", 2)] = False
    cards.book("blue", 1, red=True)
    cards.off[("blue", 1)] = True
    cards.foul("blue")
    tally.failed("blue")
    info = team_info("blue", cards, tally, keys, full=True)
    assert (info.yellow_cards, info.red_cards, info.fouls, info.max_robots) == (1, 1, 1, 1)
    assert info.yellow_card_times_s == (r.yellow_card_s,) and info.placement_failures == 1 and info.can_place_ball
    tally.failed("blue")
    assert not team_info("blue", cards, tally, keys, full=True).can_place_ball  # failed too often
    assert not team_info("yellow", cards, tally, keys, full=False).can_place_ball  # basic rules: the referee places
    assert team_info("yellow", cards, tally, keys, full=True).max_robots == 1
