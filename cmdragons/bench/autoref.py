"""``cmdragons bench autoref``: the auto-referee on vision judged against our referee on the truth.

In our own simulator both can watch the same matches: the simulator's referee judges the truth and
drives the match (full rules, our team through the cameras against the simple opponent); the
auto-referee watches as an extra, passive stage (its own tracker over every camera's detections, its
calls and game state on ``autoref/...``, its teleports carried out by nobody). A call of the truth
referee (a goal, a ball out, each foul by kind, no progress) is made by the auto-referee too when it
calls the same kind against the same team (for a ball out: for the same team's free kick) within
``WINDOW_S`` of it, each call matched at most once. Rows per kind: the truth's calls, the share the
autoref made too; the autoref's calls of its own (made by it, not by the truth referee) and their
share of all its calls. Targets (the league-world issue): >= 95% of goals and outs, >= 80% of fouls,
<= 10% calls of its own. Each kind's row names the truth's calls the autoref missed (seed, time, and
what the autoref called of that kind near it: a ball out given to the wrong side shows as such).

Beside the calls, the collisions among one team's robots (no foul, a figure of the summary): those
the autoref counts from the tracks against the simulator's contacts of two robots of one team (the
``own_collision`` row, matched by team within the window, apart from the rows of calls).

``--quick`` watches two seeds of 20 s; the full suite ten seeds of 60 s.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from cmdragons.messages import (
    BallOut,
    Contact,
    GameEvent,
    GameEvents,
    GameState,
    RefereeCommand,
    SimEvents,
    StageSummary,
)
from cmdragons.runtime.autoref import PASSIVE, autoref_rows
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.match import Match, match_sim_params
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.topics import Contract, Port
from sim.params import robot_keys
from sim.restarts import ball_out_taker
from sim.rules import FOUL_RESTARTS

__all__ = ["WINDOW_S", "CallLog", "Call", "match_calls", "missed", "run"]

WINDOW_S = 1.0  # a call of the autoref within this of the truth referee's (s) is the same call
FLOW_KINDS = ("goal", "ball_out")  # the calls that restart play (the 95% target)
FOUL_KINDS = (*sorted(FOUL_RESTARTS), "no_progress")  # the fouls (the 80% target), no progress with them
OWN_COLLISION = "own_collision"  # two robots of one team collided (a figure of the summary, no call)


@dataclass(frozen=True)
class Call:
    """One call: its time (s), kind, and the team it is against (for a ball out: whose free kick);
    ``seed``: the match's."""

    t: float
    kind: str
    team: str | None
    seed: int = 0


def _call(e: GameEvent) -> Call:
    return Call(e.t, e.kind, e.for_team if e.kind == "ball_out" else e.team)


class CallLog(BaseStage):
    """The truth referee's calls (its ``referee/events``; goals from the score it publishes; balls out
    from the simulator's events while its game state counts them) and the autoref's
    (``autoref/referee/events``); the own collisions, the simulator's (its contacts of two robots of
    one team) and the autoref's (its summary's)."""

    contract = Contract("bench/calls", (Port("referee", GameState), Port("events", SimEvents), Port("referee/events",
                                        GameEvents), Port(PASSIVE + "referee/events", GameEvents),
                                        Port("summary/autoref", StageSummary)))

    def __init__(self) -> None:
        self.truth: list[Call] = []
        self.autoref: list[Call] = []
        self.truth_collisions: list[Call] = []
        self.autoref_collisions: list[Call] = []
        self._game: GameState | None = None
        self._contact_end: dict[tuple[tuple[str, int], tuple[str, int]], float] = {}  # per pair: its last contact's end

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, StageSummary):
            self.autoref_collisions = [Call(c["t"], OWN_COLLISION, c["team"])
                                       for c in message.figures["own_collisions"]["each"]]
        elif isinstance(message, GameState):
            g = self._game
            if g is not None:
                for team, before, now in (("blue", g.score_blue, message.score_blue),
                                          ("yellow", g.score_yellow, message.score_yellow)):
                    self.truth += [Call(message.t, "goal", team)] * (now - before)
            self._game = message
        elif isinstance(message, SimEvents):
            for e in message.events:
                if isinstance(e, Contact) and e.a[0] == e.b[0]:
                    self._own_contact(e)
            g = self._game
            live = g is not None and (g.command.kick_restart or g.command.running
                                      or (g.command == RefereeCommand.PENALTY and g.ready))
            if g is not None and live:
                sign = -1 if g.blue_defends_negative_x else 1
                self.truth += [Call(e.t, "ball_out", ball_out_taker(e.last_touch, e.x, sign))
                               for e in message.events if isinstance(e, BallOut)]
        elif topic == "referee/events":
            self.truth += [_call(e) for e in message.events if e.kind in FOUL_KINDS]
        else:
            self.autoref += [_call(e) for e in message.events if e.kind in FLOW_KINDS + FOUL_KINDS]


    def _own_contact(self, e: Contact) -> None:
        """A contact of two robots of one team: a collision unless the same two were in contact within
        ``WINDOW_S`` before (the physics' contact of one meeting begins and ends many times over)."""
        pair = (e.a, e.b) if e.a < e.b else (e.b, e.a)
        if e.t_start - self._contact_end.get(pair, -math.inf) > WINDOW_S:
            self.truth_collisions.append(Call(e.t_start, OWN_COLLISION, e.a[0]))
        self._contact_end[pair] = max(self._contact_end.get(pair, -math.inf), e.t_start + e.duration_s)


