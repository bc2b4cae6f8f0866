"""The match as nodes on zenoh (loopback): lock-step equals the embedded match; a silent team is
stepped without and its robots brake; a team node killed and started again rejoins."""

from __future__ import annotations

import math
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cmdragons.runtime.distributed import MatchSpec, node_roles, run_clock, run_node
from cmdragons.runtime.match import Match
from cmdragons.runtime.stages import Tap
from tests.runtime.test_zenoh import SETTINGS, loopback_params

SECONDS = 1.0
SEED = 7
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def router() -> Iterator[Any]:
    import zenoh

    params = loopback_params("match")
    session = zenoh.open(params.zenoh.config("router"))
    try:
        yield params
    finally:
        session.close()


def _nodes(spec: MatchSpec, roles: list[str], stop: threading.Event) -> list[threading.Thread]:
    from cmdragons.runtime.zenoh_transport import ZenohTransport

    def node(role: str) -> None:
        t = ZenohTransport(spec.settings.runtime, role)
        try:
            run_node(role, spec, t, should_stop=stop.is_set)
        finally:
            t.close()

    threads = [threading.Thread(target=node, args=(r,), daemon=True) for r in roles]
    for th in threads:
        th.start()
    return threads


# small camera images keep a match through the cameras quick (vision finds less on them: the same
# for both runs)
SMALL_CAMERAS = ["cameras.auto.resolution_px=[160,120]", "cameras.auto.grid=[2,1]"]


@pytest.mark.parametrize(("perception", "vision_with_sim"), [("truth", False), ("truth", True), ("vision", True)])
def test_lock_step_nodes_play_the_embedded_match(router: Any, perception: Any, vision_with_sim: bool) -> None:
    import dataclasses

    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.zenoh_transport import ZenohTransport

    base = SETTINGS if perception == "truth" else load_settings(ROOT / "configs", SMALL_CAMERAS)
    settings = dataclasses.replace(base, runtime=dataclasses.replace(router, vision_with_sim=vision_with_sim))
    embedded: list[Any] = []
    m = Match(settings, "simple", perception, seed=SEED,
              extra=[Tap("rec", ("commands/*", "referee"), lambda t, x: embedded.append((t, x)))])
    expected = m.run(SECONDS)
    spec = MatchSpec(settings, "simple", perception, m.seed)
    roles = spec.roles(log=False)
    assert ("vision" in roles) != vision_with_sim
    stop = threading.Event()
    threads = _nodes(spec, [r for r in roles if r != "sim"], stop)
    got: list[Any] = []
    clock = ZenohTransport(router, "sim")
    try:
        summary = run_clock(spec, clock, SECONDS, roles,
                            extra=[Tap("rec", ("commands/*", "referee"), lambda t, x: got.append((t, x)))])
    finally:
        stop.set()
        for th in threads:
            th.join(10)
        clock.close()
    for key in ("score", "shots", "passes", "collisions", "kicks", "balls_out", "command_faults", "tracker"):
        assert summary[key] == expected[key], key
    by_topic = {t: [x for tt, x in embedded if tt == t] for t in ("commands/blue", "commands/yellow", "referee")}
    for topic, xs in by_topic.items():
        assert [x for t, x in got if t == topic] == xs, topic
    assert summary["frames_stepped_without_a_team"] == 0 and summary["dropped_messages"] == 0


