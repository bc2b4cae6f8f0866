"""The compile watch sees what numba compiles; on an empty cache every kernel of a play is cold."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba

from cmdragons.runtime.warmup import CompileWatch


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
           "print(json.dumps([cold_kernels(True), cold_kernels(False)]))"  # fmt: skip
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}  # an empty cache, as on a fresh clone
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    images, brain = json.loads(out.stdout)
    assert "sim._kernels._render_frame_kernel" in images and "vision._kernels.classify" in images
    assert "cmdragons.safety._kernels.dss" in brain and "cmdragons.planning._errt_kernels.errt_grow" in brain
    assert not any(name.startswith(("sim.", "vision.")) for name in brain)
    assert set(brain) < set(images)
