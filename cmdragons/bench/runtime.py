"""``cmdragons bench runtime``: the distributed runtime on zenoh against the embedded one.

- ``frame_to_command_<in_process or zenoh>``: the same seeded match (our team through the cameras
  against the simple opponent) embedded and as node processes in lock-step; per frame, the wall
  time from the simulator's capture (the clock's tick delivered) to our team's commands arriving
  at the simulator (median and p99 ms, the first frames left out), and the whole match's
  real-time factor. Both play the same
  frames, so the difference of the medians is what zenoh adds (``added_median_ms``).
- ``camera_frames_<shm or tcp>``: camera frames (one camera's BGR image, protobuf) from one zenoh
  client to another through a router, with and without shared memory: frames per second, MB/s.
- ``team_node_recovery``: the team node's process killed mid-match and started again: seconds
  from the new process's start to its first commands at the simulator, and frames stepped
  without the team meanwhile.

Every session is on a free loopback port; the node processes load the default configs/ (a
``--set`` given to the bench reaches the in-process parts only). ``--quick`` plays 2 s matches.
"""

from __future__ import annotations

import dataclasses
import io
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from cmdragons.messages import CameraFrame
from cmdragons.runtime.distributed import MatchSpec, node_roles, run_clock, wait_for_processes
from cmdragons.runtime.match import Match
from cmdragons.runtime.params import RuntimeParams
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.stages import Tap

__all__ = ["run"]

SEED = 1
WARM_FRAMES = 30  # frames left out of the latencies (s of the match: WARM_FRAMES / frame rate)


def _loopback(params: RuntimeParams, shared_memory: bool = True) -> RuntimeParams:
    """``params`` with the router on a free port of 127.0.0.1 (nothing else listens there)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    z = dataclasses.replace(params.zenoh, router=f"tcp/127.0.0.1:{port}", shared_memory=shared_memory)
    return dataclasses.replace(params, zenoh=z, field_name="bench")


def _node(role: str, params: RuntimeParams, opponent: str, perception: str) -> subprocess.Popen[bytes]:
    """``cmdragons node ROLE`` as a process on ``params``' router."""
    return subprocess.Popen([sys.executable, "-m", "cmdragons.cli", "node", role, "--opponent", opponent,
                             "--perception", perception, "--seed", str(SEED),
                             "--set", f"runtime.zenoh.router={params.zenoh.router}",
                             "--set", f"runtime.field_name={params.field_name}"])  # fmt: skip


def _latency_taps(latencies: list[float]) -> list[Tap]:
    """Taps that time each frame from the tick's delivery to our team's commands for it."""
    tick = [0.0]

    def on_tick(_t: str, _m: Any) -> None:
        tick[0] = time.perf_counter()

    def on_commands(_t: str, _m: Any) -> None:
        latencies.append((time.perf_counter() - tick[0]) * 1e3)

    return [Tap("bench:tick", ("clock",), on_tick), Tap("bench:commands", ("commands/blue",), on_commands)]


def _latency_rows(settings: Settings, seconds: float) -> list[dict[str, Any]]:
    from cmdragons.runtime.zenoh_transport import ZenohTransport, open_router

    embedded: list[float] = []
    m = Match(settings, "simple", "vision", seed=SEED, extra=_latency_taps(embedded))
    wall = time.perf_counter()
    m.run(seconds)
    embedded_rtf = m.sim.t / (time.perf_counter() - wall)
    params = _loopback(settings.runtime)
    spec = MatchSpec(dataclasses.replace(settings, runtime=params), "simple", "vision", SEED)
    roles = node_roles("simple", log=False)
    router = open_router(params)
    children = [_node(r, params, "simple", "vision") for r in roles if r != "sim"]
    clock = ZenohTransport(params, "sim")
    zenoh_ms: list[float] = []
    try:
        summary = run_clock(spec, clock, seconds, roles, extra=_latency_taps(zenoh_ms), err=io.StringIO())
    finally:
        wait_for_processes(children, 20.0)
        clock.close()
        router.close()
    rows = []
    medians, p99s = [], []
    for name, ms, rtf in (("in_process", embedded, embedded_rtf), ("zenoh", zenoh_ms, summary["realtime_factor"])):
        ms = ms[WARM_FRAMES:]  # the first frames load what each process imports lazily
        medians.append(float(np.median(ms)))
        p99s.append(float(np.percentile(ms, 99)))
        rows.append({"name": f"frame_to_command_{name}", "frames": len(ms), "median_ms": medians[-1],
                     "p99_ms": p99s[-1], "added_median_ms": medians[-1] - medians[0],
                     "added_p99_ms": p99s[-1] - p99s[0], "realtime_factor": float(rtf)})  # fmt: skip
    return rows


