"""``cmdragons`` command line: play | sim | vision | bench.

Every command takes ``--config DIR`` (default ``./configs``) and repeatable
``--set concern.key.path=value`` overrides.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import ConfigError

__all__ = ["main"]


def _common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", metavar="DIR", default=None, help="config folder (default: ./configs)")
    parser.add_argument(
        "--set", metavar="KEY=VALUE", action="append", default=[],
        help="override one config value, e.g. --set sim.physics.substeps=8 (repeatable)",
    )  # fmt: skip


def _crf(text: str) -> int:
    """x264's constant rate factor, 0 to 51."""
    if not (text.isdigit() and 0 <= int(text) <= 51):
        raise argparse.ArgumentTypeError(f"must be a whole number 0 to 51, got {text!r}")
    return int(text)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="cmdragons", description="RoboCup small-size team and simulator")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("sim", help="run the simulator with scripted motion; record camera frames and truth")
    _common(p)
    p.add_argument("--seconds", type=float, default=10.0, help="simulated seconds (default 10)")
    p.add_argument("--record", action="store_true", help="write camera frames, cameras.yaml and truth.jsonl")
    p.add_argument("--format", choices=("h264", "ffv1", "png"), default=None,
                   help="recorded frames: H.264 .mp4, lossless FFV1 .mkv or lossless PNG "
                   "(default: cameras.yaml recording)")
    p.add_argument("--crf", type=_crf, default=None, metavar="0-51",
                   help="H.264 quality on x264's scale, 0 best (default: cameras.yaml recording.crf)")
    p.add_argument("--out", metavar="DIR", default=None, help="output folder (default logs/<time>-sim)")
    p.add_argument("--snapshot", metavar="FILE.png", default=None, help="write the last frame of all cameras, tiled")
    p.add_argument("--seed", type=int, default=None, help="override sim.seed")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")

    p = sub.add_parser("play", help="play a match in the simulator; our team sees only the camera images")
    _common(p)
    p.add_argument("--opponent", choices=("simple", "self", "none"), default="simple",
                   help="the built-in simple team (on the true state), a copy of our team, or nobody")
    p.add_argument("--seconds", type=float, default=30.0, help="match time in simulated seconds (default 30)")
    p.add_argument("--division", choices=("A", "B"), default=None, help="field and team size (default: config)")
    p.add_argument("--perception", choices=("vision", "truth"), default="vision",
                   help="vision: our team sees the rendered images (default); truth: noisy true detections")
    p.add_argument("--video", action="store_true", help="write match.mp4: the cameras with the team's overlays")
    p.add_argument("--out", metavar="DIR", default=None, help="output folder (default logs/<time>-play)")
    p.add_argument("--seed", type=int, default=None, help="override sim.seed")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")

    p = sub.add_parser(
        "vision", help="detect ball and robots in camera frames (also: vision calibrate ..., vision tune ...)",
        description="SOURCE: a recording folder, a video file, an image folder or a glob (one per camera). "
        "`cmdragons vision calibrate -h` and `cmdragons vision tune -h` for the other two commands.",
    )  # fmt: skip
    _common(p)
    p.add_argument("source", nargs="+", metavar="SOURCE")
    p.add_argument("--out", metavar="DIR", default=None, help="output folder (default logs/<time>-vision)")
    p.add_argument("--video", action="store_true", help="also write an annotated video per camera")
    p.add_argument("--fps", type=float, default=None, help="frames per second for t_capture (default: sim's)")
    p.add_argument("--track", action="store_true", help="also track the detections and write tracks.jsonl")
    p.add_argument("--track-ahead", action="store_true",
                   help="tracks predicted tracker.latency_s past each frame, as the live loop hands them to the team "
                   "(default: the estimate at each frame's capture time)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")

    p = sub.add_parser("bench", help="run a benchmark suite and print its table")
    _common(p)
    p.add_argument("suite", help="suite name (see `cmdragons bench --help`: sim, planning, safety, ...)")
    p.add_argument("--quick", action="store_true", help="a reduced suite, well under a minute")
    p.add_argument("--json", metavar="PATH", default=None, help="also write the rows as JSON")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) >= 2 and argv[0] == "vision" and argv[1] in ("calibrate", "tune"):
        from cmdragons.cli_vision import main as vision_command

        try:
            return vision_command(argv[1], argv[2:], _common)
        except ConfigError as exc:
            print(f"cmdragons: config error: {exc}", file=sys.stderr)
            return 2
    args = build_parser().parse_args(argv)
    try:
        if args.command == "sim":
            return _cmd_sim(args)
        if args.command == "bench":
            return _cmd_bench(args)
        if args.command == "play":
            return _cmd_play(args)
        if args.command == "vision":
            return _cmd_vision(args)
    except ConfigError as exc:
        print(f"cmdragons: config error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("cmdragons: interrupted", file=sys.stderr)
        return 130
    return 2


def _progress(enabled: bool):  # type: ignore[no-untyped-def]
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn("{task.fields[info]}"),
        TimeRemainingColumn(), disable=not enabled, transient=False,
    )  # fmt: skip


