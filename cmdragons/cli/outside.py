"""``cmdragons play --simulator grsim|sim-protocol``: our team in someone else's simulator
(:mod:`cmdragons.runtime.outside`), with the embedded play's outputs: run.mcap, summary.json,
the top-down match.mp4 (``--video``) and the match report, from what our stages saw."""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from typing import Any

from cmdragons.cli.lines import plural, rules_line
from cmdragons.cli.progress import progress_bar
from cmdragons.runtime.interrupt import Interrupt

__all__ = ["play_outside"]

_OTHER = {"blue": "yellow", "yellow": "blue"}


def _refused(args: argparse.Namespace) -> str | None:
    """Why these options cannot play in an outside simulator (None: they can)."""
    if args.opponent not in (None, "none", "self"):
        return (f"--opponent {args.opponent} plays in our own simulator; in an outside one the other side is our "
                "team too (self) or its robots stand idle (none)")
    if args.perception not in (None, "vision"):
        return "--perception truth needs our own simulator's truth: an outside simulator's vision is all we see"
    if args.distributed:
        return "--distributed splits our own simulator's match into processes: leave it out"
    if args.video and args.view == "cameras":
        return "--view cameras draws our own simulator's camera images: an outside simulator has the field view only"
    if args.opponent_set and args.opponent != "self":
        return "--opponent-set configures a copy of our team: it needs --opponent self"
    return None


def play_outside(args: argparse.Namespace, stop: Interrupt, compile_kernels: Callable[..., float]) -> int:
    """The match (``compile_kernels``: play's first-run compile step, run before listening: a
    compile under way would leave the simulator's vision piling up)."""
    from cmdragons.messages import GameState
    from cmdragons.runtime.bus import Stage
    from cmdragons.runtime.log import RunLog, run_folder
    from cmdragons.runtime.outside import (
        OutsideError,
        OutsideMatch,
        SimulatorKind,
        field_settings,
        listen,
        outside_settings,
        vision_params,
    )
    from cmdragons.runtime.overlay import MatchVideoStage
    from cmdragons.runtime.report import ReportStage
    from cmdragons.runtime.scene import SceneStage
    from cmdragons.runtime.ssl.udp import MulticastReceiver
    from cmdragons.runtime.stages import LoggerStage, Tap
    from cmdragons.runtime.warmup import settle_heap, warm_team

    why = _refused(args)
    if why is not None:
        print(f"cmdragons play --simulator {args.simulator}: {why}", file=sys.stderr)
        return 2
    kind = SimulatorKind(args.simulator)
    overrides = list(args.set) + ([f"sim.referee.rules={args.rules}"] if args.rules else [])
    settings = outside_settings(args.config, overrides)
    ours = args.team
    teams = [ours, _OTHER[ours]] if args.opponent == "self" else [ours]
    p = vision_params(settings.protocols, kind)
    where = f"{p.vision.group}:{p.vision.port}"
    compile_kernels(args, settings, False, lambda: None)
    receiver = MulticastReceiver(p.vision.group, p.vision.port, p.interface, p.receive_buffer_bytes,
                                 p.max_datagram_bytes)
    match: OutsideMatch | None = None
    log = video = None
    try:
        print(f"play: listening for the simulator's SSL-Vision on {where} ...", file=sys.stderr, flush=True)
        o = settings.protocols.outside
        try:
            heard = listen(receiver, o.geometry_timeout_s, o.learn_s, where)
            settings, line = field_settings(settings, heard.geometry)
            heard = _division_only(settings, p, heard, receiver, where)
        except OutsideError as exc:
            print(f"cmdragons play --simulator {args.simulator}: {exc}", file=sys.stderr)
            return 2
        if line is not None:
            print(f"play: {line}", file=sys.stderr)
        geometry = settings.field_geometry()
        folder = run_folder("play", args.out, overwrite=args.overwrite)
        log = RunLog(folder / "run.mcap")
        game = [GameState(0.0)]
        scene = SceneStage(log, geometry, settings.field.robot.radius_m, settings.field.robot.height_m,
                           settings.field.ball.radius_m)
        report = ReportStage(ours, positions=f"world/{ours}")
        extra: list[Stage] = [LoggerStage(log), scene, report,
                              Tap("progress", ("referee",), lambda _topic, g: game.__setitem__(0, g))]
        if args.video:  # drawn from the log once the match is over: the match is in real time
            video = MatchVideoStage(folder / "match.mp4", "field", ours, [], geometry, settings.field.robot.radius_m,
                                    settings.field.robot.height_m, settings.sim.physics.frame_rate_hz)
        warm_team(settings)
        match = OutsideMatch(settings, kind, teams, heard, receiver, extra)
        settle_heap()
        match.skip_stale()  # what came while the team was built is gone by now
        started = time.time()
        with progress_bar(not args.no_progress, counts=False) as progress, stop.soft():
            task = progress.add_task("play", total=args.seconds, info="")

            def shown(i: int) -> None:
                if i % 15 == 0:
                    assert match is not None
                    info = f"t={match.seconds:6.1f}s  {game[0].command}  behind {match.frames_behind}"
                    progress.update(task, completed=min(match.seconds, args.seconds), info=info)

            wall0 = time.perf_counter()
            match.run(args.seconds, lambda: stop.requested, shown)
        with stop.shield():
            wall = time.perf_counter() - wall0
            summary = match.summary()
    finally:
        with stop.shield():
            if match is not None:
                match.close()
            else:
                receiver.close()
            if log is not None:
                log.close()
            if video is not None and log is not None:
                _draw(video, folder / "run.mcap", ours)
    with stop.shield():
        summary["interrupted"] = stop.requested
        summary["started_utc"] = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(started))
        summary["wall_seconds"] = round(wall, 3)
        summary["realtime_factor"] = round(summary["seconds"] / wall, 2) if wall > 0 else None
        if line is not None:
            summary["field_differs"] = line
        _finish(folder, report.collector.result(), summary, args, (geometry.half_length, geometry.half_width))
    return stop.exit_code


