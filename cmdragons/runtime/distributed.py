"""A match as processes on zenoh: the same stages as the embedded match, one node per part.

Nodes (``cmdragons node ROLE``) and the stages of :func:`~cmdragons.runtime.match.wiring` each runs:

    sim       the simulator and its cameras, and the match's clock (below)
    vision    vision per camera (or the truth perception of ``--perception truth``)
    team      our tracker, our brain, our statistics and the brain's timings
    opponent  a built-in team on the truth (simple, defend), or the copy of our team with its own tracker
    referee   the referee
    log       run.mcap: every topic and Foxglove's scene

The clock runs in the sim node. Lock-step (the default): every node says it is ready
(``control/ready``), the clock says ``start`` (the referee's kickoff), then per frame it ticks, the
simulator captures, waits for every playing team's commands for that frame, steps, and the clock
waits for the referee's word on the frame before the next tick. So each stage gets its inputs in the
order the embedded match gives them, and the same seed plays the same match. A team silent for
``lockstep_wait_s`` is stepped without (its robots brake by their own command timeout), and a node
that comes back rejoins at the next frame. Free-running (``realtime``): the clock ticks at the frame
rate of the wall clock and never waits, as real robots would not; it says ``start_free_running``,
and a node that falls behind then skips to the newest sensor messages, while commands that come
late still reach the robots (:class:`~cmdragons.runtime.stages.SimStage`).

Before it says it is ready, every node plays the first frames of a throwaway match
(:func:`rehearse`): a stage's first frames cost seconds of one-time work (lazy imports, numba's
cached kernels, the first plans) which a free-running match would otherwise spend with its robots
standing.

Every node reads the match's table (:func:`~cmdragons.runtime.match.wiring`: each stage's contract
and its node) from the same config and seed, checks it whole, and builds only its own stages (a
team node builds no simulator), so all nodes agree on what the others are without asking.
"""

from __future__ import annotations

import json
import os
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from cmdragons.messages import DetectionFrame, NodeControl
from cmdragons.runtime.bus import Bus, Stage, run_frames
from cmdragons.runtime.match import (
    BUILT_IN,
    OURS,
    THEIRS,
    Entry,
    Opponent,
    Perception,
    build,
    match_sim_params,
    match_summary,
    summary_stages,
    wiring,
)
from cmdragons.runtime.params import ROLES, RuntimeParams
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.stages import SimStage, SummaryCollector, Tap
from cmdragons.runtime.warmup import settle_heap
from cmdragons.runtime.zenoh_transport import LATEST_ONLY, ZenohTransport
from sim.params import robot_counts

if TYPE_CHECKING:
    from sim.simulator import Simulator

__all__ = ["FRAME_PATH", "ROLES", "MatchSpec", "frame_path_priority", "node_roles", "rehearse", "run_clock",
           "run_node", "wait_for_processes", "write_summary"]



FREE_RUNNING = "start_free_running"  # the clock's start of a free-running match (lock-step: "start")
STARTS = frozenset({"start", FREE_RUNNING})


FRAME_PATH = ("sim", "vision", "team")  # the nodes a camera frame goes through to our commands


def frame_path_priority(params: RuntimeParams, role: str) -> str | None:
    """Tune this process for real time when ``role`` is on the frame path: the real-time scheduler
    (SCHED_FIFO at ``runtime.realtime_priority``, when set; call it before zenoh opens, whose threads
    inherit it), so that on a host shared with other work (another team, a logger, a build) a
    frame's stages run the moment it comes instead of waiting for a time slice; and a CPU wake-up
    latency request (``runtime.cpu_latency_us``, when set; Linux PM QoS), held while the process
    runs, so that a CPU idle between two stages of a frame wakes at once instead of from a deep
    idle state. None, or the one line why something could not be done (not Linux, not permitted:
    root or CAP_SYS_NICE)."""
    if role not in FRAME_PATH:
        return None
    notes = []
    if params.realtime_priority > 0:
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(params.realtime_priority))
        except (AttributeError, OSError) as exc:
            reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else "not on this system"
            notes.append(f"runtime.realtime_priority: the real-time scheduler is not available ({reason}); "
                         "normal priority")
    if params.cpu_latency_us >= 0:
        note = _hold_cpu_latency(params.cpu_latency_us)
        if note is not None:
            notes.append(note)
    return "; ".join(notes) or None


