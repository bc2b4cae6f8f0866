"""The embedded commands (``cmdragons play | sim | vision | bench``) and the parser of every command."""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import numpy as np

from cmdragons.cli.lines import plural, rules_line
from cmdragons.cli.progress import compile_bar, progress_bar, run_shown, starting
from cmdragons.cli.runtime import add_parsers as add_runtime_parsers
from cmdragons.cli.runtime import cmd_log, cmd_node, cmd_replay, play_distributed
from cmdragons.config import ConfigError
from cmdragons.runtime.interrupt import Interrupt
from cmdragons.runtime.log import OutputError

if TYPE_CHECKING:
    from cmdragons.runtime.report import RunData
    from cmdragons.runtime.settings import Settings

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    """argparse with its errors on one line: the problem, then where the fix is."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: {message} (see {self.prog} -h)\n")


def _crf(text: str) -> int:
    """x264's constant rate factor, 0 to 51."""
    if not (text.isdigit() and 0 <= int(text) <= 51):
        raise argparse.ArgumentTypeError(f"must be a whole number 0 to 51, got {text!r}")
    return int(text)


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number; give one from 0 to 2**63-1") from None
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"{value} is out of range; give a whole number from 0 to 2**63-1")
    return value


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number; give a positive number") from None
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"{text} must be a positive number")
    return value


def _count(text: str) -> int:
    if not (text.isdigit() and 1 <= int(text) <= 1000):
        raise argparse.ArgumentTypeError(f"must be a whole number 1 to 1000, got {text!r}")
    return int(text)


def _count_or_none(text: str) -> int:
    if not (text.isdigit() and 0 <= int(text) <= 1000):
        raise argparse.ArgumentTypeError(f"must be a whole number 0 to 1000, got {text!r}")
    return int(text)


def _common(parser: argparse.ArgumentParser, example: str) -> None:
    """--config and --set; ``example``: a --set a user of this command would give (a key it reads)."""
    parser.add_argument("--config", metavar="DIR", default=None, help="config folder (default: ./configs)")
    parser.add_argument(
        "--set", metavar="KEY=VALUE", action="append", default=[],
        help=f"override one config value, e.g. --set {example} (repeatable)",
    )


