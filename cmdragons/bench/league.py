"""``cmdragons bench league``: our team in the league's simulators, refereed by our autoref.

Each row is one match of ``cmdragons play --simulator grsim|sim-protocol`` run as its own process
beside a simulator: our own served simulator (``cmdragons sim --serve``, a second process, over the
simulation protocol), grSim (its own packets) and the ER-Force simulator (the simulation protocol),
each in Division B (6 v 6) and, without ``--quick``, Division A (11 v 11); our team against itself
(``--opponent self``: both colours ours) and against the simulator's idle robots (``--opponent
none``). grSim and the ER-Force simulator multicast with no pinned interface, so they run only
through the scripts that keep them in a network namespace of their own (:func:`peer_script`); a row
whose simulator or script is not found is skipped with the reason.

What a row says, all from the match's summary.json and run.mcap (what our stages saw):

- goals as our autoref called them, beside the goals the simulator's own SSL-Vision shows (its raw
  ball detections crossing a goal line between the posts while the ball was in play, the team by
  the sides the referee gave then: :func:`vision_goals`) and, in our served simulator, its truth
  (the true ball across a goal line, both ends together, while the ball was in play by the referee
  and within the match: :func:`truth_goals`);
- fouls per team; own collisions (the autoref's count from tracks, :class:`sim.autoref.OwnContacts`);
- the first kickoff: how long until play ran, and whether it was taken (a normal start) or forced
  after the rules' time (:func:`first_start`); how far the ball was played (:func:`ball_in_play_m`);
- stoppages (play not running: from a stop to the next normal or force start): how many, how many
  restarted before the match ended, the longest, and how many took longer than the rules allow
  (:func:`rules_stoppage_s`);
- frames: the simulator's vision frames played on and those passed over (``frames_behind``: they
  came while our loop was busy with an earlier one);
- the ball's rolling deceleration our tracker learnt, against the configured one and the
  simulator's (ours: its world; grSim's measured 0.70 m/s²; the ER-Force simulator's unknown);
- passes tried and completed, followed on the autoref's tracked world (:func:`seen_passes`: the
  pass recorder of the embedded matches, fed the autoref's tracks instead of the truth);
- match seconds (vision's clock) and wall seconds.

``--quick``: Division B, two halves of 30 s; the full suite two halves of 120 s in both divisions
(``--half S``: halves of S seconds).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cmdragons.bench.play import GRSIM_BALL_ROLL_M_S2
from cmdragons.geometry import Field, FieldDims, Team
from cmdragons.messages import (
    DetectionFrame,
    GameStage,
    GameState,
    Goal,
    GroundTruth,
    RefereeCommand,
    TeamReport,
    WorldState,
)
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.ssl.udp import free_udp_ports
from sim.autoref import BallCrossing, KickDetector, observed
from sim.referee_params import RefereeParams
from sim.restarts import defender_of, other

__all__ = ["OPPONENTS", "PEERS", "Peer", "Stoppages", "ball_in_play_m", "first_start", "league_row", "match_row",
           "peer_script", "rules_stoppage_s", "run", "seen_passes", "stoppages", "truth_clock_offset", "truth_goals",
           "vision_goals"]

OPPONENTS = ("self", "none")  # whom our team plays: itself in the other colour, or the simulator's idle robots
_OTHER: dict[Team, Team] = {"blue": "yellow", "yellow": "blue"}
_PLAY_SLACK_S = 300.0  # a match process gets its match time three times over and this (compile, listening)


@dataclass(frozen=True)
class Peer:
    """A simulator of the league's: how our team plays in it (``simulator``: play's --simulator), the
    script that runs it in a network namespace of its own with a command beside it (``script``,
    found by :func:`peer_script`; None: our own, served in a second process), its binary, the flags
    that pick each division, and its ball's rolling deceleration where known (m/s²)."""

    name: str
    simulator: str
    script: str | None = None  # the script's file name; an environment variable NAME_NETNS names it too
    binary_env: str = ""  # the environment variable that names the binary (the script's own)
    binary: str = ""  # ... and the binary where the script looks without it
    division_flags: tuple[tuple[str, tuple[str, ...]], ...] = ()
    ball_roll_m_s2: float | None = None

    def flags(self, division: str) -> list[str]:
        return list(dict(self.division_flags)[division])


