"""The compile watch sees what numba compiles; on an empty cache every kernel of a play is cold."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba

from cmdragons.runtime.warmup import CompileWatch, settle_heap


def test_compile_watch_counts_each_compile_once() -> None:
    @numba.njit
    def twice(x: float) -> float:
        return 2.0 * x

    started: list[str] = []
    with CompileWatch(started.append) as watch:
        assert twice(1.5) == 3.0
        assert twice(2.5) == 5.0  # the same signature: no second compile
    assert watch.count == 1 and watch.seconds > 0.0
    assert started == [watch.last] and watch.last.endswith(".twice")
    assert twice(1) == 2  # an int is another signature, compiled outside the watch: not counted
    assert watch.count == 1


def test_a_fresh_cache_makes_every_play_kernel_cold(tmp_path: Path) -> None:
    code = "import json; from cmdragons.runtime.warmup import cold_kernels; " \
           "print(json.dumps([cold_kernels(True), cold_kernels(False)]))"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}  # an empty cache, as on a fresh clone
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    images, brain = json.loads(out.stdout)
    assert "sim._kernels._render_frame_kernel" in images and "vision._kernels.classify" in images
    assert "cmdragons.safety._kernels.dss" in brain and "cmdragons.planning._errt_kernels.errt_grow" in brain
    assert not any(name.startswith(("sim.", "vision.")) for name in brain)
    assert set(brain) < set(images)


def test_the_compile_step_counts_its_parts_to_the_total_it_shows_from_the_start() -> None:
    from cmdragons.runtime.settings import load_settings
    from cmdragons.runtime.warmup import warm_up, warm_up_parts

    parts: list[int] = []
    ran: list[bool] = []
    warm_up(load_settings(None, []), False, lambda n, name: None, lambda: ran.append(True), parts.append)
    assert ran == [True]
    assert parts == list(range(1, warm_up_parts(False) + 1)) and warm_up_parts(False) == 3  # two children, the match
    assert warm_up_parts(True) == 5 and warm_up_parts(True, meanwhile=False) == 4


def test_the_compile_line_fits_80_columns_whole() -> None:
    import io

    from rich.console import Console

    from cmdragons.cli.progress import compile_bar

    out = io.StringIO()
    console = Console(file=out, width=80, force_terminal=True, color_system=None)
    with compile_bar(True, console) as progress:
        task = progress.add_task("compiling kernels (first run)", total=5, info="0 kernels")
        progress.update(task, completed=5, info="123 kernels, cached")
    import re

    text = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", out.getvalue())  # the terminal's control sequences
    last = [line for line in text.replace("\r", "\n").splitlines() if line.strip()][-1]
    assert "5/5 parts, 123 kernels, cached" in last and "…" not in last
    assert last.startswith("compiling kernels (first run)")


def test_settle_heap_keeps_what_lives_now_out_of_later_full_collections() -> None:
    import gc

    kept = [[i] for i in range(2000)]  # tracked containers alive at the start of the frames
    gc.unfreeze()
    try:
        settle_heap()
        assert gc.get_freeze_count() >= len(kept)
        # a full collection now walks only what came after: the kept lists are not among its objects
        assert not any(o is kept[0] for o in gc.get_objects(generation=2))
    finally:
        gc.unfreeze()