def tile_cameras(images: dict[int, NDArray[np.uint8]], models: Sequence[object]) -> NDArray[np.uint8]:
    """All camera images in one picture, laid out as the cameras hang over the field."""
    from cmdragons.camera import CameraModel

    cams = [m for m in models if isinstance(m, CameraModel) and m.id in images]
    if not cams:
        raise ValueError("no camera images to tile")
    first = cams[0]
    # field directions of image 'right' and 'up' in the first camera
    c = np.array([[first.width / 2, first.height / 2], [first.width / 2 + 50, first.height / 2],
                  [first.width / 2, first.height / 2 - 50]])  # fmt: skip
    p = first.unproject(c, 0.0)
    right, up = p[1] - p[0], p[2] - p[0]
    right, up = right / np.linalg.norm(right), up / np.linalg.norm(up)
    pos = {m.id: (float(m.center[:2] @ right), float(m.center[:2] @ up)) for m in cams}
    cols = sorted({round(v[0], 1) for v in pos.values()})
    rows = sorted({round(v[1], 1) for v in pos.values()}, reverse=True)
    h = max(images[m.id].shape[0] for m in cams)
    w = max(images[m.id].shape[1] for m in cams)
    out = np.zeros((h * len(rows), w * len(cols), 3), dtype=np.uint8)
    for m in cams:
        img = images[m.id]
        r, k = rows.index(round(pos[m.id][1], 1)), cols.index(round(pos[m.id][0], 1))
        out[r * h : r * h + img.shape[0], k * w : k * w + img.shape[1]] = img
    return out