PEERS = (
    Peer("served", "sim-protocol"),
    Peer("grsim", "grsim", "grsim-netns.sh", "GRSIM", "/opt/grsim/bin/grSim",
         (("B", ("--division", "B")), ("A", ("--division", "A"))), GRSIM_BALL_ROLL_M_S2),
    Peer("erforce", "sim-protocol", "erforce-netns.sh", "ERFORCE", "/opt/erforce/bin/erforce-simulator-cli",
         (("B", ("--geometry", "2020B")), ("A", ("--geometry", "2020")))),
)


_CHECKOUT = Path(__file__).resolve().parents[2]  # this checkout: the league's simulators may be beside it


def peer_script(peer: Peer, checkout: Path = _CHECKOUT) -> tuple[str | None, str]:
    """The script that runs ``peer`` in a network namespace of its own: ``<NAME>_NETNS`` (``GRSIM_NETNS``),
    else the script on PATH, else the league's simulators beside this checkout (``../shared/peers``);
    with the reason when there is none, or no binary for it."""
    assert peer.script is not None
    env = f"{peer.name.upper()}_NETNS"
    beside = checkout.parent / "shared" / "peers" / peer.script
    candidates = [os.environ.get(env), shutil.which(peer.script), str(beside)]
    script = next((c for c in candidates if c and os.access(c, os.X_OK)), None)
    binary = os.environ.get(peer.binary_env, peer.binary)
    if script is None:
        return None, (f"no {peer.script}: set {env} to a script that runs {peer.name} in a network namespace of its "
                      "own with a command beside it (it multicasts with no pinned interface)")
    if not os.access(binary, os.X_OK):
        return None, f"no {peer.name} binary at {binary} (set {peer.binary_env})"
    return script, ""


# --- what a match's log shows ------------------------------------------------------------------------


def _in_play(g: GameState) -> bool:
    """The ball in play or about to be (a goal then counts): normal play, a restart, a penalty started."""
    return g.command.running or g.command.kick_restart or (g.command == RefereeCommand.PENALTY and g.ready)


def vision_goals(messages: Iterable[tuple[str, Any]], pitch: Field) -> dict[Team, int]:
    """Goals in the simulator's own vision: per camera frame (``ssl/vision/<id>`` messages, in capture
    order, the referee's ``referee`` game states among them) its surest ball, across a goal line
    between the posts (:class:`~sim.autoref.BallCrossing`) while the ball is in play; the scorer by
    the sides the referee gave at that moment; one goal until the referee stops play (a ball seen back
    out of the goal and in again, on the line, is the same goal). The ball must have come from where it
    was last seen on the field no faster than :data:`_BALL_MAX_M_S`: a stray detection on the field
    (the ER-Force simulator's, at a robot's front) between two views of a ball lying in a goal is no
    ball that went in (one left in a goal at half time was counted at the kickoff, the sides changed)."""
    crossing = BallCrossing(pitch)
    game = GameState(0.0)
    goals: dict[Team, int] = {"blue": 0, "yellow": 0}
    scored = False  # a goal counted since play last stopped
    on_field: tuple[float, float, float] | None = None  # the ball last seen on the field: (t, x, y)
    reach = pitch.half_length + pitch.league.ball.radius_m
    for topic, m in messages:
        if topic == "referee":
            game = m
            scored = scored and _in_play(game)
            continue
        frame: DetectionFrame = m
        if not frame.balls:
            continue
        b = max(frame.balls, key=lambda b: b.confidence)
        sign = -1 if game.blue_defends_negative_x else 1
        t = frame.t_capture
        seen = crossing.see(t, b.x, b.y, sign, None)
        came = on_field is not None and math.hypot(b.x - on_field[1], b.y - on_field[2]) <= _BALL_MAX_M_S * max(
            t - on_field[0], 0.0)
        if isinstance(seen, Goal) and _in_play(game) and not scored and came:
            goals[other(defender_of(b.x, sign))] += 1
            scored = True
        if abs(b.x) <= reach and abs(b.y) <= pitch.half_width + pitch.league.ball.radius_m:
            on_field = (t, b.x, b.y)
    return goals