def test_a_silent_team_is_stepped_without_and_its_robots_brake(router: Any) -> None:
    import dataclasses

    from cmdragons.runtime.zenoh_transport import ZenohTransport

    settings = dataclasses.replace(SETTINGS, runtime=dataclasses.replace(router, lockstep_wait_s=0.05))
    spec = MatchSpec(settings, "simple", "truth", SEED)
    roles = [r for r in node_roles("simple", log=False) if r != "team"]  # our team's node never comes
    stop = threading.Event()
    threads = _nodes(spec, [r for r in roles if r != "sim"], stop)
    truth: list[Any] = []
    clock = ZenohTransport(settings.runtime, "sim")
    try:
        summary = run_clock(spec, clock, 0.75, roles, extra=[Tap("rec", ("truth",), lambda _t, x: truth.append(x))])
    finally:
        stop.set()
        for th in threads:
            th.join(10)
        clock.close()
    frames = summary["frames"]
    assert summary["frames_stepped_without_a_team"] == frames
    blue = [r for r in truth[-1].robots if r.team == "blue"]
    # never commanded: the watchdog holds them (braked, at rest) while the opponent plays
    assert blue and all(math.hypot(r.vx, r.vy) < 0.05 for r in blue)
    assert any(math.hypot(r.vx, r.vy) > 0.1 for tr in truth for r in tr.robots if r.team == "yellow")


def _team_process(router: Any) -> subprocess.Popen[bytes]:
    """``cmdragons node team`` as its own process on the test's router."""
    return subprocess.Popen([sys.executable, "-m", "cmdragons.cli", "node", "team", "--perception", "truth",
                             "--seed", str(SEED), "--set", f"runtime.zenoh.router={router.zenoh.router}",
                             "--set", f"runtime.field_name={router.field_name}"], cwd=ROOT)


def _until(done: Callable[[], bool], what: str, timeout_s: float = 120.0) -> None:
    """Wait for ``done()``, polling every 20 ms at most ``timeout_s`` worth of polls (a guard
    against a hang, not a measure of speed)."""
    for _ in range(round(timeout_s / 0.02)):
        if done():
            return
        time.sleep(0.02)
    pytest.fail(f"never: {what}")


@pytest.mark.slow
def test_a_killed_team_node_rejoins_and_the_match_goes_on(router: Any) -> None:
    import dataclasses

    from cmdragons.runtime.zenoh_transport import ZenohTransport

    settings = dataclasses.replace(SETTINGS, runtime=dataclasses.replace(router, lockstep_wait_s=0.05))
    spec = MatchSpec(settings, "simple", "truth", SEED)
    roles = node_roles("simple", log=False)
    stop = threading.Event()
    threads = _nodes(spec, [r for r in roles if r not in ("sim", "team")], stop)
    commands: list[int] = []  # the frames blue answered
    frames: list[int] = []
    enough = threading.Event()  # the restarted node answered long enough: end the match
    clock = ZenohTransport(settings.runtime, "sim")
    taps = [Tap("rec:commands", ("commands/blue",), lambda _t, c: commands.append(c.frame_number)),
            Tap("rec:truth", ("truth",), lambda _t, g: frames.append(g.frame_number))]
    result: dict[str, Any] = {}

    def match() -> None:
        result.update(run_clock(spec, clock, 60.0, roles, extra=taps, should_stop=enough.is_set))

    team = _team_process(router)
    runner = threading.Thread(target=match, daemon=True)
    try:
        runner.start()
        _until(lambda: len(commands) >= 20, "the first team node's commands")
        team.kill()
        team.wait(10)
        killed_at = frames[-1]
        _until(lambda: frames[-1] >= killed_at + 30, "frames stepped without the team")
        restarted_at = frames[-1]
        team = _team_process(router)
        _until(lambda: sum(f > restarted_at for f in commands) >= 30, "the restarted team node's commands")
        enough.set()
        runner.join(60)
    finally:
        enough.set()
        stop.set()
        team.kill()
        team.wait(10)
        for th in threads:
            th.join(10)
        clock.close()
    assert not runner.is_alive() and result, "the match did not end"
    gap = [f for f in frames if killed_at < f <= restarted_at]
    assert gap and not set(gap) & set(commands)  # nobody answered while the node was gone
    after = sorted(f for f in commands if f > restarted_at)
    # once back, blue answers every frame to the end, in lock-step again
    assert after == list(range(after[0], frames[-1] + 1)) and len(after) >= 30
    assert result["frames"] == len(frames) and result["frames_stepped_without_a_team"] >= 30
    assert result["command_faults"]["timed_out"] > 0  # the watchdog braked blue while it was gone


