"""The first run's kernel compile, made visible and split over four processes.

numba compiles a kernel on its first call and caches the machine code in the package's
``__pycache__`` (``cache=True``); a fresh clone has no cache, and a match would stall on its first
frames for the better part of a minute without a word. :func:`warm_up` compiles the kernels a
``play`` calls before the match starts, in four processes at once (the compile is single-threaded;
the three children are forked from the play's process, with its modules and settings):
the planner's and the collision world's in a child that solves a few throwaway queries; motion
control's, the safety stage's and strategy's in a child that drives a throwaway crowd of robots;
the renderer's in a child that renders one throwaway frame; and vision's in this process on the
same frame drawn by the renderer's numpy reference, after which this process builds the match
(what is left compiles during the match). The parts are ordered so that the collision world, which
all of them need, compiles once: the planning child starts with it, the others reach it seconds
later and load it from the cache. :class:`CompileWatch`
counts what compiles in this process (and how long it took), so that real-time factors can leave
the one-time compile out.

Nothing here changes a match: the throwaway objects have their own random generators.
"""

from __future__ import annotations

import math
import os
import signal
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from types import TracebackType
from typing import TYPE_CHECKING, Any, TextIO

if TYPE_CHECKING:
    from cmdragons.runtime.settings import Settings

__all__ = ["CompileWatch", "cold_kernels", "settle_heap", "warm_team", "warm_up", "warm_up_parts"]

# the top-level kernels of a play, by module: if any has no cache index, the run compiles
_PLAY_KERNELS: dict[str, tuple[str, ...]] = {
    "sim._kernels": ("_render_frame_kernel", "_plan_objects_kernel"),
    "vision._kernels": ("classify", "match_patterns", "ball_centre"),
    "cmdragons.planning.collision": ("build_world", "point_free"),
    "cmdragons.planning._errt_kernels": ("errt_grow",),
    "cmdragons.control._kernels": ("motion_commands",),
    "cmdragons.safety._kernels": ("dss",),
}


def cold_kernels(images: bool) -> list[str]:
    """Names of the play's kernels with no numba cache yet (``images``: the run renders and sees
    camera images, so the renderer's and vision's kernels count too)."""
    import importlib

    cold = []
    for module, names in _PLAY_KERNELS.items():
        if not images and module in ("sim._kernels", "vision._kernels"):
            continue
        mod = importlib.import_module(module)
        for name in names:
            cache = getattr(mod, name)._cache
            if not os.path.exists(cache._cache_file._index_path):
                cold.append(f"{module}.{name}")
    return cold


class CompileWatch:
    """Counts the numba compiles of this process while active: ``count``, ``seconds`` (wall time
    spent compiling, outermost compiles only) and the name of the last kernel; ``on_compile(name)``
    is called as each one starts."""

    def __init__(self, on_compile: Callable[[str], None] | None = None) -> None:
        from numba.core import event

        self._event = event
        self.on_compile = on_compile
        self.count = 0
        self.seconds = 0.0
        self.last = ""
        self._depth = 0
        self._t0 = 0.0
        watch = self

        class _Listener(event.Listener):
            def on_start(self, ev: Any) -> None:
                if watch._depth == 0:
                    watch._t0 = time.perf_counter()
                    watch.last = _kernel_name(ev)
                    if watch.on_compile is not None:
                        watch.on_compile(watch.last)
                watch._depth += 1

            def on_end(self, ev: Any) -> None:
                watch._depth -= 1
                if watch._depth == 0:
                    watch.count += 1
                    watch.seconds += time.perf_counter() - watch._t0

        self._listener = _Listener()

    def start(self) -> None:
        self._event.register("numba:compile", self._listener)  # type: ignore[no-untyped-call]

    def stop(self) -> None:
        if self._listener in self._event._registered.get("numba:compile", ()):
            self._event.unregister("numba:compile", self._listener)  # type: ignore[no-untyped-call]

    def __enter__(self) -> CompileWatch:
        self.start()
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.stop()


def _kernel_name(ev: Any) -> str:
    fn = ev.data["dispatcher"].py_func
    return f"{fn.__module__.rsplit('.', 2)[-2]}.{fn.__name__}"


def warm_up_parts(images: bool, meanwhile: bool = True) -> int:
    """How many parts :func:`warm_up` compiles in (its total, known before it starts): the
    children, vision (``images``) and the caller's ``meanwhile``."""
    return len(_CHILD_PARTS[images]) + int(images) + int(meanwhile)