_BALL_MAX_M_S = 10.0  # no ball runs faster (the rules allow a kick 6.5 m/s): a longer jump is another detection
_SAME_FRAME_S = 1e-3  # two clocks' times this near are one frame's (frames 1/60 s apart; times off by float rounding)


def truth_goals(truths: Iterable[GroundTruth], pitch: Field, states: Sequence[GameState] | None = None,
                until: float = math.inf) -> int:
    """Goals in a simulator's truth, both ends: the true ball across a goal line between the posts; with
    the referee's game ``states`` (in time order, on the truth's clock) only while the ball was in play
    by them and from the first of them, and none after ``until`` (s; the match's last frame): the
    simulator runs on before a team joins and after it leaves, when no referee counts a goal. The
    state in force at a truth frame is the last one given before it: the referee's word of the same
    frame (within :data:`_SAME_FRAME_S`) already follows what it saw there, the goal's stop included."""
    crossing = BallCrossing(pitch)
    states = states or ()
    game: GameState | None = None if states else GameState(0.0, RefereeCommand.NORMAL)
    goals = k = 0
    for g in truths:
        while k < len(states) and states[k].t < g.t - _SAME_FRAME_S:
            game, k = states[k], k + 1
        seen = crossing.see(g.t, g.ball.x, g.ball.y, -1, None)
        goals += isinstance(seen, Goal) and game is not None and _in_play(game) and g.t <= until
    return goals


def first_start(states: Iterable[GameState]) -> tuple[float | None, bool]:
    """The match's first kickoff: how long (s) from the first game state until play first ran, and
    whether it was taken (a normal start: the kicker moved the ball) rather than forced after the
    rules' time (None, False: play never ran)."""
    t0: float | None = None
    for g in states:
        t0 = g.t if t0 is None else t0
        if g.command.running:
            return g.t - t0, g.command == RefereeCommand.NORMAL
    return None, False


def ball_in_play_m(messages: Iterable[tuple[str, Any]]) -> float:
    """How far the ball was played (m): the path of the autoref's tracked ball (``world/autoref``)
    while play ran by the referee (``referee``: a normal or force start), from where it was last
    seen to where it is seen next; a ball the referee placed while play stood (a restart's
    teleport) does not count."""
    last: tuple[float, float] | None = None  # where the ball was last seen while play ran
    running = False
    path = 0.0
    for topic, m in messages:
        if topic == "referee":
            running = m.command.running
            last = last if running else None
            continue
        ball = m.ball
        if not running or ball is None or not ball.visible:
            continue
        if last is not None:
            path += math.dist((ball.x, ball.y), last)
        last = (ball.x, ball.y)
    return path


def truth_clock_offset(truths: Sequence[GroundTruth], frames: Iterable[DetectionFrame]) -> float:
    """The served simulator's truth clock less our match clock (s): the served clock runs from its
    own start, ours from the first frame our match played on (both in whole seconds of Unix time
    on the wire), so they differ by how long the served simulator ran before; taken from the first
    of our detection ``frames`` whose frame number the ``truths`` have (0 when none has)."""
    at = {g.frame_number: g.t for g in truths}
    for frame in frames:
        if frame.frame_number in at:
            return round(at[frame.frame_number] - frame.t_capture, 3)  # (whole seconds, less float rounding)
    return 0.0


@dataclass(frozen=True)
class Stoppages:
    """Play stopped (from a game state that is not normal or force start to the next that is), the
    match over left out: how many, how many were restarted before the match ended, the longest
    (s; one never restarted: until the match's end) and how many lasted longer than ``limit_s``."""

    count: int
    restarted: int
    longest_s: float
    over_limit: int