def build_parser() -> argparse.ArgumentParser:
    from importlib.metadata import version

    parser = _Parser(prog="cmdragons", description="RoboCup small-size team and simulator")
    parser.add_argument("--version", action="version", version=f"cmdragons {version('cmdragons')}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("sim", help="run the simulator with scripted motion; record camera frames and truth; or "
                       "(--serve) serve it to teams as a league simulator")
    _common(p, "sim.physics.substeps=8")
    p.add_argument("--seconds", type=_positive, default=None,
                   help="simulated seconds (default 10; with --serve: until interrupted)")
    p.add_argument("--serve", action="store_true",
                   help="run alone in real time and speak what grSim speaks: SSL-Vision packets with the geometry "
                   "(224.5.23.2:10020 as grSim's, every camera of the division), the simulation protocol for both "
                   "teams (SimulatorCommand on 127.0.0.1:10300, RobotControl on 10301 blue and 10302 yellow) and "
                   "Referee packets from its own referee (224.5.23.1:10003); all on loopback (configs/protocols.yaml)")
    p.add_argument("--division", choices=("A", "B"), default=None, help="field and team size (default: config)")
    p.add_argument("--record", action="store_true", help="write camera frames, cameras.yaml and truth.jsonl")
    p.add_argument("--format", choices=("h264", "ffv1", "png"), default=None,
                   help="recorded frames: H.264 .mp4, lossless FFV1 .mkv or lossless PNG "
                   "(default: cameras.yaml recording)")
    p.add_argument("--crf", type=_crf, default=None, metavar="0-51",
                   help="H.264 quality on x264's scale, 0 best (default: cameras.yaml recording.crf)")
    p.add_argument("--out", metavar="DIR", default=None, help="output folder (default logs/<time>-sim)")
    p.add_argument("--overwrite", action="store_true", help="let --out replace the run already in that folder")
    p.add_argument("--snapshot", metavar="FILE.png", default=None, help="write the last frame of all cameras, tiled")
    p.add_argument("--seed", type=_seed, default=None, help="override sim.seed (0 .. 2**63-1)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")

    p = sub.add_parser("play", help="play a match in the simulator; our team sees only the camera images")
    _common(p, "strategy.kicking.shoot_value=0.1")
    p.add_argument("--simulator", choices=("own", "grsim", "sim-protocol"), default="own",
                   help="own: our simulator, embedded (default); grsim: an outside grSim (its vision on "
                   "224.5.23.2:10020, grSim packets to 127.0.0.1:20011); sim-protocol: an outside simulator over the "
                   "league's simulation protocol (grSim, the ER-Force simulator, cmdragons sim --serve: RobotControl "
                   "to 127.0.0.1:10301/10302, teleports to 10300, its vision on protocols.simulation.vision_port). "
                   "Outside, we see its SSL-Vision packets, play on the field its geometry gives, and --seconds is "
                   "its vision's time")
    p.add_argument("--team", choices=("blue", "yellow"), default="blue",
                   help="with --simulator grsim|sim-protocol: the colour our team plays (default blue)")
    p.add_argument("--opponent", choices=("simple", "defend", "self", "none", "outside", "simulation"), default=None,
                   help="the built-in simple team (on the true state; the default), the built-in defending team (on "
                   "the true state, at our robots' limits: marks receivers in their passing lanes, blocks shots; "
                   "configs/team.yaml defend_opponent), a copy of our team, nobody, (with "
                   "--distributed) a team outside on commands/yellow (examples/outside_team.py), or a team outside "
                   "over the league's simulation protocol (RobotControl to 127.0.0.1:10302, SimulatorCommand to "
                   "10300; it sees SSL-Vision packets on 224.5.23.2:10006 and Referee packets on 224.5.23.1:10003). "
                   "In an outside simulator: none (the default: the other side's robots idle) or self (both colours "
                   "ours)")
    p.add_argument("--opponent-set", metavar="KEY=VALUE", action="append", default=[],
                   help="with --opponent self: override one value of the copy's own config, on top of --config "
                   "and --set (its brain and tracker: planner, control, safety, tracker, strategy, team), "
                   "e.g. --opponent-set team.navigator=robox --opponent-set planner.planner=estar (repeatable)")
    p.add_argument("--seconds", type=_positive, default=30.0, help="match time in simulated seconds (default 30)")
    p.add_argument("--rules", choices=("full", "basic"), default=None,
                   help="full: the league's game controller and auto-referee (fouls, cards, placements by the teams, "
                   "penalties, halves); basic: goals, balls out and restarts placed by the referee "
                   "(default: sim.referee.rules, full)")
    p.add_argument("--division", choices=("A", "B"), default=None, help="field and team size (default: config)")
    p.add_argument("--perception", choices=("vision", "truth"), default=None,
                   help="vision: our team sees the rendered images (default); truth: noisy true detections")
    p.add_argument("--video", action="store_true", help="write match.mp4 (H.264): a top-down view of the match")
    p.add_argument("--view", choices=("field", "cameras"), default="field",
                   help="what match.mp4 shows: the top-down field (default) or the camera images with overlays")
    p.add_argument("--out", metavar="DIR", default=None, help="output folder (default logs/<time>-play)")
    p.add_argument("--overwrite", action="store_true", help="let --out replace the run already in that folder")
    p.add_argument("--seed", type=_seed, default=None, help="override sim.seed (0 .. 2**63-1)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--distributed", action="store_true",
                   help="every part as its own process on zenoh (loopback, configs/runtime.yaml), in lock-step")

    p = sub.add_parser(
        "vision", help="detect ball and robots in camera frames (also: vision calibrate ..., vision tune ...)",
        description="SOURCE: a recording folder, a video file, an image folder or a glob (one per camera). "
        "`cmdragons vision calibrate -h` and `cmdragons vision tune -h` for the other two commands.",
    )
    _common(p, "vision.regions.merge_gap_px=2")
    p.add_argument("source", nargs="+", metavar="SOURCE")
    p.add_argument("--out", metavar="DIR", default=None, help="output folder (default logs/<time>-vision)")
    p.add_argument("--overwrite", action="store_true", help="let --out replace the run already in that folder")
    p.add_argument("--video", action="store_true", help="also write an annotated video per camera")
    p.add_argument("--overlay", action="store_true",
                   help="also draw each frame's detections (team, id, heading, confidence), the balls and the fitted "
                   "field on it: a PNG per still image (OUT/overlay/), a video per video source")
    p.add_argument("--fps", type=_positive, default=None, help="frames per second for t_capture (default: sim's)")
    p.add_argument("--track", action="store_true", help="also track the detections and write tracks.jsonl")
    p.add_argument("--track-ahead", action="store_true",
                   help="tracks predicted tracker.latency_s past each frame, as the live loop hands them to the team "
                   "(default: the estimate at each frame's capture time)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")

    from cmdragons.bench import ABOUT

    width = max(len(name) for name in ABOUT)
    p = sub.add_parser("bench", help="run a benchmark suite and print its table",
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog="suites:\n" + "\n".join(f"  {name:<{width}}  {line}" for name, line in ABOUT.items()))
    _common(p, "planner.errt.step_m=0.2")
    p.add_argument("suite", metavar="SUITE", help="which suite (listed below)")
    p.add_argument("--quick", action="store_true", help="a reduced suite, well under a minute")
    p.add_argument("--json", metavar="PATH", default=None, help="also write the rows as JSON")
    p.add_argument("--maps", metavar="DIR", default=None,
                   help="grid: a folder of Moving AI .map files with their .map.scen "
                   "(default ../shared/benchdata/moving_ai)")
    p.add_argument("--figures", metavar="DIR", default=None,
                   help="navigation: the folder of the PNGs of each method's paths (default logs/bench-navigation)")
    p.add_argument("--opponent", choices=("simple", "defend", "self"), default=None,
                   help="play: only this opponent (default: simple, defend (with defend against simple on the "
                   "true state) and self, our team in the other colour; --quick: simple and defend)")
    p.add_argument("--matches", metavar="N", type=_count, default=None,
                   help="play: this many seeded matches (default 10, --quick 2)")
    p.add_argument("--half", metavar="S", type=_positive, default=None,
                   help="play: halves of S seconds (default the rules' 300, --quick 30); league: (default 120, "
                   "--quick 30)")
    p.add_argument("--shootout", metavar="N", type=_count_or_none, default=None,
                   help="play: the penalty shootout's kicks each way against simple (default 10, --quick 3; 0: none)")
    add_runtime_parsers(sub, _common)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) >= 2 and argv[0] == "vision" and argv[1] in ("calibrate", "tune"):
        from cmdragons.cli.vision import main as vision_command

        try:
            return vision_command(argv[1], argv[2:], _common)
        except ConfigError as exc:
            print(f"cmdragons: config error: {exc}", file=sys.stderr)
            return 2
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # -h, or a bad argument (already said on one line)
        return exc.code if isinstance(exc.code, int) else 2
    with Interrupt() as stop:
        try:
            if args.command == "sim" and args.serve:
                from cmdragons.cli.serve import cmd_serve

                return cmd_serve(args, stop)
            if args.command == "sim":
                return _cmd_sim(args, stop)
            if args.command == "bench":
                return _cmd_bench(args)
            if args.command == "play" and args.simulator != "own":
                from cmdragons.cli.outside import play_outside

                return play_outside(args, stop, _compile_kernels)
            if args.command == "play":
                if args.team != "blue":
                    print("cmdragons play: --team is for an outside simulator: in ours, our team plays blue",
                          file=sys.stderr)
                    return 2
                args.opponent = args.opponent or "simple"
                args.perception = args.perception or "vision"
            if args.command == "play" and args.distributed and args.opponent == "simulation":
                print("cmdragons play: --opponent simulation plays in the embedded match: leave out --distributed",
                      file=sys.stderr)
                return 2
            if args.command == "play" and args.distributed:
                return play_distributed(args, stop)
            if args.command == "play" and args.opponent == "outside":
                print("cmdragons play: --opponent outside plays over zenoh: add --distributed", file=sys.stderr)
                return 2
            if args.command == "play":
                return _cmd_play(args, stop)
            if args.command == "node":
                return cmd_node(args, stop)
            if args.command == "log":
                return cmd_log(args)
            if args.command == "replay":
                return cmd_replay(args, stop)
            if args.command == "vision":
                return _cmd_vision(args)
        except ConfigError as exc:
            print(f"cmdragons: config error: {exc}", file=sys.stderr)
            return 2
        except OutputError as exc:
            print(f"cmdragons {args.command}: {exc}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print(f"cmdragons {args.command}: interrupted by {stop.signal or 'SIGINT'} before any result; "
                  "nothing more was written", file=sys.stderr)
            return stop.exit_code or 130
    return 2


