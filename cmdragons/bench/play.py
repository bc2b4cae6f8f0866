"""``cmdragons bench play``: seeded matches against the built-in opponents under the league's full
rules, our team seeing through the cameras; the two built-in teams against each other; and the
brain's cycle for 11 v 11 in division A.

A match is two halves of the rules' duration (5 minutes each; the half-time break, in which nothing
moves, is not simulated), the sides changed between them. Rows per match against each opponent
(the simple team; the defending team; ``self``, our team in the other colour) (goals for and
against, shots, passes, own collisions (apart: those where an opponent touched one of the two,
pushing it into the other), fouls and cards per team, our placements tried and succeeded, stage
times), a totals row per opponent (matches won, drawn, lost; pass completion; own collisions; our
fouls by kind, per match; placements succeeded and their median time); the defending team against
the simple team on the true state, the same halves, once in each colour (goals, fouls and cards of
each; neither team nor the simulator draws anything at random on the true state, so more seeds
would replay these two matches) and their totals row; the brain's cycle
time (tracker to commands) for 6 and 11 robots; a penalty shootout of ``SHOOTOUT_KICKS`` kicks
each way (ours against their keeper, theirs against ours: scored and saved), played as a shootout
after two halves of a second. ``--quick`` plays two matches of two 30 s halves against simple and
against defend (no self-play), the two built-in teams' two, and a shootout of 3 kicks each.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from typing import Any

import numpy as np

from cmdragons.messages import GameStage, GameState
from cmdragons.runtime.bus import BaseStage, Bus, Publish, run_frames
from cmdragons.runtime.match import BuiltIn, Match, built_in_wiring
from cmdragons.runtime.match import build as build_stages
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.stages import SummaryCollector
from cmdragons.runtime.topics import Contract, Port
from sim.simulator import Simulator

__all__ = ["OPPONENTS", "SHOOTOUT_KICKS", "run"]

OPPONENTS = ("simple", "defend", "self")  # whom our team plays in the suite, in this order

SHOOTOUT_KICKS = 10  # penalty kicks each way in the bench's shootout (the measure)
GRSIM_BALL_ROLL_M_S2 = 0.70  # grSim's ball decelerates so while rolling (measured against its own vision)
GRSIM_ROBOT_BRAKE_M_S2 = 4.0  # ... and its robots brake at about this
_SHOOTOUT_HALF_S = 1.0  # the halves before the shootout: as short as the rules' figures allow


def _halves(settings: Settings, half_s: float, shootout_kicks: int = 0) -> Settings:
    """Full rules, halves of ``half_s`` and no half-time break to wait out; with ``shootout_kicks`` a
    shootout of that many kicks each after the match, whatever its score."""
    ref = settings.sim.referee
    figures = dataclasses.replace(ref.figures, half_s=half_s, half_time_s=0.0, shootout_kicks=shootout_kicks,
                                  shootout_always=shootout_kicks > 0)
    ref = dataclasses.replace(ref, rules="full", figures=figures)
    return dataclasses.replace(settings, sim=dataclasses.replace(settings.sim, referee=ref))


class _StageWatch(BaseStage):
    """The game's stage as the referee last published it."""

    contract = Contract("bench/stage", (Port("referee", GameState),))

    def __init__(self) -> None:
        self.stage = ""

    def on_message(self, topic: str, message: GameState, publish: Publish) -> None:
        self.stage = message.stage


def _shootout_row(settings: Settings, kicks: int, seed: int) -> dict[str, Any]:
    """A penalty shootout of ``kicks`` each way against the simple opponent (cameras): ours scored
    against their keeper, theirs saved by ours."""
    watch = _StageWatch()
    m = Match(_halves(settings, _SHOOTOUT_HALF_S, kicks), "simple", "vision", seed=seed, extra=[watch])
    r = settings.sim.referee
    # the longest a kick can take: the restart delay, the preparing and the kicker's time
    per_kick = r.restart_delay_s + r.figures.prepare_timeout_s + r.figures.penalty_time_s
    limit = round((2.0 * _SHOOTOUT_HALF_S + 2 * kicks * per_kick + 2.0) * settings.sim.physics.frame_rate_hz)
    wall = time.perf_counter()
    run_frames(lambda _i: m.step(), limit, should_stop=lambda: watch.stage == GameStage.POST_GAME)
    wall = time.perf_counter() - wall
    s = m.summary()
    shot = s["rules"]["shootout"]
    ours, theirs = shot["blue"], shot["yellow"]
    return {"name": f"shootout_{kicks}_each_seed_{seed}", "taken_ours": ours["taken"], "scored_ours": ours["scored"],
            "taken_theirs": theirs["taken"], "saved_ours": theirs["taken"] - theirs["scored"],
            "finished": watch.stage == GameStage.POST_GAME, "seconds": s["seconds"],
            "realtime_factor": s["seconds"] / wall}