def match_calls(truth: Sequence[Call], seen: Sequence[Call], window_s: float = WINDOW_S) -> list[tuple[Call, Call]]:
    """Pairs of the same call: per truth call in time order, the earliest unpaired ``seen`` call of its
    kind and team in the same match within ``window_s``."""
    used: set[int] = set()
    pairs = []
    for c in sorted(truth, key=lambda c: (c.seed, c.t)):
        for i, s in sorted(enumerate(seen), key=lambda p: p[1].t):
            if i not in used and (s.seed, s.kind, s.team) == (c.seed, c.kind, c.team) and abs(s.t - c.t) <= window_s:
                used.add(i)
                pairs.append((c, s))
                break
    return pairs


def missed(truth: Sequence[Call], seen: Sequence[Call], window_s: float = WINDOW_S) -> list[str]:
    """The truth's calls the autoref did not make, one line each: the match's seed and time, the
    call, and the autoref's calls of that kind within ``window_s`` of it (what it made instead)."""
    got = {id(c) for c, _ in match_calls(truth, seen, window_s)}
    out = []
    for c in sorted(truth, key=lambda c: (c.seed, c.t)):
        if id(c) in got:
            continue
        near = [s for s in seen if (s.seed, s.kind) == (c.seed, c.kind) and abs(s.t - c.t) <= window_s]
        instead = ", ".join(f"{s.team} at {s.t - c.t:+.2f} s" for s in near) or "none"
        out.append(f"seed {c.seed} {c.t:.2f} s {c.kind} {c.team} (autoref's: {instead})")
    return out


def rows(truth: Sequence[Call], seen: Sequence[Call], window_s: float = WINDOW_S) -> list[dict[str, Any]]:
    """Per kind (those either made) and per group (goals and outs, fouls, all): the truth's calls,
    the share the autoref made too, the autoref's calls and those of its own; per kind, the truth's
    calls it missed (:func:`missed`). Own collisions (:data:`OWN_COLLISION`), when either side has
    any, come last in a row of their own, in no group."""
    pairs = match_calls(truth, seen, window_s)
    matched_seen = {id(s) for _, s in pairs}

    def row(name: str, kinds: Iterable[str], listed: bool = True) -> dict[str, Any]:
        ks = set(kinds)
        t = [c for c in truth if c.kind in ks]
        s = [c for c in seen if c.kind in ks]
        both = sum(1 for c, _ in pairs if c.kind in ks)
        own = sum(1 for c in s if id(c) not in matched_seen)
        return {"name": name, "truth_calls": len(t), "matched": both,
                "matched_share": both / len(t) if t else None, "autoref_calls": len(s), "own_calls": own,
                "own_share": own / len(s) if s else None,
                "missed": "; ".join(missed(t, s, window_s)) if listed else ""}

    order = (*FLOW_KINDS, *FOUL_KINDS, OWN_COLLISION)
    kinds = sorted({c.kind for c in (*truth, *seen)}, key=order.index)
    return [*(row(k, [k]) for k in kinds if k != OWN_COLLISION), row("goals_and_outs", FLOW_KINDS, False),
            row("fouls", FOUL_KINDS, False), row("all", FLOW_KINDS + FOUL_KINDS, False),
            *([row(OWN_COLLISION, [OWN_COLLISION])] if OWN_COLLISION in kinds else [])]


def watch(settings: Settings, seed: int, seconds: float) -> tuple[list[Call], list[Call]]:
    """One match of ``seconds`` (full rules, halves as long as the match), the truth referee driving and
    the autoref watching: both referees' calls, each with the own collisions (:data:`OWN_COLLISION`)
    among them."""
    ref = settings.sim.referee
    ref = dataclasses.replace(ref, rules="full", figures=dataclasses.replace(ref.figures, half_s=max(seconds, 1.0)))
    settings = dataclasses.replace(settings, sim=dataclasses.replace(settings.sim, referee=ref))
    cams = [f"detections/{m.id}" for m in settings.camera_models()]
    keys = robot_keys(settings.field, match_sim_params(settings, "simple"))
    log = CallLog()
    stages = [e.build() for e in autoref_rows(settings, cams, keys, passive=True)]
    m = Match(settings, "simple", "vision", seed=seed, extra=[*stages, log])
    m.run(seconds)
    tag = functools.partial(dataclasses.replace, seed=seed)
    return [tag(c) for c in log.truth + log.truth_collisions], [tag(c) for c in log.autoref + log.autoref_collisions]


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    seeds, seconds = ((1, 2), 20.0) if quick else (tuple(range(1, 11)), 60.0)
    truth: list[Call] = []
    seen: list[Call] = []
    for seed in seeds:
        t, s = watch(settings, seed, seconds)
        truth += t
        seen += s
    return rows(truth, seen)
