"""``cmdragons sim --serve``: our simulator alone as a league simulator, paced to the wall clock.

It speaks what grSim speaks (SSL-Vision packets with the geometry, the simulation protocol for both
teams, Referee packets from its own referee: :func:`~cmdragons.runtime.match.served_wiring`) until
interrupted or ``--seconds`` of match time, then writes summary.json and says the score on one line.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

import numpy as np

from cmdragons.runtime.interrupt import Interrupt

__all__ = ["cmd_serve", "refused_options"]

# the options of cmdragons sim that record what the scripted simulator renders: not served
_RECORDING = (("record", "--record"), ("format", "--format"), ("crf", "--crf"), ("snapshot", "--snapshot"))


def refused_options(args: argparse.Namespace) -> str | None:
    """The line saying which given option ``--serve`` does not take, or None."""
    given = [flag for key, flag in _RECORDING if getattr(args, key) not in (None, False)]
    if given:
        return (f"cmdragons sim: --serve renders no images, so {', '.join(given)} cannot be used with it "
                "(it sends SSL-Vision packets; record them with a client)")
    return None


def cmd_serve(args: argparse.Namespace, stop: Interrupt) -> int:
    from cmdragons.cli.progress import progress_bar, run_shown
    from cmdragons.messages import GameState
    from cmdragons.runtime.bus import Bus
    from cmdragons.runtime.log import OutputError, RunLog, run_folder
    from cmdragons.runtime.match import build, served_wiring
    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.ssl.stages import close_sockets
    from cmdragons.runtime.stages import LoggerStage, SummaryCollector, Tap
    from cmdragons.runtime.warmup import settle_heap
    from sim.simulator import Simulator

    refused = refused_options(args)
    if refused is not None:
        print(refused, file=sys.stderr)
        return 2
    overrides = [*args.set, *([f"field.division={args.division}"] if args.division else [])]
    settings = load_settings(args.config, overrides)
    models = settings.camera_models()
    sim = Simulator(settings.field, models, settings.sim, seed=args.seed, render=False, referee=False)
    fps = settings.sim.physics.frame_rate_hz
    n_frames = max(1, round(args.seconds * fps)) if args.seconds is not None else sys.maxsize
    game = [GameState(0.0)]  # the referee's latest word, for the progress bar
    summaries = SummaryCollector()
    progress_tap = Tap("progress", ("referee",), lambda _t, g: game.__setitem__(0, g))
    try:  # the sockets first: a port another program holds is said before anything is written
        served = build(served_wiring(settings, sim, sim.seed), [summaries, progress_tap])
    except OSError as exc:
        s = settings.protocols.simulation
        print(f"cmdragons sim: --serve cannot open its sockets ({exc.strerror or exc}): another simulator may hold "
              f"{s.address} ports {s.control_port}, {s.blue_port} or {s.yellow_port}; stop it or move ours with "
              "--set protocols.simulation.control_port=... (and blue_port, yellow_port)", file=sys.stderr)
        return 2
    try:
        folder = run_folder("serve", args.out, overwrite=args.overwrite)
    except OutputError:
        close_sockets(served)
        raise
    log = RunLog(folder / "run.mcap")
    bus = Bus()
    stages = [*served, LoggerStage(log)]
    try:
        for stage in stages:
            bus.add(stage)
        print(_listening(settings, [m.id for m in models]), flush=True)
        bus.start()
        settle_heap()
        late = [0]
        frame_ms: list[float] = []  # each frame's work (the wall time it took, the wait for it left out)
        wall0 = time.monotonic()
        due = [wall0]  # when the next frame is due (wall clock)

        def frame(i: int) -> None:
            """Frame ``i`` at its wall time. A frame more than a frame's time late runs at once and is
            counted: from it on the frames are due anew (the clients see the frame rate, never a burst)."""
            wait_s = due[0] - time.monotonic()
            if wait_s > 0:
                time.sleep(wait_s)
            elif wait_s < -1.0 / fps:
                late[0] += 1
                due[0] = time.monotonic()
            due[0] += 1.0 / fps
            t0 = time.perf_counter()
            bus.tick(i)
            frame_ms.append((time.perf_counter() - t0) * 1e3)

        with progress_bar(not args.no_progress, counts=args.seconds is not None) as progress, stop.soft():
            task = progress.add_task("sim --serve", total=n_frames if args.seconds is not None else None, info="")
            run_shown(frame, n_frames, stop, progress, task,
                      lambda _i: f"t={sim.t:7.2f}s  blue {game[0].score_blue}:{game[0].score_yellow} yellow")
        wall = time.monotonic() - wall0
    finally:
        with stop.shield():
            close_sockets(stages)
            log.close()
    with stop.shield():
        bus.summarize()
        return _finish(args, stop, folder, summaries.figures, wall, late[0], frame_ms, len(models))


def _listening(settings: Any, camera_ids: list[int]) -> str:
    """The line that tells a client where to listen and send."""
    p = settings.protocols
    s = p.simulation
    return (f"sim --serve: Division {settings.field.division}, cameras {', '.join(map(str, camera_ids))}: SSL-Vision "
            f"on {p.vision.group}:{p.simulation.vision_port}, Referee on {p.referee.group}:{p.referee.port} (interface "
            f"{p.interface}, ttl {p.ttl}); simulation protocol on {s.address}: control {s.control_port}, blue "
            f"{s.blue_port}, yellow {s.yellow_port}")


def _finish(args: argparse.Namespace, stop: Interrupt, folder: Any, f: dict[str, Any], wall: float, late: int,
            frame_ms: list[float], cameras: int) -> int:
    """summary.json and the line that sums the run up."""
    sim, referee = f["sim"], f["referee"]
    seconds = float(sim["seconds"])
    summary = {
        "score": referee["score"], "seconds": seconds, "wall_seconds": round(wall, 3), "frames": sim["frames"],
        "frames_late": late, "frame_ms": {"median": float(np.median(frame_ms)),
                                          "p95": float(np.percentile(frame_ms, 95))} if frame_ms else None,
        "cameras": cameras, "interrupted": stop.requested, "kicks": referee["kicks"],
        "balls_out": referee["balls_out"], "command_faults": sim["command_faults"],
        "rules": {k: referee[k] for k in ("rules", "game_stage", "fouls", "cards", "placements")},
        "protocols": {k: v for k, v in f.items() if k.startswith("ssl/")},
    }
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    score, received = summary["score"], f["ssl/simulation_in"]
    late_frames = f"{late} late frame{'' if late == 1 else 's'}"
    print(f"sim --serve: {seconds:.1f} s served in {wall:.1f} s ({late_frames}), score blue "
          f"{score['blue']}:{score['yellow']} yellow, {received['packets']} robot commands and "
          f"{received['teleports']} teleports taken{', interrupted by ' + str(stop.signal) if stop.requested else ''}; "
          f"output -> {folder}")
    return stop.exit_code