def _cmd_sim(args: argparse.Namespace) -> int:
    import dataclasses

    import cv2

    from cmdragons.recording import RecordingWriter
    from cmdragons.runtime.log import RunLog, run_folder
    from cmdragons.runtime.settings import load_settings
    from sim.script import ScriptedPlay
    from sim.simulator import Simulator

    if not (args.seconds > 0 and math.isfinite(args.seconds)):
        print("cmdragons sim: --seconds must be a positive number", file=sys.stderr)
        return 2
    settings = load_settings(args.config, args.set)
    models = settings.camera_models()
    sim = Simulator(settings.field, models, settings.sim, seed=args.seed)
    script = ScriptedPlay(settings.field_geometry(), settings.field.robot.radius_m, settings.sim.script, sim.rng)
    folder = run_folder("sim", args.out)
    fps = settings.sim.physics.frame_rate_hz
    n_frames = max(1, round(args.seconds * fps))
    rec = settings.cameras.recording
    rec = dataclasses.replace(rec, codec=args.format or rec.codec, crf=rec.crf if args.crf is None else args.crf)
    recorder = RecordingWriter(folder, models, fps, rec) if args.record else None
    log = RunLog(folder / "run.mcap")
    wall0 = time.perf_counter()
    frame = None
    try:
        with _progress(not args.no_progress) as progress:
            task = progress.add_task("sim", total=n_frames, info="")
            for i in range(n_frames):
                frame = sim.capture()
                if recorder is not None:
                    recorder.write(frame.frame_number, frame.images, frame.truth)
                log.write("/truth", frame.t_capture, frame.truth.to_dict())
                log.write("/game", frame.t_capture, frame.game.to_dict())
                commands = script.commands(sim.world.snapshot())
                for c in commands:
                    log.write("/commands", frame.t_capture, c.to_dict())
                for e in sim.advance(commands):
                    log.write("/events", sim.t, {"type": type(e).__name__.lower(), **_event_dict(e)})
                if i % 15 == 0 or i == n_frames - 1:
                    g = frame.game
                    progress.update(task, completed=i + 1,
                                    info=f"t={sim.t:6.2f}s  blue {g.score_blue}:{g.score_yellow} yellow")  # fmt: skip
    finally:
        log.close()
        if recorder is not None:
            recorder.close()
    wall = time.perf_counter() - wall0
    if args.snapshot and frame is not None:
        Path(args.snapshot).parent.mkdir(parents=True, exist_ok=True)
        if not cv2.imwrite(args.snapshot, tile_cameras(frame.images, models)):
            print(f"cmdragons sim: could not write {args.snapshot}", file=sys.stderr)
            return 1
    summary = sim.summary()
    summary["wall_seconds"] = round(wall, 3)
    summary["realtime_factor"] = round(sim.t / wall, 2) if wall > 0 else None
    summary["cameras"] = [m.id for m in models]
    summary["cycle_ms"] = {
        name: {"median": float(np.median(v)), "p95": float(np.percentile(v, 95))}
        for name, v in (("physics", sim.times.physics_ms), ("render", sim.times.render_ms)) if v
    }  # fmt: skip
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    faults = sum(summary["command_faults"].values())  # type: ignore[attr-defined]
    score = summary["score"]
    print(
        f"sim: {sim.t:.1f} s simulated in {wall:.1f} s ({summary['realtime_factor']}x real time), "
        f"{n_frames} frames x {len(models)} cameras, score blue {score['blue']}:{score['yellow']} yellow, "  # type: ignore[index]
        f"{summary['kicks']} kicks, {summary['balls_out']} balls out, "
        f"{summary['robot_contacts']['count']} robot contacts, {faults} command faults -> {folder}"  # type: ignore[index]
    )
    return 0