def _cmd_sim(args: argparse.Namespace, stop: Interrupt) -> int:
    import dataclasses

    from cmdragons.messages import GameState
    from cmdragons.recording import RecordingWriter
    from cmdragons.runtime.bus import Bus
    from cmdragons.runtime.log import RunLog, check_writable_file, run_folder
    from cmdragons.runtime.match import build, scripted_wiring
    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.stages import LoggerStage, RecorderStage, Tap
    from sim.script import ScriptedPlay
    from sim.simulator import Simulator

    settings = load_settings(args.config, [*args.set, *([f"field.division={args.division}"] if args.division else [])])
    seconds = 10.0 if args.seconds is None else args.seconds
    if args.snapshot:
        if Path(args.snapshot).suffix.lower() not in (".png", ".jpg", ".jpeg"):
            raise OutputError(f"--snapshot {args.snapshot}: not an image file name; give one ending in .png")
        check_writable_file(args.snapshot, "--snapshot")
    folder = run_folder("sim", args.out, overwrite=args.overwrite)
    models = settings.camera_models()
    sim = Simulator(settings.field, models, settings.sim, seed=args.seed, look=settings.cameras.look())
    script = ScriptedPlay(settings.field_geometry(), settings.field.robot.radius_m, settings.sim.script, sim.rng)
    fps = settings.sim.physics.frame_rate_hz
    n_frames = max(1, round(seconds * fps))
    rec = settings.cameras.recording
    rec = dataclasses.replace(rec, codec=args.format or rec.codec, crf=rec.crf if args.crf is None else args.crf)
    recorder = RecordingWriter(folder, models, fps, rec) if args.record else None
    log = RunLog(folder / "run.mcap")
    game = [GameState(0.0)]  # the referee's latest word, for the progress bar
    bus = Bus()
    stages = build(scripted_wiring(sim, script, recorder),
                   [LoggerStage(log), Tap("progress", ("referee",), lambda _topic, g: game.__setitem__(0, g))])
    for stage in stages:
        bus.add(stage)
    bus.start()
    wall0 = time.perf_counter()
    try:
        with progress_bar(not args.no_progress) as progress, stop.soft():
            task = progress.add_task("sim", total=n_frames, info="")
            run_shown(bus.tick, n_frames, stop, progress, task,
                      lambda _i: f"t={sim.t:6.2f}s  blue {game[0].score_blue}:{game[0].score_yellow} yellow")
    finally:
        with stop.shield():
            log.close()
            if recorder is not None:
                recorder.close()
    images = next(s for s in stages if isinstance(s, RecorderStage)).images
    with stop.shield():
        return _finish_sim(args, stop, sim, models, folder, images, time.perf_counter() - wall0, n_frames)