CPU_LATENCY_DEVICE = "/dev/cpu_dma_latency"  # Linux PM QoS: a request held while the file is open
_cpu_latency: list[int] = []  # this process's open request (its file descriptor), at most one


def _hold_cpu_latency(us: int) -> str | None:
    """Ask the kernel to keep every CPU out of idle states slower to wake than ``us`` µs while this
    process runs (the request lasts while the device stays open, and ends with the process)."""
    import struct

    if _cpu_latency:
        return None
    try:
        fd = os.open(CPU_LATENCY_DEVICE, os.O_WRONLY)
    except OSError as exc:
        return (f"runtime.cpu_latency_us: {CPU_LATENCY_DEVICE} cannot be opened ({exc.strerror}); the kernel's "
                "idle states")
    os.write(fd, struct.pack("i", us))
    _cpu_latency.append(fd)
    return None


def node_roles(opponent: Opponent, log: bool, vision_with_sim: bool = False) -> list[str]:
    """The nodes a match needs (no opponent node against nobody or a team outside; the log node
    when logging; no vision node when vision runs in the sim node)."""
    return [r for r in ROLES if (r != "opponent" or opponent in (*BUILT_IN, "self")) and (r != "log" or log)
            and (r != "vision" or not vision_with_sim)]


class MatchSpec:
    """What every node of one match agrees on: the settings, the opponent, the perception, the seed."""

    def __init__(self, settings: Settings, opponent: Opponent, perception: Perception, seed: int,
                 opponent_settings: Settings | None = None) -> None:
        self.settings = settings
        self.opponent: Opponent = opponent
        self.perception: Perception = perception
        self.seed = seed
        self.opponent_settings = opponent_settings

    def table(self) -> list[Entry]:
        """The match's table: every stage's contract and node (nothing built; the sim node's
        simulator is built by its row)."""
        def simulator() -> Simulator:
            from sim.simulator import Simulator  # (built, and loaded, by the sim node alone)

            return Simulator(self.settings.field, self.settings.camera_models(),
                             match_sim_params(self.settings, self.opponent), seed=self.seed,
                             render=self.perception == "vision", referee=False)

        return wiring(self.settings, self.opponent, self.perception, self.seed, simulator,
                      opponent_settings=self.opponent_settings)

    def stages(self, role: str) -> list[Stage]:
        """The stages of ``role``, built as the embedded match builds them, after the whole table is
        checked; a stage no node runs (a league protocol's) is an error."""
        table = self.table()
        unplaced = [e.contract.name for e in table if not e.node]
        if unplaced:
            raise ValueError(f"no node runs stage {unplaced[0]!r}")
        return build(table, node=role)

    def nodes(self) -> dict[str, str]:
        """Stage name -> the node that runs it."""
        return {e.contract.name: e.node for e in self.table()}

    def roles(self, log: bool) -> list[str]:
        """The nodes of this match (:func:`node_roles`)."""
        return node_roles(self.opponent, log, self.settings.runtime.vision_with_sim)