def _division_only(settings: Any, params: Any, heard: Any, receiver: Any, where: str) -> Any:
    """What the simulator's vision shows once the robots beyond the division's count a team are
    taken off its field (none beyond: ``heard`` as it is); :class:`OutsideError` when they stay."""
    from cmdragons.runtime.outside import OutsideError, beyond_division, listen, take_off

    per_team = settings.field.dims.robots_per_team
    extra = beyond_division(heard.robots, per_team)
    if not extra:
        return heard
    print(f"play: the simulator has {len(extra)} robots beyond Division {settings.field.division}'s {per_team} a "
          f"team: taken off its field ({', '.join(f'{t} {i}' for t, i in extra)})", file=sys.stderr, flush=True)
    take_off(params, extra)
    o = settings.protocols.outside
    time.sleep(o.learn_s)  # the frames that still show them, passed
    receiver.drain()
    heard = listen(receiver, o.geometry_timeout_s, o.learn_s, where)
    still = beyond_division(heard.robots, per_team)
    if still:
        raise OutsideError(f"{len(still)} robots beyond the division's {per_team} a team stay on the simulator's "
                           "field after being taken off (present: false)")
    return heard


def _draw(video: Any, log: Any, ours: str) -> None:
    """The match video from the match's log (its topics in the order the match wrote them)."""
    from cmdragons.runtime.log import read_log

    try:
        for topic, _t, message in read_log(log, {f"/{t}" for t in video.inputs if "*" not in t}):
            video.on_message(topic[1:], message, lambda *_: None)
    finally:
        video.close()


def _finish(folder: Any, run: Any, summary: dict[str, Any], args: argparse.Namespace,
            half_size_m: tuple[float, float]) -> None:
    """summary.json, the report and the summary lines; the last names the output folder."""
    from cmdragons.runtime.report import run_warnings, write_report

    summary["warnings"] = run_warnings(run, summary)
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    report = write_report(run, summary, folder / "report.png", half_size_m) if run.frames else None
    brain = summary["cycle_ms"].get("brain", {})
    cams = ", ".join(map(str, summary["cameras"]))
    length, width = summary["field_m"]
    sides = "both colours ours" if len(summary["teams"]) > 1 else f"{summary['teams'][0]} ours, the other side idle"
    print(f"play: {summary['seconds']:.1f} s in {args.simulator} ({sides}) in {summary['wall_seconds']:.1f} s "
          f"({summary['realtime_factor']}x real time): {summary['frames']} frames, {summary['frames_behind']} "
          f"came while we were busy; brain {brain.get('median', float('nan')):.2f} ms median, "
          f"{brain.get('p95', float('nan')):.2f} ms p95; cameras {cams}; field {length:g} x {width:g} m "
          f"(division {summary['division']})")
    if "score" in summary:  # refereed by ours on the tracked world
        score = summary["score"]
        own = summary["collisions"]["own"]
        collided = ", ".join(f"{team} {plural(n, 'own collision')}" for team, n in own.items())
        print(f"play: refereed on our tracked world: blue {score['blue']}:{score['yellow']} yellow, "
              f"{plural(summary['balls_out'], 'ball')} out, {plural(summary['kicks'], 'kick')} seen; {collided}")
        if summary["rules"].get("rules") == "full":
            print("play: " + rules_line(summary["rules"], args.team))
    for w in summary["warnings"]:
        print(f"play: warning: {w}")
    files = ["run.mcap", "summary.json"] + (["match.mp4"] if args.video and (folder / "match.mp4").exists() else [])
    files += [report.name] if report is not None else []
    print(f"play: {', '.join(files)} -> {folder}")