def _cmd_play(args: argparse.Namespace) -> int:
    import cv2

    from cmdragons.runtime.log import RunLog, run_folder
    from cmdragons.runtime.match import Match
    from cmdragons.runtime.overlay import draw_overlays
    from cmdragons.runtime.settings import load_settings

    if not (args.seconds > 0 and math.isfinite(args.seconds)):
        print("cmdragons play: --seconds must be a positive number", file=sys.stderr)
        return 2
    overrides = list(args.set) + ([f"field.division={args.division}"] if args.division else [])
    settings = load_settings(args.config, overrides)
    match = Match(settings, args.opponent, args.perception, seed=args.seed, render=args.video)
    folder = run_folder("play", args.out)
    log = RunLog(folder / "run.mcap")
    video = None
    models = match.sim.cameras
    height = settings.field.robot.height_m
    fps = settings.sim.physics.frame_rate_hz
    n_frames = max(1, round(args.seconds * fps))
    wall0 = time.perf_counter()
    try:
        with _progress(not args.no_progress) as progress:
            task = progress.add_task("play", total=n_frames, info="")
            for i in range(n_frames):
                frame = match.step()
                log.write("/truth", frame.t_capture, frame.truth.to_dict())
                log.write("/game", frame.t_capture, frame.game.to_dict())
                if match.last_world is not None:
                    log.write("/world", frame.t_capture, match.last_world.to_dict())
                for c in match.last_commands:
                    log.write("/commands", frame.t_capture, c.to_dict())
                if args.video and frame.images:
                    drawn = {m.id: draw_overlays(frame.images[m.id], m, match.last_world, match.brain,
                                                 match.last_commands, height) for m in models}  # fmt: skip
                    full = tile_cameras(drawn, models)
                    tiled = cv2.resize(full, (full.shape[1] // 2, full.shape[0] // 2), interpolation=cv2.INTER_AREA)
                    if video is None:
                        video = cv2.VideoWriter(str(folder / "match.mp4"), cv2.VideoWriter.fourcc(*"mp4v"), fps,
                                                (tiled.shape[1], tiled.shape[0]))  # fmt: skip
                    video.write(tiled)
                if i % 15 == 0 or i == n_frames - 1:
                    g = frame.game
                    progress.update(task, completed=i + 1, info=f"t={frame.t_capture:6.1f}s  blue {g.score_blue}:"
                                                                 f"{g.score_yellow} yellow  {g.command}")  # fmt: skip
    finally:
        log.close()
        if video is not None:
            video.release()
    wall = time.perf_counter() - wall0
    summary = match.summary()
    summary["wall_seconds"] = round(wall, 3)
    summary["realtime_factor"] = round(summary["seconds"] / wall, 2) if wall > 0 else None
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    score, passes, coll = summary["score"], summary["passes"], summary["collisions"]
    brain = summary["cycle_ms"].get("brain", {}).get("median", float("nan"))
    print(
        f"play: {summary['seconds']:.0f} s against {args.opponent} ({args.perception}) in {wall:.1f} s: "
        f"blue {score['blue']}:{score['yellow']} yellow, {summary['shots']} shots, "
        f"passes {passes['completed']}/{passes['tried']}, own collisions {coll['own']}, "
        f"brain {brain:.2f} ms median -> {folder}"
    )
    return 0


def _event_dict(e: object) -> dict[str, object]:
    import dataclasses

    return {k: v for k, v in dataclasses.asdict(e).items()} if dataclasses.is_dataclass(e) else {}  # type: ignore[arg-type]


def _cmd_vision(args: argparse.Namespace) -> int:
    from cmdragons.runtime.log import run_folder
    from cmdragons.runtime.settings import load_settings
    from vision.run import run_vision
    from vision.sources import SourceError, open_sources

    settings = load_settings(args.config, args.set)
    try:
        sources, recording = open_sources(args.source)
    except SourceError as exc:
        print(f"cmdragons vision: {exc}", file=sys.stderr)
        return 2
    folder = run_folder("vision", args.out)
    fps = args.fps or settings.sim.physics.frame_rate_hz
    total = sum(len(s.paths) for s in sources if s.kind == "images") or None
    with _progress(not args.no_progress) as progress:
        task = progress.add_task("vision", total=total, info="")
        summary = run_vision(sources, {m.id: m for m in settings.camera_models()}, settings.vision, settings.field,
                             folder, args.video, fps, recording, lambda n: progress.advance(task, n))  # fmt: skip
    d = summary.as_dict()
    bad = summary.unreadable + summary.empty + summary.wrong_size
    ms = d["ms_per_frame"]["median"]
    print(f"vision: {summary.frames} frames from {len(sources)} camera(s), {d['robots_per_frame']:.2f} robots and "
          f"{d['balls_per_frame']:.2f} balls per frame, " + (f"{ms:.2f} ms per frame (median)" if ms else "no frame")
          + f" -> {folder}")  # fmt: skip
    for name, frames in d["bad_frames"].items():
        if frames:
            print(f"vision: {len(frames)} {name.replace('_', ' ')} frame(s): {', '.join(frames[:20])}"
                  + (" ..." if len(frames) > 20 else ""))  # fmt: skip
    for message in summary.broken_off:
        print(f"cmdragons vision: {message}; the frames before it were processed", file=sys.stderr)
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
    from cmdragons.bench import SUITES, print_table, write_json
    from cmdragons.runtime.settings import load_settings

    if args.suite not in SUITES:
        print(f"cmdragons bench: unknown suite {args.suite!r}; suites: {', '.join(sorted(SUITES))}", file=sys.stderr)
        return 2
    settings = load_settings(args.config, args.set)
    rows = SUITES[args.suite](settings, args.quick)
    print_table(args.suite, rows)
    if args.json:
        write_json(args.json, args.suite, rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