_CHILD_PARTS = {True: ("planning", "motion", "render"), False: ("planning", "motion")}


def warm_up(settings: Settings, images: bool, on_progress: Callable[[int, str], None],
            meanwhile: Callable[[], None] | None = None,
            on_part: Callable[[int], None] | None = None) -> float:
    """Compile the play's kernels now (see the module docstring); returns the wall seconds it took.
    ``on_progress(kernels compiled so far, last kernel's name)`` is called from this thread and a
    reader thread; ``on_part(parts done)`` as each part ends (of :func:`warm_up_parts`). ``meanwhile``
    runs in this thread while the children compile (the caller builds its match there, so that the
    two cores stay busy to the end). A child that fails only leaves its kernels to compile during
    the match."""
    t0 = time.perf_counter()
    done = [0, 0]  # kernels, parts
    lock = threading.Lock()

    def tick(name: str) -> None:
        with lock:
            done[0] += 1
            on_progress(done[0], name)

    def part_done() -> None:
        with lock:
            done[1] += 1
            if on_part is not None:
                on_part(done[1])

    children = [_fork(part, settings) for part in _CHILD_PARTS[images]]

    def read(child: _Child) -> None:
        with os.fdopen(child.fd, encoding="utf-8") as lines:
            for line in lines:
                tick(line.strip())
        part_done()  # the child closed its pipe: it has ended

    readers = [threading.Thread(target=read, args=(c,), daemon=True) for c in children]
    for r in readers:
        r.start()
    try:
        with CompileWatch(tick):
            if images:
                _warm_vision(settings)
                part_done()
            if meanwhile is not None:  # after vision: the children have cached the world's kernels by now
                meanwhile()
                part_done()
        for c in children:
            os.waitpid(c.pid, 0)
            c.done = True
        for r in readers:
            r.join()
    finally:
        for c in children:
            if not c.done:
                os.kill(c.pid, signal.SIGKILL)
                os.waitpid(c.pid, 0)
    return time.perf_counter() - t0


@dataclass
class _Child:
    pid: int
    fd: int  # the read end of the pipe the child names its kernels on
    done: bool = False


def _fork(part: str, settings: Settings) -> _Child:
    """A child process compiling ``part`` (see :func:`_child`). Forked, not spawned: it starts with
    every module this process has imported (a spawned one spent a second or two of a core importing
    them again), and this process opens no zenoh session and runs no other thread that a compile
    could need: numba compiles nothing here before the children are forked."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            os.close(r)
            for sig in (signal.SIGINT, signal.SIGTERM):  # the parent's handlers only set flags
                signal.signal(sig, signal.SIG_DFL)
            quiet = os.open(os.devnull, os.O_WRONLY)
            os.dup2(quiet, 1)
            os.dup2(quiet, 2)
            with os.fdopen(w, "w", encoding="utf-8") as out:
                _child(part, settings, out)
            code = 0
        finally:
            os._exit(code)  # no atexit handlers, no flushing of the parent's buffers
    os.close(w)
    return _Child(pid, r)


def _warm_vision(settings: Settings) -> None:
    """Vision on one throwaway frame of the first camera (the ball at the centre spot and robots in
    view: every kernel of the pipeline runs), drawn by the renderer's numpy reference (the compiled
    renderer is the other child's)."""
    import numpy as np

    from sim import _kernels as kern
    from sim.simulator import Simulator
    from vision.pipeline import VisionPipeline

    sim = Simulator(settings.field, settings.camera_models()[:1], settings.sim, seed=0)
    snap = sim.world.snapshot()
    robots = np.ascontiguousarray(snap.robots, dtype=np.float64).reshape(-1, 8)
    ball = np.ascontiguousarray(snap.ball, dtype=np.float64)
    for r in sim.renderers:
        p = r.params
        plan = kern.plan_objects_reference(r.model, robots, ball, r.shape, r.pink, r.palette, p.exposure_s,
                                           p.max_blur_samples, p.blur_step_px)
        image = kern.render_frame_reference(r.background, r.noise, None, r.rays, r.foot, r.gain, r.cam, r.shape,
                                            r.dots, r.palette, plan)[0]
        VisionPipeline(settings.vision, settings.field, r.model).process(image, 0, 0.0)


def _child(part: str, settings: Settings, out: TextIO) -> None:
    """A child of :func:`warm_up`: compile one part, writing each kernel's name to ``out`` as it starts."""

    def say(name: str) -> None:
        out.write(name + "\n")
        out.flush()

    with CompileWatch(say):
        if part == "render":
            from sim.simulator import Simulator

            Simulator(settings.field, settings.camera_models(), settings.sim, seed=0).capture()
        elif part == "planning":
            _warm_planner(settings)
        else:
            _warm_motion(settings)