def stoppages(states: Iterable[GameState], end_t: float, limit_s: float) -> Stoppages:
    """The stoppages of a match's game states (in time order) up to ``end_t`` (s)."""
    spans: list[tuple[float, bool]] = []  # duration, restarted
    since: float | None = None
    for g in states:
        stopped = not g.command.running and g.stage != GameStage.POST_GAME
        if stopped and since is None:
            since = g.t
        elif not stopped and since is not None:
            spans.append((g.t - since, g.command.running))
            since = None
    if since is not None:
        spans.append((end_t - since, False))
    return Stoppages(len(spans), sum(r for _, r in spans), max((d for d, _ in spans), default=0.0),
                     sum(d > limit_s for d, _ in spans))


def rules_stoppage_s(referee: RefereeParams) -> float:
    """The longest a stoppage may last by the rules the referee applies (s): the delay before the
    restart, the placement's time, the preparation's and the longest a restart may wait to be taken."""
    f = referee.figures
    return referee.restart_delay_s + f.placement_time_s + f.prepare_timeout_s + max(referee.restart_timeout_s,
                                                                                    f.penalty_time_s)


def seen_passes(messages: Iterable[tuple[str, Any]], team: Team, settings: Settings) -> dict[str, Any]:
    """``team``'s passes as the autoref's tracks show them: the embedded matches' pass recorder fed the
    autoref's tracked world (``world/autoref``) for the truth, the team's reports (``report/<team>``:
    what each kick was meant for) and the referee's word, each kick from the autoref's kick detector
    (a touch by a robot of ``team``; the same robot's touch seen again is no new one, as the autoref
    has it). ``settings``: on the simulator's field."""
    from cmdragons.runtime.pass_record import PassRecorder

    recorder = PassRecorder.of(team, settings)
    detector = KickDetector(settings.field_geometry(), settings.sim.referee.autoref)
    report: TeamReport | None = None
    last: tuple[Team, int] | None = None
    ball = (0.0, 0.0)
    for topic, m in messages:
        if topic == "referee":
            recorder.referee(m)
        elif topic == f"report/{team}":
            report = m
            recorder.report(m)
        elif topic == "world/autoref":
            world: WorldState = m
            ball = (world.ball.x, world.ball.y) if world.ball is not None else ball
            gt = observed(world, ball)
            kick = detector.see(world)
            if kick is not None and (kick.team, kick.id) != last:
                last = (kick.team, kick.id)
                if kick.team == team:
                    action = report.actions.get(kick.id) if report is not None else None
                    recorder.kick(kick, action, gt)
            recorder.truth(gt)
    return recorder.summary()


def _on_field(settings: Settings, summary: dict[str, Any]) -> Settings:
    """``settings`` on the field the match was played on (its summary's division and sizes)."""
    league = settings.field
    division = summary["division"]
    dims = FieldDims(**summary["field"])
    return dataclasses.replace(settings, field=dataclasses.replace(
        league, division=division, divisions={**league.divisions, division: dims}))