def _suffix(opponent: str) -> str:
    """Row names against the simple team as they always were; against another, its name appended."""
    return "" if opponent == "simple" else f"_{opponent}"


def _match_row(settings: Settings, seed: int, seconds: float, opponent: str) -> dict[str, Any]:
    wall = time.perf_counter()
    m = Match(settings, opponent, "vision", seed=seed)  # type: ignore[arg-type]
    s = m.run(seconds)
    wall = time.perf_counter() - wall
    c = s["cycle_ms"]
    rules = s["rules"]
    ours, theirs = rules["fouls"]["blue"], rules["fouls"]["yellow"]
    placed = rules["placements"]["blue"]
    return {
        "name": f"match_seed_{seed}{_suffix(opponent)}",
        "goals_for": s["score"]["blue"],
        "goals_against": s["score"]["yellow"],
        "shots": s["shots"],
        "passes_tried": s["passes"]["tried"],
        "passes_completed": s["passes"]["completed"],
        "pass_ends": _kinds_text(s["passes"]["ends"]),
        "_pass_ends": dict(s["passes"]["ends"]),
        "own_collisions": s["collisions"]["own"],
        "own_collisions_pushed": s["collisions"]["own_pushed"],
        "fouls_ours": ours["total"],
        "fouls_theirs": theirs["total"],
        "fouls_ours_by_kind": _kinds_text({k: v for k, v in ours.items() if k != "total"}),
        "_kinds": {k: v for k, v in ours.items() if k != "total"},
        "yellow_cards_ours": rules["cards"]["blue"]["yellow"],
        "red_cards_ours": rules["cards"]["blue"]["red"],
        "yellow_cards_theirs": rules["cards"]["yellow"]["yellow"],
        "placements_tried": placed["tried"],
        "placements_succeeded": placed["succeeded"],
        "placements_cut_short": placed["cut_short"],
        "placement_median_s": placed["median_s"],
        "brain_median_ms": c["brain"]["median"],
        "brain_p95_ms": c["brain"]["p95"],
        "tracker_median_ms": c["tracker"]["median"],
        "vision_median_ms": c["vision"]["median"],
        "frame_median_ms": c["frame"]["median"],
        "realtime_factor": s["seconds"] / wall,
        **_learnt(s),
    }


def _learnt(summary: dict[str, Any]) -> dict[str, Any]:
    """What our tracker measured of the ball and our robots, against the configured values (m/s²)."""
    out: dict[str, Any] = {}
    for name, e in summary.get("physics", {}).items():
        if name in ("ball_roll", "robot_brake"):
            out[f"{name}_learnt_m_s2"] = e["value_m_s2"]
            out[f"{name}_configured_m_s2"] = e["configured_m_s2"]
            out[f"{name}_windows"] = e["samples"]
            out[f"{name}_used"] = e["used"]
    return out


def _other_world_row(settings: Settings, seed: int, seconds: float, opponent: str, roll_m_s2: float,
                     brake_m_s2: float) -> dict[str, Any]:
    """A match in our simulator made another simulator's world (its ball rolling out at ``roll_m_s2``,
    its robots braking at ``brake_m_s2``; grSim's by default) while our team believes field.yaml:
    what the tracker learns, and how the team plays once it uses it."""
    world = dataclasses.replace(settings.sim, world_ball_acc_roll_m_s2=roll_m_s2, world_robot_max_brake_m_s2=brake_m_s2)
    row = _match_row(dataclasses.replace(settings, sim=world), seed, seconds, opponent)
    row["name"] = f"other_world_roll_{roll_m_s2:g}_brake_{brake_m_s2:g}_seed_{seed}"
    row["world_ball_roll_m_s2"], row["world_robot_brake_m_s2"] = roll_m_s2, brake_m_s2
    return row


def _kinds_text(kinds: dict[str, int]) -> str:
    """Fouls by kind as one line ("crash 1, stop speed 2"; "none")."""
    return ", ".join(f"{k.replace('_', ' ')} {n}" for k, n in kinds.items()) or "none"


def _sum_kinds(per_match: list[dict[str, int]]) -> dict[str, int]:
    out: dict[str, int] = {}
    for kinds in per_match:
        for k, n in kinds.items():
            out[k] = out.get(k, 0) + n
    return dict(sorted(out.items()))


