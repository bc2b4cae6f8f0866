"""The distributed runtime's commands: ``cmdragons node ROLE``, ``cmdragons play --distributed``,
``cmdragons replay LOG.mcap`` and ``cmdragons log info LOG.mcap``. Zenoh is imported only here and
in the runtime, when one of these runs, so the embedded ``cmdragons play`` never loads it."""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cmdragons.runtime.interrupt import Interrupt

__all__ = ["add_parsers", "cmd_log", "cmd_node", "cmd_replay", "play_distributed"]


def _match_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--opponent", choices=("simple", "defend", "self", "none", "outside"), default="simple",
                   help="as cmdragons play: every node of a match must be given the same")
    p.add_argument("--perception", choices=("vision", "truth"), default="vision", help="as cmdragons play")
    p.add_argument("--seed", type=int, default=None, help="override sim.seed (every node the same)")


def _non_negative(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (value >= 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be 0 or more, got {text}")
    return value


def _speed(text: str) -> float:
    value = _non_negative(text)
    if value == 0:
        raise argparse.ArgumentTypeError("must be above 0")
    return value


def add_parsers(sub: Any, common: Callable[[argparse.ArgumentParser, str], None]) -> None:
    from cmdragons.runtime.params import ROLES

    p = sub.add_parser("node", help="run one part of a match as a process on zenoh (see configs/runtime.yaml)")
    common(p, "runtime.lockstep_wait_s=5")
    p.add_argument("role", choices=ROLES, help="which part: " + ", ".join(ROLES))
    _match_args(p)
    p.add_argument("--seconds", type=float, default=30.0, help="sim: match time in simulated seconds (default 30)")
    p.add_argument("--realtime", action="store_true", help="sim: free-running at the wall clock (real hardware)")
    p.add_argument("--router", action="store_true", help="sim: also be the zenoh router the other nodes connect to")
    p.add_argument("--roles", default=None,
                   help="sim: the nodes to wait for, comma-separated (default: all a match needs, log included)")
    p.add_argument("--out", metavar="DIR", default=None, help="log and sim: the run folder (default logs/<time>-play)")
    p.add_argument("--overwrite", action="store_true", help="let --out replace the run already in that folder")

    p = sub.add_parser("replay", help="publish a run's MCAP log on zenoh again (for a team node, a viewer, ...); "
                       "a league log (.log, .log.gz) plays into our tracker and brain")
    common(p, "runtime.field_name=lab")
    p.add_argument("path", metavar="LOG", help="a run's run.mcap, or a league log (SSL_LOG_FILE: .log or .log.gz)")
    p.add_argument("--team", choices=("blue", "yellow"), default="blue",
                   help="league log: the team our tracker and brain play (default blue)")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="league log: the run folder for run.mcap and summary.json (default logs/<time>-replay)")
    p.add_argument("--overwrite", action="store_true", help="let --out replace the run already in that folder")
    p.add_argument("--own", action="store_true",
                   help="league log: a match our team played with this config; the tracker takes the brain's commands "
                   "as the robots' control input, as in the match (without: the detections alone)")
    p.add_argument("--from", dest="start", type=_non_negative, default=0.0, metavar="S",
                   help="start S seconds into the log (default 0)")
    p.add_argument("--speed", type=_speed, default=1.0, metavar="X",
                   help="X times the log's pace (default 1: as recorded)")
    p.add_argument("--skip", action="append", default=[], metavar="TOPIC",
                   help="leave out a topic or pattern (repeatable), e.g. --skip 'commands/blue' for a live blue team")
    p.add_argument("--wait", default=None, metavar="ROLES",
                   help="wait for these nodes to be ready first, comma-separated (e.g. team)")
    p.add_argument("--router", action="store_true", help="also be the zenoh router the other nodes connect to")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")

    p = sub.add_parser("log", help="about a log: cmdragons log info LOG; cmdragons log convert IN OUT "
                       "(league log <-> MCAP)")
    p.add_argument("action", choices=("info", "convert"))
    p.add_argument("path", metavar="LOG", help="a run's run.mcap or a league log (.log, .log.gz)")
    p.add_argument("out", metavar="OUT", nargs="?", default=None,
                   help="convert: the file to write (a league log from an MCAP log, an MCAP log from a league log)")
    common(p, "cameras.auto.k1=-0.02")  # convert to a league log: the geometry packets' field and cameras


def _spec(args: argparse.Namespace) -> Any:
    from cmdragons.runtime.distributed import MatchSpec
    from cmdragons.runtime.settings import load_settings

    settings = load_settings(args.config, args.set)
    seed = settings.sim.seed if args.seed is None else args.seed
    return MatchSpec(settings, args.opponent, args.perception, seed)


def _log_stages(spec: Any, folder: Path) -> tuple[Any, list[Any]]:
    from cmdragons.runtime.log import RunLog
    from cmdragons.runtime.scene import SceneStage
    from cmdragons.runtime.stages import LoggerStage

    s = spec.settings
    log = RunLog(folder / "run.mcap")
    scene = SceneStage(log, s.field_geometry(), s.field.robot.radius_m, s.field.robot.height_m, s.field.ball.radius_m)
    return log, [LoggerStage(log), scene]


def _connect(params: Any, name: str, router: bool, command: str) -> tuple[Any, Any] | None:
    """The router session (when ``router``) and ``name``'s transport, on that session when there is
    one (a message to or from the router's node then crosses one link, not two); None once the
    error (no router there, or the endpoint taken) is said on one line."""
    from cmdragons.runtime.distributed import frame_path_priority
    from cmdragons.runtime.zenoh_transport import RouterError, ZenohTransport, open_router

    note = frame_path_priority(params, name)
    if note is not None:
        print(f"cmdragons {command}: {note}", file=sys.stderr)
    session = None
    try:
        session = open_router(params) if router else None
        return session, ZenohTransport(params, name, session=session)
    except RouterError as exc:
        if session is not None:
            session.close()
        print(f"cmdragons {command}: {exc}", file=sys.stderr)
        return None


def cmd_node(args: argparse.Namespace, stop: Interrupt) -> int:
    from cmdragons.runtime.distributed import run_clock, run_node, write_summary
    from cmdragons.runtime.log import run_folder
    spec = _spec(args)
    params = spec.settings.runtime
    connected = _connect(params, args.role, args.router, f"node {args.role}")
    if connected is None:
        return 2
    router, transport = connected
    log = None
    try:
        with stop.soft():
            if args.role == "sim":
                roles = args.roles.split(",") if args.roles else spec.roles(log=True)
                # the log node may share the folder (and have made run.mcap in it already)
                folder = Path(args.out) if args.out else run_folder("play")
                folder.mkdir(parents=True, exist_ok=True)
                summary = run_clock(spec, transport, args.seconds, ["sim", *roles], realtime=args.realtime,
                                    should_stop=lambda: stop.requested)
                summary["interrupted"] = stop.requested
                write_summary(folder, summary)
                s = summary.get("score", {})
                print(f"node sim: {summary.get('frames', 0)} frames, score blue {s.get('blue')}:{s.get('yellow')} "
                      f"yellow, {summary.get('realtime_factor')}x real time -> {folder}")
                return stop.exit_code
            extra: list[Any] = []
            if args.role == "log":
                folder = run_folder("play", args.out, overwrite=args.overwrite)
                log, extra = _log_stages(spec, folder)
            code = run_node(args.role, spec, transport, extra, should_stop=lambda: stop.requested)
            return stop.exit_code or code
    finally:
        with stop.shield():
            if log is not None:
                log.close()
            transport.close()
            if router is not None:
                router.close()


def play_distributed(args: argparse.Namespace, stop: Interrupt) -> int:
    """``cmdragons play --distributed``: a router here, every other node as its own process (spawned,
    never forked after zenoh opened), the clock here; Ctrl-C stops them all."""
    from cmdragons.runtime.distributed import run_clock, wait_for_processes, write_summary
    from cmdragons.runtime.log import run_folder

    spec = _spec(args)
    params = spec.settings.runtime
    folder = run_folder("play", args.out, overwrite=args.overwrite)
    roles = spec.roles(log=True)
    common = ["--config", args.config] if args.config else []
    for s in args.set:
        common += ["--set", s]
    common += ["--opponent", spec.opponent, "--perception", spec.perception, "--seed", str(spec.seed)]
    connected = _connect(params, "sim", True, "play")
    if connected is None:
        return 2
    router, transport = connected
    children: list[subprocess.Popen[bytes]] = []
    try:
        for role in roles:
            if role != "sim":
                extra = ["--out", str(folder)] if role == "log" else []
                children.append(subprocess.Popen([sys.executable, "-m", "cmdragons.cli", "node", role, *common,
                                                  *extra]))
        wall0 = time.perf_counter()
        with stop.soft():
            summary = run_clock(spec, transport, args.seconds, roles, should_stop=lambda: stop.requested)
        summary["interrupted"] = stop.requested
        summary["distributed"] = True
        summary["nodes"] = roles
        write_summary(folder, summary)
        s = summary.get("score", {})
        print(f"play --distributed: {len(roles)} nodes, {summary.get('frames', 0)} frames in "
              f"{time.perf_counter() - wall0:.1f} s ({summary.get('realtime_factor')}x real time), score blue "
              f"{s.get('blue')}:{s.get('yellow')} yellow -> {folder}")
        return stop.exit_code
    finally:
        with stop.shield():
            wait_for_processes(children)
            transport.close()
            router.close()


def _league_log(args: argparse.Namespace, path: Path) -> int:
    """``log info`` of a league log (records per type, time span) and ``log convert`` both ways."""
    from cmdragons.runtime.log import LogError
    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.ssl.convert import is_league_log, league_to_mcap, mcap_to_league
    from cmdragons.runtime.ssl.logfile import LogFileError, LogReader, MessageType

    try:
        if args.action == "convert":
            if args.out is None:
                print("cmdragons log: convert needs the file to write: cmdragons log convert IN OUT", file=sys.stderr)
                return 2
            if is_league_log(path):
                counts, cut = league_to_mcap(path, args.out)
                print(f"log convert: {path} -> {args.out}: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
                if cut is not None:
                    print(f"cmdragons log: warning: {cut}", file=sys.stderr)
            else:
                n = mcap_to_league(path, args.out, load_settings(args.config, args.set))
                print(f"log convert: {path} -> {args.out}: {n} records (SSL-Vision packets with geometry, "
                      "Referee packets)")
            return 0
        reader = LogReader(path)
        kinds: dict[str, int] = {}
        first = last = None
        for r in reader:
            name = MessageType(r.type).name if r.type in MessageType._value2member_map_ else f"type {r.type}"
            kinds[name] = kinds.get(name, 0) + 1
            first = r.receive_time_ns if first is None else first
            last = r.receive_time_ns
        span = (last - first) / 1e9 if first is not None and last is not None else 0.0
        print(f"{path}: {reader.records} records, {span:.2f} s" + (", indexed" if reader.index is not None else ""))
        for name, n in sorted(kinds.items()):
            print(f"  {name:28s} {n:7d}")
        if reader.truncated is not None:
            print(f"cmdragons log: warning: {reader.truncated}", file=sys.stderr)
        return 0
    except (LogFileError, LogError, OSError) as exc:
        print(f"cmdragons log: {exc}", file=sys.stderr)
        return 2


def cmd_log(args: argparse.Namespace) -> int:
    """``cmdragons log info LOG``: an MCAP log's topics with their schemas and counts, the duration,
    the summary; a league log's records. ``cmdragons log convert IN OUT``: league <-> MCAP."""
    from cmdragons.runtime.log import LogError, log_info
    from cmdragons.runtime.ssl.convert import is_league_log

    path = Path(args.path)
    if not path.is_file():
        print(f"cmdragons log: {path}: no such file; give a run's run.mcap or a league log", file=sys.stderr)
        return 2
    if args.action == "convert" or is_league_log(path):
        return _league_log(args, path)
    try:
        print("\n".join(log_info(path)))
    except LogError as exc:
        print(f"cmdragons log: {exc}", file=sys.stderr)
        return 2
    run_summary = path.parent / "summary.json"
    if run_summary.exists():
        d = json.loads(run_summary.read_text())
        s = d.get("score", {})
        print(f"summary: score blue {s.get('blue')}:{s.get('yellow')} yellow, seed {d.get('seed')}, "
              f"{d.get('seconds')} s, kicks {d.get('kicks')}, shots {d.get('shots')}")
    return 0


def cmd_replay(args: argparse.Namespace, stop: Interrupt) -> int:
    """``cmdragons replay LOG.mcap``: the log's messages on zenoh again, paced as recorded."""
    from cmdragons.cli.progress import progress_bar
    from cmdragons.runtime.log import LogError
    from cmdragons.runtime.replay import replay, replay_span
    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.ssl.convert import is_league_log

    path = Path(args.path)
    if not path.is_file():
        print(f"cmdragons replay: {path}: no such file; give a run's run.mcap or a league log", file=sys.stderr)
        return 2
    if is_league_log(path):
        return _replay_league(args, path, stop)
    try:
        first, last = replay_span(path, args.start)
    except LogError as exc:
        print(f"cmdragons replay: {exc}", file=sys.stderr)
        return 2
    params = load_settings(args.config, args.set).runtime
    connected = _connect(params, "replay", args.router, "replay")
    if connected is None:
        return 2
    router, transport = connected
    try:
        wait = [r for r in args.wait.split(",") if r] if args.wait else []
        span = last - first - args.start
        with progress_bar(not args.no_progress, counts=False) as progress, stop.soft():
            task = progress.add_task("replay", total=max(span, 1e-9), info="")
            shown = [0.0]

            def show(t: float, n: int) -> None:
                if t - shown[0] >= 0.25 or t >= last:
                    shown[0] = t
                    done = t - first - args.start
                    progress.update(task, completed=done, info=f"{done:.1f}/{span:.1f} s, {n} messages")

            if not wait:  # nobody to wait for: let the subscribers' declarations reach us first
                transport.wait_for(lambda: stop.requested, params.settle_s)
            result = replay(path, transport, args.start, args.speed, skip=args.skip, wait_for=wait,
                            wait_timeout_s=params.start_timeout_s, should_stop=lambda: stop.requested,
                            on_progress=show)
    except (LogError, TimeoutError) as exc:
        print(f"cmdragons replay: {exc}", file=sys.stderr)
        return 2
    finally:
        with stop.shield():
            transport.close()
            if router is not None:
                router.close()
    cut = f", interrupted by {stop.signal}" if result.interrupted else ""
    print(f"replay: {result.messages} messages, log time {result.first_s - first:.2f} .. {result.last_s - first:.2f} s "
          f"at {args.speed:g}x on cmdragons/{params.field_name}{cut}")
    return stop.exit_code


def _replay_league(args: argparse.Namespace, path: Path, stop: Interrupt) -> int:
    """``cmdragons replay match.log.gz``: the league log's vision and referee packets into our
    tracker and brain, in-process and as fast as they go; run.mcap and summary.json."""
    from cmdragons.cli.progress import progress_bar
    from cmdragons.runtime.log import LogError, RunLog, run_folder
    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.ssl.logfile import LogFileError
    from cmdragons.runtime.ssl.replay import replay_league_log
    from cmdragons.runtime.stages import LoggerStage

    zenoh_only = [name for name, given in (("--from", args.start != 0.0), ("--speed", args.speed != 1.0),
                                           ("--skip", bool(args.skip)), ("--wait", args.wait is not None),
                                           ("--router", args.router)) if given]
    if zenoh_only:
        print(f"cmdragons replay: {', '.join(zenoh_only)} are for MCAP logs on zenoh; a league log plays into our "
              "tracker and brain as fast as it goes: leave them out", file=sys.stderr)
        return 2
    settings = load_settings(args.config, args.set)
    folder = run_folder("replay", args.out, overwrite=args.overwrite)
    log = RunLog(folder / "run.mcap")
    total = path.stat().st_size
    try:
        with progress_bar(not args.no_progress) as progress, stop.soft():
            task = progress.add_task("replay", total=None, info=f"{path.name} ({total / 1e6:.1f} MB)")

            def show(_t_ns: int, n: int) -> None:
                if n % 500 == 0:
                    progress.update(task, completed=n, info=f"{n} records")

            result = replay_league_log(path, settings, args.team, extra=(LoggerStage(log),), own=args.own,
                                       should_stop=lambda: stop.requested, on_record=show)
    except (LogFileError, LogError) as exc:
        print(f"cmdragons replay: {exc}", file=sys.stderr)
        return 2
    finally:
        with stop.shield():
            log.close()
    span = (result.last_ns - result.first_ns) / 1e9 if result.first_ns is not None and result.last_ns is not None \
        else 0.0
    vision = result.figures.get("ssl/vision_in", {})
    tracker = result.figures.get(f"tracker/{args.team}", {})
    summary = {"log": str(path), "team": args.team, "own": args.own, "records": result.records,
               "cameras": result.cameras, "seconds": round(span, 3), "truncated": result.truncated,
               "interrupted": result.interrupted, "field_m": list(result.field_m), "field_from": result.field_from,
               "vision": vision,
               "referee": result.figures.get("ssl/referee_in", {}), "tracker": tracker}
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    dropped = vision.get("dropped", {})
    print(f"replay: {path}: {sum(result.records.values())} records over {span:.2f} s, cameras "
          f"{', '.join(map(str, result.cameras)) or 'none'}; {vision.get('detections', 0)} detections into the "
          f"{args.team} tracker and brain" + (f", dropped {dropped}" if dropped else "") + f" -> {folder}")
    if result.truncated is not None:
        print(f"cmdragons replay: warning: {result.truncated}", file=sys.stderr)
    return stop.exit_code