def league_row(name: str, folder: Path, settings: Settings, truth_log: Path | None = None,
               simulator_roll_m_s2: float | None = None) -> dict[str, Any]:
    """One row from a match's output ``folder`` (summary.json, run.mcap; our team the summary's first
    colour) and, for our served simulator, its run.mcap ``truth_log``."""
    from cmdragons.runtime.log import read_log

    summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    played = _on_field(settings, summary)
    pitch = played.field_geometry()
    teams: list[Team] = summary["teams"]
    ours, theirs = teams[0], _OTHER[teams[0]]
    cams = {f"/ssl/vision/{c}" for c in summary["cameras"]}
    log = folder / "run.mcap"
    topics = cams | {"/referee", "/world/autoref", f"/report/{ours}"}
    events = [(topic[1:], m) for topic, _t, m in read_log(log, topics)]
    goals_seen = vision_goals(((t, m) for t, m in events if t == "referee" or t.startswith("ssl/vision/")), pitch)
    states = [m for t, m in events if t == "referee"]
    end_t = max((m.t for t, m in events if t == "world/autoref"), default=0.0)
    stops = stoppages(states, end_t, rules_stoppage_s(played.sim.referee))
    kickoff_s, kickoff_taken = first_start(states)
    ball_m = ball_in_play_m((t, m) for t, m in events if t in ("referee", "world/autoref"))
    passes = seen_passes(((t, m) for t, m in events if not t.startswith("ssl/vision/")), ours, played)
    fouls = summary["rules"]["fouls"]
    contacts = summary["collisions"]["own"]
    roll = summary["tracker"][ours].get("physics", {}).get("ball_roll", {})
    truth = None
    if truth_log is not None:
        truths = [m for _topic, _t, m in read_log(truth_log, {"/truth"})]
        offset = truth_clock_offset(truths, (m for t, m in events if t.startswith("ssl/vision/")))
        on_truth = [dataclasses.replace(g, t=g.t + offset) for g in states]
        truth = truth_goals(truths, pitch, on_truth, end_t + offset)
    tried = passes["tried"]
    return {
        "name": name,
        "goals_ours": summary["score"][ours], "goals_theirs": summary["score"][theirs],
        "goals_vision_ours": goals_seen[ours], "goals_vision_theirs": goals_seen[theirs],
        "goals_truth": truth,
        "fouls_ours": fouls[ours]["total"], "fouls_theirs": fouls[theirs]["total"],
        "fouls_ours_by_kind": ", ".join(f"{k.replace('_', ' ')} {n}" for k, n in fouls[ours].items()
                                        if k != "total") or "none",
        "own_collisions_ours": contacts[ours], "own_collisions_theirs": contacts[theirs] if theirs in teams else None,
        "first_kickoff_s": None if kickoff_s is None else round(kickoff_s, 2), "first_kickoff_taken": kickoff_taken,
        "ball_in_play_m": round(ball_m, 2),
        "stoppages": stops.count, "stoppages_restarted": stops.restarted,
        "longest_stoppage_s": round(stops.longest_s, 2), "stoppages_over_rules": stops.over_limit,
        "frames": summary["frames"], "frames_behind": summary["frames_behind"],
        "ball_roll_learnt_m_s2": roll.get("value_m_s2"), "ball_roll_configured_m_s2": roll.get("configured_m_s2"),
        "ball_roll_simulator_m_s2": simulator_roll_m_s2, "ball_roll_windows": roll.get("samples", 0),
        "passes_tried": tried, "passes_completed": passes["completed"],
        "pass_completion": passes["completed"] / tried if tried else None,
        "match_s": summary["seconds"], "wall_s": summary["wall_seconds"],
    }


# --- running the matches ------------------------------------------------------------------------------


def _cmdragons(*args: Any) -> list[str]:
    return [sys.executable, "-m", "cmdragons.cli", *map(str, args)]


def _common(config: str | None, sets: Sequence[str]) -> list[str]:
    return [*(["--config", config] if config else []), *(x for s in sets for x in ("--set", s))]


def _play(peer: Peer, opponent: str, seconds: float, out: Path, common: list[str]) -> list[str]:
    return _cmdragons("play", "--simulator", peer.simulator, "--opponent", opponent, "--seconds", seconds,
                      "--no-progress", "--overwrite", "--out", out, *common)


def _run(cmd: list[str], timeout_s: float, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s, env=env)


def _failed(name: str, done: subprocess.CompletedProcess[str]) -> str:
    said = (done.stderr.strip() or done.stdout.strip()).splitlines()
    return f"{name}: the match ended with exit code {done.returncode}: {said[-1] if said else 'nothing said'}"