def _finish_sim(args: argparse.Namespace, stop: Interrupt, sim: Any, models: Sequence[Any], folder: Path,
                images: dict[int, Any], wall: float, n_frames: int) -> int:
    """summary.json, the line that sums the run up, and the snapshot of the last frame's ``images``."""
    import cv2

    from cmdragons.runtime.overlay import tile_cameras

    summary = sim.summary()
    summary["interrupted"] = stop.requested
    summary["wall_seconds"] = round(wall, 3)
    summary["realtime_factor"] = round(sim.t / wall, 2) if wall > 0 else None
    summary["cameras"] = [m.id for m in models]
    summary["cycle_ms"] = {
        name: {"median": float(np.median(v)), "p95": float(np.percentile(v, 95))}
        for name, v in (("physics", sim.times.physics_ms), ("render", sim.times.render_ms)) if v
    }
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    faults = sum(summary["command_faults"].values())
    score = summary["score"]
    print(
        f"sim: {sim.t:.1f} s simulated in {wall:.1f} s ({summary['realtime_factor']}x real time), "
        f"{plural(summary['frames'], 'frame')} x {plural(len(models), 'camera')}, score blue "
        f"{score['blue']}:{score['yellow']} yellow, {plural(summary['kicks'], 'kick')}, "
        f"{plural(summary['balls_out'], 'ball')} out, {plural(summary['robot_contacts']['count'], 'robot contact')}, "
        f"{plural(faults, 'command fault')}"
    )
    code = stop.exit_code
    if args.snapshot and images and not cv2.imwrite(args.snapshot, tile_cameras(images, models)):
        print(f"sim: could not write the snapshot {args.snapshot} (summary.json is written); give a .png path",
              file=sys.stderr)
        code = code or 1
    if stop.requested:
        print(f"sim: interrupted by {stop.signal} after {plural(summary['frames'], 'frame')} of {n_frames}: "
              "the output so far is closed and readable, summary.json says \"interrupted\": true")
    print(f"sim: output -> {folder}")
    return code