def _first_moving_frame(truth: list[Any], team: str, speed_m_s: float) -> int | None:
    """The first frame of the simulator's truth in which a robot of ``team`` moves faster than
    ``speed_m_s``."""
    return next((g.frame_number for g in truth if any(math.hypot(r.vx, r.vy) > speed_m_s for r in g.robots
                                                      if r.team == team)), None)


# free-running: our robots may start this many frames later than in lock-step (a quarter second:
# commands come a frame or two late when the team runs behind the wall clock)
START_SLACK_FRAMES = 15


def test_free_running_real_time_steps_every_frame_and_our_robots_drive_at_once(router: Any) -> None:
    import dataclasses

    from cmdragons.runtime.zenoh_transport import ZenohTransport

    settings = dataclasses.replace(SETTINGS, runtime=router)
    lockstep: list[Any] = []
    Match(settings, "simple", "truth", seed=SEED, extra=[Tap("rec", ("truth",), lambda _t, g: lockstep.append(g))]
          ).run(SECONDS)
    starts = _first_moving_frame(lockstep, "blue", 0.1)
    assert starts is not None  # the reference: when our robots drive in lock-step
    spec = MatchSpec(settings, "simple", "truth", SEED)
    roles = node_roles("simple", log=False)
    stop = threading.Event()
    threads = _nodes(spec, [r for r in roles if r != "sim"], stop)
    commands: list[Any] = []
    truth: list[Any] = []
    clock = ZenohTransport(router, "sim")
    taps = [Tap("rec:commands", ("commands/*",), lambda _t, c: commands.append(c)),
            Tap("rec:truth", ("truth",), lambda _t, g: truth.append(g))]
    try:
        summary = run_clock(spec, clock, SECONDS, roles, realtime=True, extra=taps)
    finally:
        stop.set()
        for th in threads:
            th.join(10)
        clock.close()
    n = round(SECONDS * SETTINGS.sim.physics.frame_rate_hz)
    assert summary["frames"] == n and [g.frame_number for g in truth] == list(range(truth[0].frame_number, n))
    assert summary["realtime_factor"] <= 1.01  # paced by the wall clock, never ahead of it
    # it never waits for a team, yet both teams' commands came
    assert summary["frames_stepped_without_a_team"] == 0 and {c.team for c in commands} == {"blue", "yellow"}
    # the simple opponent's robots drive, and ours from (nearly) the frame they do in lock-step: every
    # node played its first frames before the match, and commands that come late still reach the robots
    assert any(math.hypot(r.vx, r.vy) > 0.1 for g in truth for r in g.robots if r.team == "yellow")
    moving = _first_moving_frame(truth, "blue", 0.1)
    assert moving is not None and moving <= starts + START_SLACK_FRAMES, (moving, starts)


def test_a_node_without_a_clock_says_so_and_not_while_the_clock_waits_for_others(router: Any) -> None:
    import dataclasses
    import io

    from cmdragons.messages import NodeControl
    from cmdragons.runtime.zenoh_transport import ZenohTransport

    params = dataclasses.replace(router, peer_timeout_s=0.2, rehearsal_frames=0)
    spec = MatchSpec(dataclasses.replace(SETTINGS, runtime=params), "simple", "truth", SEED)
    said = {}
    for clock_there in (False, True):
        err = io.StringIO()
        node, clock = ZenohTransport(params, "referee"), ZenohTransport(params, "sim")
        heard: list[str] = []
        clock.subscribe("control/*", lambda _t, c, heard=heard: heard.append(c.node))
        enough = lambda heard=heard: len(heard) >= 12  # noqa: E731
        runner = threading.Thread(target=run_node, args=("referee", spec, node),
                                  kwargs={"err": err, "should_stop": enough}, daemon=True)
        try:
            runner.start()
            while runner.is_alive():  # the node says it is ready four times a second: 3 s in all
                if clock_there:
                    clock.publish("control/clock", NodeControl("clock", "waiting"))
                clock.spin(0.05)
            runner.join(10)
        finally:
            node.close()
            clock.close()
        said[clock_there] = err.getvalue()
    assert "no match clock" in said[False] and "is the sim node running" in said[False]
    assert said[True] == ""