def _served_match(division: str, opponent: str, seconds: float, folder: Path, config: str | None,
                  sets: Sequence[str]) -> tuple[subprocess.CompletedProcess[str], Path]:
    """``sim --serve`` in one process, our team's play in another, on ports free now; the served
    referee watches without placing anything (``place_by: robots``: ours is the autoref, which
    teleports), its run.mcap keeping the truth."""
    vision, referee, control, blue, yellow = free_udp_ports(5)
    ports = [f"protocols.simulation.vision_port={vision}", f"protocols.referee.port={referee}",
             f"protocols.simulation.control_port={control}", f"protocols.simulation.blue_port={blue}",
             f"protocols.simulation.yellow_port={yellow}"]
    served_out = folder / "served"
    server = subprocess.Popen(_cmdragons("sim", "--serve", "--division", division, "--no-progress", "--overwrite",
                                         "--out", served_out, *_common(config, [*sets, *ports,
                                                                               "sim.referee.place_by=robots"])),
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        done = _run(_play(PEERS[0], opponent, seconds, folder / "ours", _common(config, [*sets, *ports])),
                    3 * seconds + _PLAY_SLACK_S)
    finally:
        if server.poll() is None:
            server.send_signal(signal.SIGINT)
        try:
            server.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            server.kill()
            server.communicate()
    return done, served_out / "run.mcap"


def _peer_match(peer: Peer, script: str, division: str, opponent: str, seconds: float, folder: Path,
                config: str | None, sets: Sequence[str]) -> subprocess.CompletedProcess[str]:
    """Our team's play beside ``peer``, both inside the peer's network namespace (its script)."""
    timeout_s = 3 * seconds + _PLAY_SLACK_S
    env = {**os.environ, f"{peer.name.upper()}_TIMEOUT": str(round(timeout_s))}
    return _run([script, *peer.flags(division), *_play(peer, opponent, seconds, folder / "ours",
                                                       _common(config, sets))], timeout_s + 30, env)


def _match_sets(half_s: float) -> list[str]:
    """Full rules, halves of ``half_s`` and no half-time break to wait out (the bench's matches)."""
    return ["sim.referee.rules=full", f"sim.referee.figures.half_s={half_s:g}", "sim.referee.figures.half_time_s=0"]


def match_row(settings: Settings, peer: Peer, division: str, opponent: str, half_s: float, out: Path,
              config: str | None = None, overrides: Sequence[str] = ()) -> dict[str, Any]:
    """One row: our team against ``opponent`` in ``peer``'s ``division``, two halves of ``half_s``,
    its output in ``out/<row name>``; a row that says why when the peer is not found (``skipped``) or
    the match failed (``failed``)."""
    name = f"{peer.name}_{division}_{opponent}"
    script, why = peer_script(peer) if peer.script is not None else (None, "")
    if peer.script is not None and script is None:
        return {"name": name, "skipped": why}
    folder = out / name
    seconds = 2.0 * half_s
    sets = [*overrides, *_match_sets(half_s)]
    wall = time.perf_counter()
    truth: Path | None = None
    if script is None:
        done, truth = _served_match(division, opponent, seconds, folder, config, sets)
        roll: float | None = settings.sim.world_ball().acc_roll_m_s2
    else:
        done = _peer_match(peer, script, division, opponent, seconds, folder, config, sets)
        roll = peer.ball_roll_m_s2
    if done.returncode != 0 or not (folder / "ours" / "summary.json").exists():
        return {"name": name, "failed": _failed(name, done)}
    row = league_row(name, folder / "ours", settings, truth if truth is not None and truth.exists() else None, roll)
    row["bench_wall_s"] = round(time.perf_counter() - wall, 1)
    return row


def run(settings: Settings, quick: bool, half: float | None = None, config: str | None = None,
        overrides: Sequence[str] = (), out: str | Path = "logs/bench-league") -> list[dict[str, Any]]:
    """The suite's rows: per division, simulator and opponent one match of two halves (``half`` s;
    default 30 with ``quick``, else 120), its output under ``out``. ``config`` and ``overrides``:
    the bench's own --config and --set, which every match's processes take too."""
    half = half or (30.0 if quick else 120.0)
    rows: list[dict[str, Any]] = []
    for division in ("B",) if quick else ("B", "A"):
        for peer in PEERS:
            for opponent in OPPONENTS:
                print(f"bench league: {peer.name} {division} against {opponent} (2 x {half:g} s) ...",
                      file=sys.stderr, flush=True)
                rows.append(match_row(settings, peer, division, opponent, half, Path(out), config, overrides))
                print(f"bench league: {json.dumps(rows[-1])}", file=sys.stderr, flush=True)  # kept if stopped
    return rows