def warm_team(settings: Settings) -> None:
    """Load into this process (compiling what has no cache) what our team's tracker and brain call
    on their first frames: for a match in real time (an outside simulator's), whose first frames
    would otherwise wait on it."""
    from cmdragons.tracking.filters import kalman

    kalman()
    _warm_planner(settings)
    _warm_motion(settings)


def _warm_motion(settings: Any) -> None:
    """The navigator and the safety stage as the brain calls them (not through the brain: its
    planners are the planning part's), on a throwaway crowd of own robots driving into each other
    and opponents, then strategy's kernels (the shot and pass evaluation; here, to even out the
    parts). Motion control first: the planning part compiles the collision world meanwhile, and this
    part then loads it from the cache."""
    import numpy as np

    from cmdragons.control.motion import motion_commands
    from cmdragons.messages import BallState, GameState, RobotCommand, RobotState, WorldState
    from cmdragons.navigation import Arrival, make_navigator
    from cmdragons.planning import deadline, field_world
    from cmdragons.safety import make_safety
    from strategy.plays import Strategy

    motion_commands(np.zeros((1, 6)), np.ones((1, 5)), settings.control)
    radius = settings.field.robot.radius_m
    geometry = settings.field_geometry()
    static = field_world(geometry, defense_areas=False)
    safety = make_safety(settings.safety, settings.control, radius, static)
    n = settings.field.dims.robots_per_team
    ours = [RobotState("blue", i, -1.0 + 0.25 * i, 0.1 * (i % 2), 0.0, 1.5 - 0.5 * i, 0.0, 0.0) for i in range(n)]
    theirs = [RobotState("yellow", i, -0.9 + 0.25 * i, 0.3, math.pi, -1.0, 0.0, 0.0) for i in range(3)]
    world = WorldState(0.0, BallState(0.0, 0.0, 0.0, 0.0), tuple(ours + theirs))
    others = field_world(geometry, np.array([[r.x, r.y] for r in theirs]), np.array([[r.vx, r.vy] for r in theirs]))
    nav = make_navigator(settings.team.navigator, settings.team.navigator_sections, settings.control, radius,
                         settings.planner.collision)
    commands = []
    for r in ours:
        nav.set_plan(np.array([(r.x, r.y), (1.0, 1.0), (2.0, 1.0)]), Arrival(0.0))
        vx, vy, omega = nav.command(r, others, deadline(0.5))
        commands.append(RobotCommand("blue", r.id, vx, vy, omega))
    safety.make_safe(commands, world)
    # strategy's kernels (the shot and pass evaluation) on a few robots round the ball
    strategy = Strategy("blue", settings.field_geometry(), settings.strategy)
    robots = tuple(RobotState(t, i, (-1.0 if t == "blue" else 1.0) * (0.5 + i), 0.3 * i, 0.0)
                   for t in ("blue", "yellow") for i in range(3))
    strategy.decide(WorldState(0.0, BallState(0.2, 0.1, 0.0, 0.0), robots), GameState(0.0))


def _warm_planner(settings: Any) -> None:
    """Hard queries for the configured planner (what a match meets only now and then): a wall of
    robots with one gap between start and goal."""
    import numpy as np

    from cmdragons.planning import PlanProblem, deadline, field_world, make_planner

    ys = [y for y in np.arange(-3.0, 3.01, 0.15) if abs(y - 1.5) > 0.3]
    world = field_world(settings.field_geometry(), np.column_stack([np.zeros(len(ys)), ys]))
    radius = settings.field.robot.radius_m
    planner = make_planner(settings.planner)
    # the way through the gap; again a step on (the last plan is checked first); from inside a robot
    for start in ((-2.0, -1.0), (-1.9, -1.0), (0.0, -0.6)):
        planner.solve(PlanProblem(start, (2.0, -1.0), radius, world), deadline(0.5))


def settle_heap() -> None:
    """Collect what start-up left behind and keep the objects alive now (settings, stages, modules,
    compiled kernels) out of later collections, just before a process starts its frames: Python's
    full collection walks every tracked object, and after start-up one held a frame up for 0.1-0.2 s
    (a distributed node) or 0.24 s (a match in an outside simulator, which then passed over 14 of the
    simulator's frames)."""
    import gc

    gc.collect()
    gc.freeze()

