"""The progress bar the long commands show (play, sim, replay)."""

from __future__ import annotations

from typing import Any

__all__ = ["compile_bar", "progress_bar", "starting"]


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
    )  # fmt: skip


def compile_bar(enabled: bool, console: Any = None):  # type: ignore[no-untyped-def]
    """The compile step's line: its title, a short bar, parts done of all, the kernels so far and the
    time it has taken; within 80 columns. ``console``: rich's, default the terminal."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(bar_width=10), MofNCompleteColumn(),
        TextColumn("parts, {task.fields[info]}"), TimeElapsedColumn(), disable=not enabled, transient=False,
        console=console,
    )  # fmt: skip


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