def _brain_cycle(settings: Settings, division: str, seconds: float) -> dict[str, Any]:
    """Tracker and brain on noisy true detections, 6 or 11 robots a side: the brain's own cost."""
    league = dataclasses.replace(settings.field, division=division)  # type: ignore[arg-type]
    s = dataclasses.replace(settings, field=league)
    m = Match(s, "self", "truth", seed=3)
    m.run(seconds)
    brain = m.stage_ms["brain"]
    tracker = m.stage_ms["tracker"]
    cycle = np.array(brain) + np.array(tracker)
    return {"name": f"brain_cycle_{league.dims.robots_per_team}_robots", "median_ms": float(np.median(cycle)),
            "p95_ms": float(np.percentile(cycle, 95)), "brain_median_ms": float(np.median(brain)),
            "tracker_median_ms": float(np.median(tracker))}


def _built_in_match(settings: Settings, blue: BuiltIn, yellow: BuiltIn, seed: int,
                    seconds: float) -> tuple[dict[str, Any], float]:
    """One match of two built-in teams on the true state: the referee's figures and the simulated
    seconds per wall-clock second."""
    sim = Simulator(settings.field, settings.camera_models(), settings.sim, seed=seed, render=False, referee=False)
    summaries = SummaryCollector()
    bus = Bus()
    for stage in build_stages(built_in_wiring(settings, blue, yellow, lambda: sim), [summaries]):
        bus.add(stage)
    wall = time.perf_counter()
    bus.start()
    run_frames(bus.tick, max(1, round(seconds * settings.sim.physics.frame_rate_hz)))
    wall = time.perf_counter() - wall
    bus.summarize()
    return summaries.figures["referee"], summaries.figures["sim"]["seconds"] / wall


def _duel_row(settings: Settings, seed: int, seconds: float) -> dict[str, Any]:
    """The defending team against the simple team: yellow on odd seeds, blue on even ones (the
    seed picks nothing else: both play on the true state, which the simulator keeps free of noise)."""
    defend, simple = ("yellow", "blue") if seed % 2 else ("blue", "yellow")
    colours: dict[str, BuiltIn] = {defend: "defend", simple: "simple"}
    ref, speed = _built_in_match(settings, colours["blue"], colours["yellow"], seed, seconds)
    return {"name": f"defend_vs_simple_seed_{seed}", "defend_plays": defend,
            "goals_defend": ref["score"][defend], "goals_simple": ref["score"][simple],
            "fouls_defend": ref["fouls"][defend]["total"], "fouls_simple": ref["fouls"][simple]["total"],
            "fouls_defend_by_kind": _kinds_text({k: v for k, v in ref["fouls"][defend].items() if k != "total"}),
            "cards_defend": ref["cards"][defend]["yellow"] + ref["cards"][defend]["red"],
            "cards_simple": ref["cards"][simple]["yellow"] + ref["cards"][simple]["red"],
            "realtime_factor": speed}


def _duel_total(rows: list[dict[str, Any]], seconds: float) -> dict[str, Any]:
    won = sum(r["goals_defend"] > r["goals_simple"] for r in rows)
    lost = sum(r["goals_defend"] < r["goals_simple"] for r in rows)
    n = len(rows)
    return {"name": f"total_defend_vs_simple_{n}_matches_{seconds:.0f}s", "won_defend": won,
            "drawn": n - won - lost, "lost_defend": lost,
            "goals_defend": sum(r["goals_defend"] for r in rows), "goals_simple": sum(r["goals_simple"] for r in rows),
            "fouls_defend_per_match": sum(r["fouls_defend"] for r in rows) / n,
            "fouls_simple_per_match": sum(r["fouls_simple"] for r in rows) / n,
            "cards_defend": sum(r["cards_defend"] for r in rows), "cards_simple": sum(r["cards_simple"] for r in rows),
            "realtime_factor": float(np.median([r["realtime_factor"] for r in rows]))}


