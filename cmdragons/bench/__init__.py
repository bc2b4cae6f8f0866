"""Benchmark suites behind ``cmdragons bench <suite>``.

A suite is ``run(settings, quick) -> rows``; a row is ``{"name": ..., "<metric>": number, ...}``
with the unit in each metric's name. Baselines run side by side in the same process.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cmdragons.runtime.settings import Settings

__all__ = ["SUITES", "print_table", "write_json"]

Row = dict[str, Any]


def _sim(settings: Settings, quick: bool) -> list[Row]:
    from cmdragons.bench.sim import run

    return run(settings, quick)


def _planning(settings: Settings, quick: bool) -> list[Row]:
    from cmdragons.bench.planning import run

    return run(settings, quick)


def _safety(settings: Settings, quick: bool) -> list[Row]:
    from cmdragons.bench.safety import run

    return run(settings, quick)


SUITES: dict[str, Callable[[Settings, bool], list[Row]]] = {"sim": _sim, "planning": _planning, "safety": _safety}


def print_table(suite: str, rows: list[Row]) -> None:
    """One table per run of consecutive rows that share their metrics."""
    groups: list[list[Row]] = []
    for row in rows:
        if groups and set(groups[-1][0]) == set(row):
            groups[-1].append(row)
        else:
            groups.append([row])
    for group in groups:
        _print_group(suite, group)


def _print_group(suite: str, rows: list[Row]) -> None:
    from rich.console import Console
    from rich.table import Table

    metrics: list[str] = []
    for row in rows:
        metrics += [k for k in row if k != "name" and k not in metrics]
    table = Table(title=f"cmdragons bench {suite}")
    table.add_column("name")
    for m in metrics:
        table.add_column(m, justify="right")
    for row in rows:
        table.add_row(row["name"], *(_fmt(row.get(m)) for m in metrics))
    Console(width=160).print(table)


def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.3g}" if abs(v) < 1000 else f"{v:.0f}"
    return str(v)


def write_json(path: str | Path, suite: str, rows: list[Row]) -> None:
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(json.dumps({"suite": suite, "rows": rows}, indent=2) + "\n", encoding="utf-8")