def rehearse(spec: MatchSpec, role: str) -> None:
    """Play the first frames of a throwaway scene with ``role``'s kind of work in this process:
    what a stage does only on its first frames (lazy imports such as the tracker's filterpy, loading
    numba's cached kernels, the planners' first queries; seconds on a busy machine) is done before
    the node says it is ready, so a free-running match does not start with its teams a second
    behind. The team's (and a copy's) tracker and brain play ``runtime.rehearsal_frames`` frames of
    a scene made up from the field alone (:func:`rehearsal_scene`: no simulator; their first plans
    come a few frames in); the simulator and vision two (their kernels load on the first); the
    referee, the logger and the built-in opponents need none. Throwaway: nothing published."""
    frames = spec.settings.runtime.rehearsal_frames
    if frames == 0 or role in ("referee", "log") or (role == "opponent" and spec.opponent != "self"):
        return  # (a built-in opponent's first frame costs what its others do)
    settings = spec.settings
    if role in ("team", "opponent"):
        from cmdragons.messages import GameState
        from cmdragons.team import Brain
        from cmdragons.tracking import Tracker

        team = OURS if role == "team" else THEIRS
        own = spec.opponent_settings if role == "opponent" and spec.opponent_settings is not None else settings
        tracker, brain = Tracker(own.tracker), Brain(team, own)
        dt = 1.0 / settings.sim.physics.frame_rate_hz
        for k, detections in enumerate(rehearsal_scene(settings, frames)):
            brain.step(tracker.step([detections]), GameState(k * dt))
        return
    from sim.simulator import Simulator

    vision = spec.perception == "vision"
    sim = Simulator(settings.field, settings.camera_models(), settings.sim, seed=spec.seed, render=vision,
                    referee=False)
    pipelines = []
    if vision and role == "vision":
        from vision.pipeline import VisionPipeline

        pipelines = [VisionPipeline(settings.vision, settings.field, m) for m in sim.cameras]
    for _ in range(min(frames, 2)):  # the renderer's and vision's kernels load on the first frame
        frame = sim.capture()
        for pipeline, (_, image) in zip(pipelines, sorted(frame.images.items()), strict=False):
            pipeline.process(image, frame.frame_number, frame.t_capture)
        sim.advance()


def rehearsal_scene(settings: Settings, frames: int) -> list[DetectionFrame]:
    """``frames`` camera frames of a made-up scene on the configured field: each team's robots in a
    row across its own half, the ball rolling slowly from the centre: what a tracker and a brain
    rehearse on (positions and paths to plan, a ball to go for)."""
    from cmdragons.messages import BallDetection, RobotDetection

    dims = settings.field.dims
    counts = robot_counts(settings.field, settings.sim)
    dt = 1.0 / settings.sim.physics.frame_rate_hz
    out = []
    for k in range(frames):
        t = k * dt
        robots = tuple(RobotDetection(team, i, side * dims.length_m * (0.1 + 0.3 * (i % 2)),
                                      dims.width_m * ((i + 0.5) / n - 0.5) * 0.8, 0.0, 1.0, (0.0, 0.0))
                       for team, side in ((OURS, -1.0), (THEIRS, 1.0)) for n in [counts[team]]
                       for i in range(n))
        ball = BallDetection(0.3 * t, 0.1 * t, 1.0, (0.0, 0.0))
        out.append(DetectionFrame(0, k, t, t, (ball,), robots))
    return out


def _control(transport: ZenohTransport, node: str, command: str) -> None:
    transport.publish(f"control/{node}", NodeControl(node, command))