def _cmd_play(args: argparse.Namespace, stop: Interrupt) -> int:
    # a line at once: loading the simulator, vision and the team takes seconds (more on a fresh clone)
    status = starting(not args.no_progress, "play: loading the simulator, vision and the team ...")
    try:
        return _play(args, stop, status)
    finally:
        status.stop()


def _play(args: argparse.Namespace, stop: Interrupt, status: Any) -> int:
    from cmdragons.messages import GameState
    from cmdragons.runtime.bus import Stage
    from cmdragons.runtime.log import RunLog, run_folder
    from cmdragons.runtime.match import OURS, Match
    from cmdragons.runtime.overlay import MatchVideoStage
    from cmdragons.runtime.report import ReportStage, pyplot
    from cmdragons.runtime.scene import SceneStage
    from cmdragons.runtime.settings import load_settings, load_team_settings
    from cmdragons.runtime.stages import LoggerStage, Tap
    from cmdragons.runtime.warmup import CompileWatch
    from cmdragons.tracking.filters import kalman

    overrides = list(args.set) + ([f"field.division={args.division}"] if args.division else [])
    overrides += [f"sim.referee.rules={args.rules}"] if args.rules else []
    if args.opponent_set and args.opponent != "self":
        print(f"cmdragons play: --opponent-set configures a copy of our team: it needs --opponent self, "
              f"not {args.opponent}", file=sys.stderr)
        return 2
    settings = load_settings(args.config, overrides)
    theirs = load_team_settings(args.config, overrides, args.opponent_set) if args.opponent_set else None
    folder = run_folder("play", args.out, overwrite=args.overwrite)
    images = args.perception == "vision" or (args.video and args.view == "cameras")
    log = RunLog(folder / "run.mcap")
    fps = settings.sim.physics.frame_rate_hz
    n_frames = max(1, round(args.seconds * fps))
    game = [GameState(0.0)]  # the referee's latest word, for the progress bar
    scene = SceneStage(log, settings.field_geometry(), settings.field.robot.radius_m, settings.field.robot.height_m,
                       settings.field.ball.radius_m)
    report = ReportStage(OURS)
    extra: list[Stage] = [LoggerStage(log), scene, report,
                          Tap("progress", ("referee",), lambda _topic, g: game.__setitem__(0, g))]
    video = None
    if args.video:
        video = MatchVideoStage(folder / "match.mp4", args.view, OURS, settings.camera_models(),
                                settings.field_geometry(), settings.field.robot.radius_m, settings.field.robot.height_m,
                                fps)
        extra.append(video)
    watch = CompileWatch()
    built: list[Match] = []
    try:
        def build() -> Match:
            return Match(settings, args.opponent, args.perception, seed=args.seed, render=images, extra=extra,
                         opponent_settings=theirs)

        def prepare() -> None:
            """A first run builds the match while its kernels compile in other processes, and loads
            what the match and its report import later (filterpy brings scipy.stats: a second)."""
            built.append(build())
            kalman()
            pyplot()

        status.stop()
        compile_s = _compile_kernels(args, settings, images, prepare)
        match = built[0] if built else build()
        built[:] = [match]
        started = time.time()
        with progress_bar(not args.no_progress) as progress, stop.soft():
            task = progress.add_task("play", total=n_frames, info="")
            watch.on_compile = lambda name: progress.update(task, info=f"compiling {name} (first run only)")
            wall0 = time.perf_counter()
            watch.start()
            run_shown(lambda _i: match.step(), n_frames, stop, progress, task,
                      lambda _i: f"t={game[0].t:6.1f}s  blue {game[0].score_blue}:{game[0].score_yellow} yellow  "
                                 f"{game[0].command}")
        with stop.shield():
            wall = time.perf_counter() - wall0
            summary = match.summary()  # the stages' summaries go into the log as well
    finally:
        with stop.shield():
            watch.stop()
            for m in built:
                m.close()
            log.close()
            if video is not None:
                video.close()
    with stop.shield():
        summary["interrupted"] = stop.requested
        summary["started_utc"] = _utc(started)
        summary["wall_seconds"] = round(wall, 3)
        summary["compile_seconds"] = round(compile_s + watch.seconds, 3)
        # the one-time compile is not the team's speed
        run_wall = wall - watch.seconds
        summary["realtime_factor"] = round(summary["seconds"] / run_wall, 2) if run_wall > 0 else None
        geometry = settings.field_geometry()
        _finish_play(folder, report.collector.result(), summary, args, stop,
                     (geometry.half_length, geometry.half_width))
    return stop.exit_code


