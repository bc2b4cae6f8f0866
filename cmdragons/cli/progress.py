"""The progress bar the long commands show (play, sim, replay)."""

from __future__ import annotations

__all__ = ["progress_bar"]


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