def run_node(role: str, spec: MatchSpec, transport: ZenohTransport, extra: Sequence[Stage] = (),
             err: TextIO | None = None, should_stop: Callable[[], bool] = lambda: False) -> int:
    """Run one node (not the sim: :func:`run_clock`) until the clock says stop; 0, or 1 when it
    never started (stopped first)."""
    err = err if err is not None else sys.stderr
    params = spec.settings.runtime
    rehearse(spec, role)
    stages = spec.stages(role) if role != "log" else []
    transport.expect(s.contract for s in [*stages, *extra])
    bus = Bus(transport)
    commands: list[str] = []
    bus.add(Tap(f"control:{role}", ("control/clock",), lambda _t, c: commands.append(c.command)))
    for stage in [*stages, *extra]:
        bus.add(stage)
    settle_heap()
    started = time.monotonic()
    last_ready = -1.0
    warned = started
    while not set(commands) & STARTS and not should_stop():  # say so until the clock hears it
        now = time.monotonic()
        if now - last_ready >= 0.25:
            _control(transport, role, "ready")
            last_ready = now
        if now - warned >= params.peer_timeout_s and not commands:  # (the clock says when it waits for others)
            print(f"node {role}: no match clock on cmdragons/{params.field_name} for {now - started:.0f} s: is the "
                  f"sim node running and connected to {params.zenoh.router}?", file=err)
            warned = now
        transport.spin(0.05)
    if not set(commands) & STARTS:
        return 1
    # free-running: a stage that falls behind works on the newest sensor messages, as a real team
    # does, instead of answering a backlog the robots no longer wait for; the logger keeps every one
    transport.latest_only = LATEST_ONLY if FREE_RUNNING in commands and role != "log" else ()
    bus.start()
    done = 0
    while not should_stop():
        transport.spin(0.05)
        while done < len(commands):
            command = commands[done]
            done += 1
            if command == "summarize":
                bus.summarize()
            elif command == "stop":
                return 0
        if time.monotonic() - transport.last_received > params.peer_timeout_s:
            print(f"node {role}: nothing from the other nodes for {params.peer_timeout_s:.0f} s: is the sim node "
                  "still running?", file=err)
            transport.last_received = time.monotonic()
    return 0


