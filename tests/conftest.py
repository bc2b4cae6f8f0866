"""The suite's start: on a fresh clone (no numba cache) run in parallel, the play's kernels are
compiled once, before the workers start, instead of once in every worker that meets them at the same
time; and the files that hold slow tests run first, so that a parallel run ends on short tests
(every worker busy to the end) rather than on a long match that one worker plays while the other has
nothing left; unless ``--dist`` says otherwise, an idle worker steals from the busiest. ``-n auto``
starts two workers more than the machine has CPUs: about a quarter of the suite's wall time is
real-time play (served, grSim and outside matches) waiting on the clock, in which a worker uses
little CPU (on 2 CPUs, warm: 5:12 with 2 workers, 3:54 with 4). The workers already share the CPUs,
so BLAS runs one thread in each: OpenBLAS's own threads, one per CPU in every worker and in every
command a test starts, spin while they wait (tests/vision/test_field_lines.py and tests/estimation:
49-53 CPU-s with them, 30-32 without, the same wall time)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

for _threads in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_threads, "1")  # before numpy loads in the workers and the commands tests start

CONFIGS = Path(__file__).resolve().parents[1] / "configs"

# the project's own compile step (what `cmdragons play` runs on a fresh clone): four processes at once
_WARM_UP = (
    "import sys; from cmdragons.runtime.settings import load_settings; "
    "from cmdragons.runtime.warmup import cold_kernels, warm_up; "
    "cold_kernels(True) and warm_up(load_settings(sys.argv[1]), True, lambda n, name: None)"
)


@pytest.hookimpl(optionalhook=True)  # pytest -p no:xdist still runs
def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """The workers of ``-n auto``: the CPUs and two more for the tests that wait on the clock."""
    return (os.cpu_count() or 1) + 2


def pytest_configure(config: pytest.Config) -> None:
    workers = getattr(config.option, "numprocesses", None)
    if hasattr(config, "workerinput") or not isinstance(workers, int) or workers < 2:
        return  # a worker, or one process: nothing would compile twice
    if config.getoption("dist") == "load" and not any(a.startswith("--dist") for a in config.invocation_params.args):
        # unless asked otherwise, an idle worker takes half of the busiest one's queue (xdist's
        # `load` hands out the first quarter of the tests in fixed chunks, the slow files first
        # among them: on 2 CPUs one worker ended 127 s after another; 3:47 -> 3:20 with stealing)
        config.option.dist = "worksteal"
    subprocess.run([sys.executable, "-c", _WARM_UP, str(CONFIGS)], check=True)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The files with a test marked slow first, each file's tests together and in their order (a
    module's fixtures built once), the rest after them in collection order."""
    slow_files = {item.path for item in items if item.get_closest_marker("slow") is not None}
    items.sort(key=lambda item: item.path not in slow_files)  # (sorted is stable)
