"""The progress bar the long commands show (play, sim, replay)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cmdragons.runtime.interrupt import Interrupt

__all__ = ["compile_bar", "progress_bar", "run_shown", "starting"]

EVERY_FRAMES = 15  # the bar's refresh: every half second of a 30 fps match


def progress_bar(enabled: bool, counts: bool = True):  # type: ignore[no-untyped-def]
    """A progress bar with a task's description, ``info`` field and times; ``counts``: "done/total"."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(), *([MofNCompleteColumn()] if counts else []),
        TextColumn("{task.fields[info]}"), TimeElapsedColumn(), TimeRemainingColumn(), disable=not enabled,
        transient=False,
    )


def compile_bar(enabled: bool, console: Any = None):  # type: ignore[no-untyped-def]
    """The compile step's line: its title, a short bar, parts done of all, the kernels so far and the
    time it has taken; within 80 columns. ``console``: rich's, default the terminal."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(bar_width=10), MofNCompleteColumn(),
        TextColumn("parts, {task.fields[info]}"), TimeElapsedColumn(), disable=not enabled, transient=False,
        console=console,
    )


def starting(enabled: bool, text: str) -> Any:
    """A spinner with ``text`` on stderr, shown at once while a command loads (stop() it before
    another live line; stopping twice is harmless); with ``enabled`` false, or stderr no terminal
    (a pipe, a file, a test), nothing shows."""
    import sys

    from rich.console import Console
    from rich.status import Status

    status = Status(text, console=Console(stderr=True))
    if enabled and sys.stderr.isatty():
        status.start()
    return status


def run_shown(step: Callable[[int], None], n: int, stop: Interrupt, progress: Any, task: Any,
              info: Callable[[int], str]) -> int:
    """:func:`~cmdragons.runtime.bus.run_frames` with the bar ``task`` of ``progress`` moved on
    (``info(i)``: its text after frame ``i``) every few frames and on the last, until ``stop`` is
    requested; the frames run."""
    from cmdragons.runtime.bus import run_frames

    def shown(i: int) -> None:
        if i % EVERY_FRAMES == 0 or i == n - 1:
            progress.update(task, completed=i + 1, info=info(i))

    return run_frames(step, n, lambda: stop.requested, shown)