def _throughput_row(settings: Settings, shared_memory: bool, frames: int, limit_s: float) -> dict[str, Any]:
    """Camera frames from one client to another through a router: how many a second get through."""
    from cmdragons.runtime.zenoh_transport import ZenohTransport, open_router

    params = _loopback(settings.runtime, shared_memory)
    model = settings.camera_models()[0]
    image = np.random.default_rng(0).integers(0, 256, (model.height, model.width, 3), dtype=np.uint8)
    router = open_router(params)
    sender, receiver = ZenohTransport(params, "camera"), ZenohTransport(params, "vision")
    got: list[float] = []
    receiver.subscribe("camera/*", lambda _t, _f: got.append(time.perf_counter()))
    try:
        if not sender.wait_for(lambda: sender.has_subscribers("camera/0/frame"), 10.0):
            raise TimeoutError("the receiving client never subscribed")
        done = threading.Event()

        def receive() -> None:
            receiver.wait_for(lambda: len(got) >= frames or done.is_set(), limit_s + 5.0, poll_s=0.01)

        th = threading.Thread(target=receive)
        th.start()
        t0 = time.perf_counter()
        for i in range(frames):
            sender.publish("camera/0/frame", CameraFrame(0, i, i / 60, image))
            if time.perf_counter() - t0 > limit_s:
                break
        th.join(limit_s + 10.0)
        done.set()
        th.join()
    finally:
        sender.close()
        receiver.close()
        router.close()
    elapsed = (got[-1] - t0) if got else float("nan")
    return {"name": f"camera_frames_{'shm' if shared_memory else 'tcp'}", "frames": len(got),
            "frames_per_s": len(got) / elapsed if got else 0.0,
            "mb_per_s": len(got) * image.nbytes / 1e6 / elapsed if got else 0.0}  # fmt: skip


def _until(done: Callable[[], bool], timeout_s: float, what: str) -> None:
    end = time.monotonic() + timeout_s
    while not done():
        if time.monotonic() > end:
            raise TimeoutError(f"never: {what}")
        time.sleep(0.005)


def _recovery_row(settings: Settings) -> dict[str, Any]:
    """Kill the team node's process mid-match, start it again: seconds until its commands come."""
    from cmdragons.runtime.zenoh_transport import ZenohTransport, open_router

    params = dataclasses.replace(_loopback(settings.runtime), lockstep_wait_s=0.05)
    spec = MatchSpec(dataclasses.replace(settings, runtime=params), "simple", "truth", SEED)
    roles = node_roles("simple", log=False)
    router = open_router(params)
    others = [_node(r, params, "simple", "truth") for r in roles if r not in ("sim", "team")]
    team = _node("team", params, "simple", "truth")
    clock = ZenohTransport(params, "sim")
    commands: list[tuple[float, int]] = []
    frames: list[int] = []
    enough = threading.Event()
    taps = [Tap("bench:commands", ("commands/blue",), lambda _t, c: commands.append((time.perf_counter(),
                                                                                     c.frame_number))),
            Tap("bench:truth", ("truth",), lambda _t, g: frames.append(g.frame_number))]  # fmt: skip
    result: dict[str, Any] = {}
    runner = threading.Thread(target=lambda: result.update(run_clock(
        spec, clock, 120.0, roles, extra=taps, should_stop=enough.is_set, err=io.StringIO())))  # "stepped without"
    try:
        runner.start()
        _until(lambda: len(commands) >= 30, 120.0, "the team node's commands")
        team.kill()
        team.wait(10)
        killed_at = frames[-1]
        t_restart = time.perf_counter()
        team = _node("team", params, "simple", "truth")
        _until(lambda: commands[-1][1] > killed_at, 120.0, "the restarted team node's commands")
        back_at = commands[-1][0]
    finally:
        enough.set()
        runner.join(60)
        team.kill()
        team.wait(10)
        wait_for_processes(others, 20.0)
        clock.close()
        router.close()
    gone = [f for f in frames if killed_at < f < min(f for _, f in commands if f > killed_at)]
    return {"name": "team_node_recovery", "recovery_s": back_at - t_restart, "frames_without_team": len(gone),
            "frames": result.get("frames", len(frames))}  # fmt: skip


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    seconds = 2.0 if quick else 6.0
    rows = _latency_rows(settings, seconds)
    n = 120 if quick else 600
    rows += [_throughput_row(settings, shm, n, 10.0 if quick else 20.0) for shm in (True, False)]
    rows.append(_recovery_row(settings))
    return rows