def _utc(t: float) -> str:
    import datetime as dt

    return dt.datetime.fromtimestamp(t, dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


def _finish_play(folder: Path, run: RunData, summary: dict[str, Any], args: argparse.Namespace, stop: Interrupt,
                 half_size_m: tuple[float, float]) -> None:
    """summary.json (with its warnings), the match report of ``run`` and the summary lines; the last
    line names the output folder."""
    from cmdragons.runtime.report import run_warnings, write_report

    warnings = run_warnings(run, summary)
    summary["warnings"] = warnings
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    report = None
    if run.frames:
        report = write_report(run, summary, folder / "report.png", half_size_m)
    score, passes, coll = summary["score"], summary["passes"], summary["collisions"]
    brain = summary["cycle_ms"].get("brain", {}).get("median", float("nan"))
    rtf = summary["realtime_factor"]
    compile_note = f", not counting {summary['compile_seconds']:.0f} s of first-run compile" \
        if summary["compile_seconds"] >= 1 else ""
    played = f"{summary['seconds']:.1f} s of {args.seconds:g} s" if stop.requested else f"{summary['seconds']:.0f} s"
    print(
        f"play: {played} against {args.opponent} ({args.perception}) in {summary['wall_seconds']:.1f} s "
        f"({rtf}x real time{compile_note}): blue (us) {score['blue']}:{score['yellow']} yellow (them); ours: "
        f"{plural(summary['shots'], 'shot')}, passes {passes['completed']}/{passes['tried']} completed, "
        f"{plural(coll['own'], 'own collision')}{_pushed(coll)}; brain {brain:.2f} ms median"
        + _their_line(summary)
    )
    rules = summary.get("rules")
    if rules is not None and rules["rules"] == "full":
        print("play: " + rules_line(rules))
    if summary.get("physics"):
        print("play: " + physics_line(summary["physics"]))
    for w in warnings:
        print(f"play: warning: {w}")
    if stop.requested:
        print(f"play: interrupted by {stop.signal}: the output so far is closed and readable, "
              "summary.json says \"interrupted\": true")
    files = ["run.mcap", "summary.json"] + (["match.mp4"] if args.video and (folder / "match.mp4").exists() else [])
    files += [report.name] if report is not None else []
    print(f"play: {', '.join(files)} -> {folder}")


_FACT_WORDS = {"ball_roll": "ball rolls", "ball_slide": "slides", "robot_accel": "robots accelerate",
               "robot_brake": "brake", "kick_gain": "kicks leave at (share of the speed asked)",
               "kick_retention": "keep across the heading (share)"}


def physics_line(physics: dict[str, Any]) -> str:
    """What the tracker measured, each fact against its configured value (m/s², the kick's gain and
    retention shares), and which are in use."""
    parts = []
    for name, e in physics.items():
        if not e["samples"]:
            continue
        state = "in use" if e["used"] else "confident" if e["confident"] else "unsure"
        parts.append(f"{_FACT_WORDS.get(name, name)} {e['value_m_s2']:.2f} (configured {e['configured_m_s2']:g}, "
                     f"{plural(e['samples'], 'window')}, {state})")
    return "physics measured (m/s²): " + ("; ".join(parts) if parts else "nothing yet")


def _pushed(collisions: dict[str, int]) -> str:
    """The own collisions an opponent pushed into, when there were any."""
    n = collisions.get("own_pushed", 0)
    return f" (and {n} pushed by an opponent)" if n else ""


def _their_line(summary: dict[str, Any]) -> str:
    """The copy of our team's figures for the summary line (a self match only)."""
    them = summary.get("opponent_team")
    if them is None:
        return ""
    brain = summary["cycle_ms"].get("opponent_brain", {}).get("median", float("nan"))
    return (f"; theirs: {plural(them['shots'], 'shot')}, {plural(them['collisions']['own'], 'own collision')}"
            f"{_pushed(them['collisions'])}, "
            f"brain {brain:.2f} ms median")


def _compile_kernels(args: argparse.Namespace, settings: Settings, images: bool,
                     meanwhile: Callable[[], None]) -> float:
    """Compile the play's numba kernels before the match when they have no cache yet, with a
    progress line, running ``meanwhile`` as it goes; returns the wall seconds it took (0 when every
    kernel was cached, and then ``meanwhile`` is not run)."""
    from cmdragons.runtime.warmup import cold_kernels, warm_up, warm_up_parts

    if not cold_kernels(images):
        return 0.0
    title = "compiling kernels (first run)"
    if args.no_progress:
        print(f"{args.command}: {title} ...", file=sys.stderr, flush=True)
    parts = warm_up_parts(images)
    # a total from the start (the parts compiled side by side, the match built meanwhile the last), the
    # kernels counted as they come; short columns, so that the line fits 80 columns
    with compile_bar(not args.no_progress) as progress:
        task = progress.add_task(title, total=parts, info="")
        counted = [0]

        def show(n: int, name: str) -> None:
            counted[0] = n
            progress.update(task, info=f"{n} kernels")

        seconds = warm_up(settings, images, show, meanwhile, lambda k: progress.update(task, completed=k))
        progress.update(task, completed=parts, info=f"{counted[0]} kernels, cached")
    if args.no_progress:
        print(f"{args.command}: compiled {counted[0]} kernels in {seconds:.0f} s (cached for next time)",
              file=sys.stderr, flush=True)
    return seconds


def _cmd_vision(args: argparse.Namespace) -> int:
    from cmdragons.recording import RecordingError
    from cmdragons.runtime.log import run_folder
    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.vision_command import run_vision
    from vision.sources import SourceError, open_sources

    if args.track_ahead and not args.track:
        print("cmdragons vision: --track-ahead predicts the tracks of --track: add --track", file=sys.stderr)
        return 2
    settings = load_settings(args.config, args.set)
    try:
        sources, recording = open_sources(args.source)
    except SourceError as exc:
        print(f"cmdragons vision: {exc}", file=sys.stderr)
        return 2
    folder = run_folder("vision", args.out, overwrite=args.overwrite)
    fps = args.fps or settings.sim.physics.frame_rate_hz
    total = sum(len(s.paths) for s in sources if s.kind == "images") or None
    with progress_bar(not args.no_progress) as progress:
        task = progress.add_task("vision", total=total, info="")
        try:
            summary = run_vision(sources, {m.id: m for m in settings.camera_models()}, settings.vision, settings.field,
                                 folder, args.video, fps, recording, lambda n: progress.advance(task, n),
                                 args.overlay)
        except (SourceError, RecordingError) as exc:
            print(f"cmdragons vision: {exc}", file=sys.stderr)
            return 2
    d = summary.as_dict()
    bad = summary.unreadable + summary.empty + summary.wrong_size
    ms = d["ms_per_frame"]["median"]
    print(f"vision: {summary.frames} frames from {len(sources)} camera(s), {d['captures']} captures; the whole "
          f"field per capture (any camera): {d['robots_per_capture']:.2f} robots, the ball in "
          f"{100 * d['ball_seen_share']:.0f} %; " + (f"{ms:.2f} ms per frame (median)" if ms else "no frame")
          + f" -> {folder}")
    if args.overlay:
        pngs = len(list((folder / "overlay").glob("*.png"))) if (folder / "overlay").is_dir() else 0
        videos = sorted(p.name for p in folder.glob("annotated_camera_*.mp4"))
        print("vision: overlays -> " + ", ".join(([f"{pngs} PNG in {folder / 'overlay'}"] if pngs else [])
                                                   + [str(folder / v) for v in videos]))
    for name, frames in d["bad_frames"].items():
        if frames:
            print(f"vision: {len(frames)} {name.replace('_', ' ')} frame(s): {', '.join(frames[:20])}"
                  + (" ..." if len(frames) > 20 else ""))
    for message in summary.broken_off:
        print(f"cmdragons vision: {message}", file=sys.stderr)
    if summary.score:
        print("vision: against truth: " + ", ".join(f"{k} {v:.4g}" for k, v in summary.score.items()))
    if args.track:
        from cmdragons.runtime.tracks import track_detections

        ahead = settings.tracker.latency_s if args.track_ahead else 0.0
        counts = track_detections(folder / "detections.jsonl", folder / "tracks.jsonl", settings.tracker, ahead)
        print(f"vision: tracked {counts['frames']} frames -> {folder / 'tracks.jsonl'} "
              + (f"(predicted {ahead * 1e3:.0f} ms ahead, as the live loop)" if ahead else "(at capture time)")
              + (f" ({counts['bad_lines']} unreadable detection lines skipped)" if counts["bad_lines"] else ""))
    return 0 if len(bad) < summary.frames else 1


def _cmd_bench(args: argparse.Namespace) -> int:
    from cmdragons.bench import HANDS_ON, OPTIONS, SUITES, print_table, write_json
    from cmdragons.runtime.log import check_writable_file
    from cmdragons.runtime.settings import load_settings

    if args.suite not in SUITES:
        print(f"cmdragons bench: unknown suite {args.suite!r}; suites: {', '.join(sorted(SUITES))}", file=sys.stderr)
        return 2
    settings = load_settings(args.config, args.set)
    if args.json:
        check_writable_file(args.json, "--json")  # before the bench: its rows are not lost at the end
    options = {k: getattr(args, k) for k in OPTIONS.get(args.suite, ()) if getattr(args, k) is not None}
    if args.suite in HANDS_ON:
        options.update(config=args.config, overrides=list(args.set))
    for suite, keys in OPTIONS.items():
        for k in keys:
            if getattr(args, k) is not None and k not in OPTIONS.get(args.suite, ()):
                print(f"cmdragons bench: --{k} is for the {suite} suite, not {args.suite}", file=sys.stderr)
                return 2
    if args.figures is not None and Path(args.figures).exists() and not Path(args.figures).is_dir():
        print(f"cmdragons bench: --figures {args.figures} is a file, not a folder", file=sys.stderr)
        return 2
    try:
        rows = SUITES[args.suite](settings, args.quick, **options)
    except FileNotFoundError as exc:  # a suite's input data (the grid suite's maps) is not there
        print(f"cmdragons bench: {exc}; give a folder with --maps DIR", file=sys.stderr)
        return 2
    print_table(args.suite, rows)
    if args.json:
        try:
            write_json(args.json, args.suite, rows)
        except OSError as exc:  # checked before the bench; gone since (a folder removed, a full disk)
            print(f"cmdragons bench: --json {args.json}: not written ({exc.strerror}); the table above has "
                  "the rows", file=sys.stderr)
            return 2
    return 0