def run_clock(spec: MatchSpec, transport: ZenohTransport, seconds: float, roles: Sequence[str],
              realtime: bool = False, extra: Sequence[Stage] = (), err: TextIO | None = None,
              should_stop: Callable[[], bool] = lambda: False,
              on_frame: Callable[[int], None] | None = None) -> dict[str, Any]:
    """The sim node: waits for ``roles`` to be ready, starts them, runs ``seconds`` of the match and
    returns the summary (as the embedded match's, gathered over the bus); tells every node to stop."""
    err = err if err is not None else sys.stderr
    params = spec.settings.runtime
    # rehearsed while the clock waits for the nodes (and says so): (vision's rehearsal has the simulator's)
    rehearsal = threading.Thread(target=rehearse, args=(spec, "vision" if params.vision_with_sim else "sim"))
    rehearsal.start()
    if params.vision_with_sim:
        transport.local_only = ("camera/*",)  # vision is here: the frames stay in this process
    elif spec.perception == "vision":  # camera frames go through shared memory
        transport.reserve_shared_memory()
    stages = spec.stages("sim")
    transport.expect(s.contract for s in [*stages, *extra])
    bus = Bus(transport)
    ready: set[str] = set()
    judged = [0]  # the referee's words so far
    summaries = SummaryCollector()
    started = [False]

    start = FREE_RUNNING if realtime else "start"

    def on_control(_topic: str, c: NodeControl) -> None:
        if c.command == "ready":
            if started[0]:  # a node started again mid-match: it plays on from the next frame
                _control(transport, "clock", start)
            ready.add(c.node)

    bus.add(Tap("control:ready", ("control/*",), on_control))
    bus.add(Tap("clock:referee", ("referee",), lambda _t, _g: judged.__setitem__(0, judged[0] + 1)))
    placed = [0]  # the referee's teleports so far (the kickoff formation first)
    bus.add(Tap("clock:teleport", ("teleport",), lambda _t, _g: placed.__setitem__(0, placed[0] + 1)))
    for stage in [*stages, *extra, summaries]:
        bus.add(stage)
    sim_stage = next(s for s in stages if isinstance(s, SimStage))
    sim = sim_stage.sim
    others = [r for r in roles if r != "sim"]
    t0 = time.monotonic()
    warned = t0
    said = -1.0
    while not ready >= set(others) or rehearsal.is_alive():
        if should_stop():
            rehearsal.join()
            return {}
        now = time.monotonic()
        if now - t0 > params.start_timeout_s:
            raise TimeoutError(f"nodes {', '.join(sorted(set(others) - ready))} did not come up within "
                               f"{params.start_timeout_s:.0f} s (runtime.start_timeout_s)")
        if now - warned >= params.peer_timeout_s and not ready >= set(others):
            print(f"sim: waiting for nodes {', '.join(sorted(set(others) - ready))} on {params.zenoh.router}",
                  file=err)
            warned = now
        if now - said >= 0.25:  # the nodes that are ready hear that the clock is there
            _control(transport, "clock", "waiting")
            said = now
        transport.spin(0.05)
    settle_heap()
    transport.wait_for(lambda: False, params.settle_s)  # declarations propagate: nothing of frame 0 is lost
    _control(transport, "clock", start)
    started[0] = True
    bus.start()
    if not transport.wait_for(lambda: judged[0] >= 1 and placed[0] >= 1, 5.0):
        raise TimeoutError(f"the referee node did not give the kickoff (referee {judged[0]}, teleport {placed[0]})")
    fps = spec.settings.sim.physics.frame_rate_hz
    n = max(1, round(seconds * fps))
    frame_ms: list[float] = []
    silent = [0]  # frames stepped without a team's commands
    wall0 = time.perf_counter()

    def frame(i: int) -> None:
        """Frame ``i`` of the distributed match: the tick, then (free-running) the step at its wall
        time, or (lock-step) once the referee judged it, stepped without the commands that did not come."""
        f0 = time.perf_counter()
        before = judged[0]
        bus.tick(i)
        if realtime:
            _pace(transport, wall0 + (i + 1) / fps)
            sim_stage.advance_without_missing(transport.publish)
            transport.spin()
        else:
            waited = time.monotonic()
            while judged[0] == before:
                transport.spin(0.01)
                if time.monotonic() - waited > params.lockstep_wait_s:
                    missing = sim_stage.advance_without_missing(transport.publish)
                    if missing:
                        silent[0] += 1
                        print(f"sim: frame {i}: no commands from {', '.join(missing)} within "
                              f"{params.lockstep_wait_s} s: stepped without", file=err)
                    waited = time.monotonic()
        frame_ms.append((time.perf_counter() - f0) * 1e3)

    run_frames(frame, n, should_stop, on_frame)
    wall = time.perf_counter() - wall0
    nodes = spec.nodes()
    wanted = {s for s in summary_stages(spec.opponent) if nodes[s] in roles}
    _control(transport, "clock", "summarize")
    bus.summarize()
    if not transport.wait_for(lambda: wanted <= set(summaries.figures), params.start_timeout_s):
        raise TimeoutError(f"no summary from {', '.join(sorted(wanted - set(summaries.figures)))}")
    _control(transport, "clock", "stop")
    transport.spin(0.2)
    f = summaries.figures
    if summary_stages(spec.opponent) <= set(f):
        summary = match_summary(f, {"frame": frame_ms}, sim.seed, spec.opponent, spec.perception)
    else:  # a node of the match was not there: what the others said
        summary = {"seed": sim.seed, "opponent": spec.opponent, "perception": spec.perception,
                   "missing_nodes": sorted(set(spec.roles(log=False)) - set(roles)),
                   "score": f["referee"]["score"], "command_faults": f["sim"]["command_faults"]}
    summary.update(frames=len(frame_ms), wall_seconds=round(wall, 3), frames_stepped_without_a_team=silent[0],
                   realtime_factor=round(sim.t / wall, 2) if wall > 0 else None,
                   dropped_messages=transport.dropped)
    return summary


def _pace(transport: ZenohTransport, until: float) -> None:
    """Deliver what comes until the wall clock reaches ``until`` (perf_counter s)."""
    while (left := until - time.perf_counter()) > 0:
        transport.spin(min(left, 0.005))


def wait_for_processes(children: Sequence[Any], timeout_s: float = 10.0) -> None:
    """Wait for node processes told to stop; one that does not end within ``timeout_s`` is ended."""
    import subprocess

    for child in children:
        try:
            child.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            child.terminate()
            child.wait(timeout=5)


def write_summary(folder: Path, summary: dict[str, Any]) -> None:
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