_SCHEDULER_PROBE = """
import dataclasses, os
from cmdragons.runtime.distributed import frame_path_priority
from cmdragons.runtime.params import RuntimeParams
params = dataclasses.replace(RuntimeParams(), realtime_priority={priority})
note = frame_path_priority(params, {role!r})
print(os.sched_getscheduler(0) == os.SCHED_FIFO, os.sched_getparam(0).sched_priority, note)
"""


@pytest.mark.skipif(not hasattr(__import__("os"), "sched_setscheduler"), reason="no POSIX scheduler calls here")
@pytest.mark.parametrize(("priority", "role"), [(0, "team"), (7, "opponent"), (7, "log"), (7, "team"), (7, "sim")])
def test_the_frame_paths_nodes_go_on_the_real_time_scheduler_only_when_set(priority: int, role: str) -> None:
    """In a process of its own (the setting changes the whole process): off by default, and never
    for the nodes off the frame path; on, the process runs SCHED_FIFO at the priority, or, where the
    system does not allow it, keeps the normal scheduler and says why in one line."""
    out = subprocess.run([sys.executable, "-c", _SCHEDULER_PROBE.format(priority=priority, role=role)], cwd=ROOT,
                         capture_output=True, text=True, check=True).stdout.split(maxsplit=2)
    fifo, level, note = out[0] == "True", int(out[1]), out[2].strip()
    if priority == 0 or role not in ("sim", "vision", "team"):
        assert (fifo, note) == (False, "None")
    elif fifo:
        assert level == priority and note == "None"
    else:
        assert note.startswith("runtime.realtime_priority: the real-time scheduler is not available (")


_CPU_LATENCY_PROBE = """
import dataclasses, os, struct
from cmdragons.runtime.distributed import CPU_LATENCY_DEVICE, frame_path_priority
from cmdragons.runtime.params import RuntimeParams

def target():  # the kernel's CPU latency target now: the least of every request held
    try:
        with open(CPU_LATENCY_DEVICE, "rb") as f:
            return struct.unpack("i", f.read(4))[0]
    except OSError:
        return None

before = target()
note = frame_path_priority(dataclasses.replace(RuntimeParams(), cpu_latency_us={us}), {role!r})
print(before, target(), note)
"""


@pytest.mark.skipif(not __import__("os").path.exists("/dev/cpu_dma_latency"), reason="no Linux PM QoS device here")
@pytest.mark.parametrize(("us", "role"), [(-1, "team"), (37, "opponent"), (37, "team"), (0, "sim")])
def test_the_frame_paths_nodes_hold_a_cpu_latency_request_only_when_set(us: int, role: str) -> None:
    """In a process of its own (the request lasts as long as the process): none by default or off
    the frame path; on, the kernel's target is at most the request while the process runs, or,
    where the device may not be opened, the node says why in one line."""
    out = subprocess.run([sys.executable, "-c", _CPU_LATENCY_PROBE.format(us=us, role=role)], cwd=ROOT,
                         capture_output=True, text=True, check=True).stdout.split(maxsplit=2)
    before, during, note = out[0], out[1], out[2].strip()
    if us < 0 or role not in ("sim", "vision", "team"):
        assert (during, note) == (before, "None")
    elif note == "None":
        assert int(during) <= us
    else:
        assert note.startswith("runtime.cpu_latency_us: /dev/cpu_dma_latency cannot be opened (")
