"""``cmdragons bench runtime``: the distributed runtime on zenoh against the embedded one.

- ``frame_to_command_<in_process or zenoh>``: the same seeded match (our team through the cameras
  against the simple opponent) embedded and as node processes in lock-step; per frame, the wall
  time from the clock's tick (before the simulator renders the frame, so the zenoh side pays for
  publishing the images) to our team's commands arriving at the simulator (median and p99 ms, the
  first frames left out), and the whole match's real-time factor. Both play the same frames, so
  the difference of the medians is what zenoh adds (``added_median_ms``). ``zenoh`` has vision in
  its own node (a frame crosses three processes: images to vision, detections to the team,
  commands to the simulator); ``zenoh_vision_with_sim`` has it in the sim node
  (``runtime.vision_with_sim``: two crossings, the images stay where they are rendered).
- ``zenoh_one_hop_floor``: zenoh alone (no protobuf, no stage), a command-sized message to a
  client in another process and straight back through the router: half the round trip, what one
  crossing cannot go below on this machine.
- ``camera_frames_<shm or tcp>``: camera frames (one camera's BGR image, protobuf) from one zenoh
  client to another through a router, with and without shared memory: frames per second, MB/s.
- ``team_node_recovery``: the team node's process killed mid-match and started again: seconds
  from the new process's start to its first commands at the simulator, and frames stepped
  without the team meanwhile.

Every session is on a free loopback port; the node processes load the default configs/ (a
``--set`` given to the bench reaches the in-process parts only). The three set-ups play in turn,
four times (``--quick``: once, 2 s matches), their frames pooled.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import io
import multiprocessing
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from cmdragons.messages import CameraFrame
from cmdragons.runtime.bus import InProcessTransport, Transport
from cmdragons.runtime.distributed import MatchSpec, frame_path_priority, run_clock, wait_for_processes
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
                             "--set", f"runtime.field_name={params.field_name}",
                             "--set", f"runtime.vision_with_sim={str(params.vision_with_sim).lower()}",
                             "--set", f"runtime.realtime_priority={params.realtime_priority}",
                             "--set", f"runtime.cpu_latency_us={params.cpu_latency_us}"])


def _realtime_latency_rows(settings: Settings, seconds: float, rounds: int) -> list[dict[str, Any]]:
    """:func:`_latency_rows` with this process (the embedded match, and the sim node with the
    router) and the frame path's nodes on the real-time scheduler, and the CPUs kept from idle
    states slow to wake while they run (``runtime.cpu_latency_us``); in a process of its own,
    spawned for it, so that every thread (zenoh's are made once a process and kept) inherits the
    scheduler and the CPU request ends with it."""
    note = frame_path_priority(settings.runtime, "sim")
    if note is not None:
        return [{"name": "frame_to_command_rt", "note": note}]
    return _latency_rows(settings, seconds, rounds, "_rt")


class _TimesTicks:
    """A transport that notes the wall time (perf_counter s) at which the clock publishes each tick,
    before the simulator renders the frame: in ``tick[0]``."""

    tick: list[float]

    def publish(self, topic: str, message: Any) -> None:
        if topic == "clock":
            self.tick[0] = time.perf_counter()
        super().publish(topic, message)  # type: ignore[misc]


class _InProcessTicks(_TimesTicks, InProcessTransport):
    def __init__(self, tick: list[float]) -> None:
        super().__init__()
        self.tick = tick


def _time_commands(transport: Transport, tick: list[float], latencies: list[float]) -> None:
    """Time each frame from its tick to our team's commands for it arriving (ms): subscribed on the
    transport before any stage, so the time is taken as they come, before the simulator steps on them."""
    transport.subscribe("commands/blue", lambda _t, _m: latencies.append((time.perf_counter() - tick[0]) * 1e3))


def _zenoh_latencies(settings: Settings, seconds: float, vision_with_sim: bool) -> tuple[list[float], float]:
    """The bench's match as node processes on zenoh in lock-step: per frame tick -> commands (ms),
    and the real-time factor. ``vision_with_sim``: vision in the sim node (no vision node)."""
    from cmdragons.runtime.zenoh_transport import ZenohTransport, open_router

    class ZenohTicks(_TimesTicks, ZenohTransport):
        pass

    params = dataclasses.replace(_loopback(settings.runtime), vision_with_sim=vision_with_sim)
    spec = MatchSpec(dataclasses.replace(settings, runtime=params), "simple", "vision", SEED)
    roles = spec.roles(log=False)
    router = open_router(params)
    children = [_node(r, params, "simple", "vision") for r in roles if r != "sim"]
    clock = ZenohTicks(params, "sim", session=router)  # the sim node is the router, as in play --distributed
    clock.tick = [0.0]
    ms: list[float] = []
    _time_commands(clock, clock.tick, ms)
    try:
        summary = run_clock(spec, clock, seconds, roles, err=io.StringIO())
    finally:
        wait_for_processes(children, 20.0)
        clock.close()
        router.close()
    return ms, float(summary["realtime_factor"])


def _embedded_latencies(settings: Settings, seconds: float) -> tuple[list[float], float]:
    """The bench's match embedded: per frame tick -> commands (ms), and the real-time factor."""
    ms: list[float] = []
    transport = _InProcessTicks([0.0])
    _time_commands(transport, transport.tick, ms)
    m = Match(settings, "simple", "vision", seed=SEED, transport=transport)
    wall = time.perf_counter()
    m.run(seconds)
    return ms, m.sim.t / (time.perf_counter() - wall)


def _latency_rows(settings: Settings, seconds: float, rounds: int, suffix: str = "") -> list[dict[str, Any]]:
    """The three set-ups in turn, ``rounds`` times (the machine's load drifts: each set-up meets
    it alike), their frames pooled. The nodes start on the scheduler of
    ``settings.runtime.realtime_priority``; this process stays on the one it runs on."""
    setups: dict[str, Callable[[], tuple[list[float], float]]] = {
        "in_process": lambda: _embedded_latencies(settings, seconds),
        "zenoh": lambda: _zenoh_latencies(settings, seconds, vision_with_sim=False),
        "zenoh_vision_with_sim": lambda: _zenoh_latencies(settings, seconds, vision_with_sim=True)}  # fmt: skip
    pooled: dict[str, tuple[list[float], list[float]]] = {name: ([], []) for name in setups}
    for _ in range(rounds):
        for name, run_once in setups.items():
            ms, rtf = run_once()
            pooled[name][0].extend(ms[WARM_FRAMES:])  # the first frames load what each process imports lazily
            pooled[name][1].append(rtf)
    rows = []
    medians, p99s = [], []
    for name, (ms, rtfs) in pooled.items():
        medians.append(float(np.median(ms)))
        p99s.append(float(np.percentile(ms, 99)))
        rows.append({"name": f"frame_to_command_{name}{suffix}", "frames": len(ms), "median_ms": medians[-1],
                     "p99_ms": p99s[-1], "added_median_ms": medians[-1] - medians[0],
                     "added_p99_ms": p99s[-1] - p99s[0], "realtime_factor": float(np.mean(rtfs))})
    return rows


def _floor_row(settings: Settings, messages: int, size_bytes: int = 300) -> dict[str, Any]:
    """zenoh alone, no protobuf and no stage: a message of a command's size from one client to
    another process's client through the router, which answers at once from its callback; half
    the round trip is what one hop of the match cannot go below."""
    from cmdragons.runtime.zenoh_transport import open_router, round_trips

    params = _loopback(settings.runtime)
    router = open_router(params)
    try:
        rtt = round_trips(params, messages, size_bytes, session=router)
    finally:
        router.close()
    one_way = np.asarray(rtt[10:]) / 2
    return {"name": "zenoh_one_hop_floor", "messages": len(one_way), "bytes": size_bytes,
            "median_ms": float(np.median(one_way)), "p99_ms": float(np.percentile(one_way, 99))}


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
            "mb_per_s": len(got) * image.nbytes / 1e6 / elapsed if got else 0.0}


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
    roles = spec.roles(log=False)
    router = open_router(params)
    others = [_node(r, params, "simple", "truth") for r in roles if r not in ("sim", "team")]
    team = _node("team", params, "simple", "truth")
    clock = ZenohTransport(params, "sim", session=router)
    commands: list[tuple[float, int]] = []
    frames: list[int] = []
    enough = threading.Event()
    taps = [Tap("bench:commands", ("commands/blue",), lambda _t, c: commands.append((time.perf_counter(),
                                                                                     c.frame_number))),
            Tap("bench:truth", ("truth",), lambda _t, g: frames.append(g.frame_number))]
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
            "frames": result.get("frames", len(frames))}


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    seconds = 2.0 if quick else 6.0
    rounds = 1 if quick else 4  # a 6 s match's median moves by a few tenths of a ms from one round to the next
    normal = dataclasses.replace(settings.runtime, realtime_priority=0, cpu_latency_us=-1)
    rows = _latency_rows(dataclasses.replace(settings, runtime=normal), seconds, rounds)
    r = settings.runtime  # the real-time rows: the real-time scheduler and CPUs that wake at once
    realtime = dataclasses.replace(r, realtime_priority=r.realtime_priority or 10,
                                   cpu_latency_us=r.cpu_latency_us if r.cpu_latency_us >= 0 else 0)
    spawn = multiprocessing.get_context("spawn")  # (never fork a process that has zenoh open)
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=spawn) as pool:
        rows += pool.submit(_realtime_latency_rows, dataclasses.replace(settings, runtime=realtime), seconds,
                            rounds).result()
    rows.append(_floor_row(settings, 200 if quick else 1000))
    n = 120 if quick else 600
    rows += [_throughput_row(settings, shm, n, 10.0 if quick else 20.0) for shm in (True, False)]
    rows.append(_recovery_row(settings))
    return rows