def _total(rows: list[dict[str, Any]], seconds: float, opponent: str) -> dict[str, Any]:
    """The totals row of the matches ``rows`` against ``opponent`` (each row's kinds of fouls taken out)."""
    won = sum(r["goals_for"] > r["goals_against"] for r in rows)
    tried_placing = sum(r["placements_tried"] for r in rows)
    placed = sum(r["placements_succeeded"] for r in rows)
    lost = sum(r["goals_for"] < r["goals_against"] for r in rows)
    tried = sum(r["passes_tried"] for r in rows)
    return {
        "name": f"total_{len(rows)}_matches_{seconds:.0f}s{_suffix(opponent)}", "opponent": opponent,
        "won": won, "drawn": len(rows) - won - lost, "lost": lost,
        "goals_for": sum(r["goals_for"] for r in rows), "goals_against": sum(r["goals_against"] for r in rows),
        "passes_tried": tried, "passes_completed": sum(r["passes_completed"] for r in rows),
        "pass_completion": sum(r["passes_completed"] for r in rows) / tried if tried else float("nan"),
        "pass_ends": _kinds_text(_sum_kinds([r.pop("_pass_ends") for r in rows])),
        "shots": sum(r["shots"] for r in rows),
        "own_collisions": sum(r["own_collisions"] for r in rows),
        "own_collisions_pushed": sum(r["own_collisions_pushed"] for r in rows),
        "fouls_ours_per_match": sum(r["fouls_ours"] for r in rows) / len(rows),
        "fouls_theirs_per_match": sum(r["fouls_theirs"] for r in rows) / len(rows),
        "fouls_ours_by_kind": _kinds_text(_sum_kinds([r.pop("_kinds") for r in rows])),
        "cards_ours": sum(r["yellow_cards_ours"] + r["red_cards_ours"] for r in rows),
        "placements_succeeded_share": placed / tried_placing if tried_placing else float("nan"),
        "placements_succeeded": placed, "placements_tried": tried_placing,
        "placements_cut_short": sum(r["placements_cut_short"] for r in rows),
        "placement_median_of_matches_s": float(np.median(times)) if (times := [r["placement_median_s"] for r in rows
                                                                    if r["placement_median_s"] is not None]) else None,
        "realtime_factor": float(np.median([r["realtime_factor"] for r in rows])),
    }


def run(settings: Settings, quick: bool, opponent: str | None = None, matches: int | None = None,
        half: float | None = None, shootout: int | None = None) -> list[dict[str, Any]]:
    """The suite's rows. ``opponent``: one of :data:`OPPONENTS` alone (default: each of them, but
    self-play only without ``quick``); the defending team's matches against the simple team come
    with the matches against the defending team, the shootout and the brain's cycle with those
    against the simple team. ``matches``, ``half``: how many and how long (seconds); ``shootout``:
    the shootout's kicks each way (default ``SHOOTOUT_KICKS``, quick 3; 0: none)."""
    opponents = [opponent] if opponent else [o for o in OPPONENTS if not (quick and o == "self")]
    seeds = list(range(1, (matches or (2 if quick else 10)) + 1))
    half = half or (30.0 if quick else settings.sim.referee.figures.half_s)
    seconds = 2.0 * half
    rules = _halves(settings, half)
    rows: list[dict[str, Any]] = []
    for opp in opponents:
        played = []
        for k, seed in enumerate(seeds):
            print(f"bench play: match {k + 1} of {len(seeds)} (seed {seed}, 2 x {half:g} s, against {opp}) ...",
                  file=sys.stderr, flush=True)
            played.append(_match_row(rules, seed, seconds, opp))
        rows += [*played, _total(played, seconds, opp)]
        if opp == "defend":
            duels = []
            for k, seed in enumerate(seeds[:2]):  # (deterministic: one match in each colour is all there is)
                print(f"bench play: defend against simple {k + 1} of {len(seeds[:2])} (2 x {half:g} s) ...",
                      file=sys.stderr, flush=True)
                duels.append(_duel_row(rules, seed, seconds))
            rows += [*duels, _duel_total(duels, seconds)]
    if "simple" in opponents:  # and one more against the simple team in grSim's physics
        print("bench play: a match in grSim's physics (ball 0.70 m/s², braking 4 m/s²) ...", file=sys.stderr,
              flush=True)
        other = _other_world_row(rules, seeds[0], seconds, "simple", GRSIM_BALL_ROLL_M_S2, GRSIM_ROBOT_BRAKE_M_S2)
        other.pop("_kinds")
        other.pop("_pass_ends")
        rows.append(other)
    if "simple" not in opponents:
        return rows
    kicks = (3 if quick else SHOOTOUT_KICKS) if shootout is None else shootout
    if kicks:
        print("bench play: penalty shootout ...", file=sys.stderr, flush=True)
        rows.append(_shootout_row(settings, kicks, seeds[0]))
    rows.append(_brain_cycle(settings, "B", 10.0 if quick else 30.0))
    rows.append(_brain_cycle(settings, "A", 10.0 if quick else 30.0))
    return rows
