"""Benchmark suites behind ``cmdragons bench <suite>``.

A suite is ``run(settings, quick) -> rows``; a row is ``{"name": ..., "<metric>": number, ...}``
with the unit in each metric's name. Baselines run side by side in the same process.
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cmdragons.runtime.settings import Settings

__all__ = ["ABOUT", "SUITES", "TABLE_WIDTH", "header", "print_table", "write_json"]

Row = dict[str, Any]


Suite = Callable[..., list[Row]]  # run(settings, quick, **options): options a suite takes by name (maps=...)


def _lazy(module: str) -> Suite:
    """A suite's ``run`` imported on first use (a suite may pull in heavy or optional packages)."""

    def run(settings: Settings, quick: bool, **options: Any) -> list[Row]:
        rows: list[Row] = importlib.import_module(module).run(settings, quick, **options)
        return rows

    return run


SUITES: dict[str, Suite] = {
    "sim": _lazy("cmdragons.bench.sim"),
    "planning": _lazy("cmdragons.bench.planning"),
    "safety": _lazy("cmdragons.bench.safety"),
    "tracking": _lazy("cmdragons.bench.tracking"),
    "play": _lazy("cmdragons.bench.play"),
    "vision": _lazy("cmdragons.bench.vision"),
    "grid": _lazy("cmdragons.bench.grid"),
    "robox": _lazy("cmdragons.bench.robox"),
    "navigation": _lazy("cmdragons.bench.navigation"),
    "estimation": _lazy("cmdragons.bench.estimation"),
    "goalie": _lazy("cmdragons.bench.goalie"),
    "runtime": _lazy("cmdragons.bench.runtime"),
    "protocols": _lazy("cmdragons.bench.protocols"),
    "autoref": _lazy("cmdragons.bench.autoref"),
    "league": _lazy("cmdragons.bench.league"),
}
# what each suite measures, one line each (``cmdragons bench -h``)
ABOUT: dict[str, str] = {
    "sim": "physics per frame, rendering per camera frame beside OpenCV, the simulator against real time",
    "planning": "the planners and collision queries on seeded small-size scenes",
    "safety": "the dynamics safety search in the simulator (Bruce 2006 5.6.1): collisions with and without",
    "tracking": "the tracker on the rendered cameras through vision, against the truth",
    "play": "seeded full-rules matches against the simple, the defending and our own team, and the brain's cycle",
    "vision": "detection quality against truth (noise, light, video, 1920x1200) and time beside OpenCV",
    "grid": "the grid planners on Moving AI maps beside their peers (--maps DIR)",
    "robox": "Philippsen's Robox stack (E*, elastic band, dynamic window) beside ERRT and DSS",
    "navigation": "every planner and navigator on one seeded scene suite beside known implementations (--figures)",
    "estimation": "EKF localisation, EKF-SLAM and the particle filter beside the Robotics Toolbox's",
    "goalie": "what the goalie's escape/evade reflex is worth on seeded shots",
    "runtime": "the distributed runtime on zenoh against the embedded one",
    "protocols": "the league's packets through loopback: size, encode and decode time, none lost",
    "autoref": "the auto-referee on vision against the referee on the truth: calls both made, calls of its own",
    "league": "our team in sim --serve, grSim and the ER-Force simulator (their scripts), refereed by our autoref",
}
# the options each suite takes
OPTIONS: dict[str, tuple[str, ...]] = {"grid": ("maps",), "navigation": ("figures",),
                                       "play": ("opponent", "matches", "half", "shootout"), "league": ("half",)}
# the suites that run the command's own processes: they take the bench's --config and --set to hand on
# (as ``config`` and ``overrides``)
HANDS_ON: tuple[str, ...] = ("league",)


TABLE_WIDTH = 100  # columns: a bench table fits a standard terminal
_NAME_WIDTH = 26  # the row name column; longer names wrap onto a second line (the JSON keeps them whole)
_CELL_WIDTH = 9  # a number column, borders included
# metric name endings that are units, shown under the metric's name in the header
_UNITS = {"_mm_s": "mm·s", "_m_s2": "m/s²", "_m_s": "m/s", "_ms": "ms", "_us": "µs", "_ns": "ns", "_mm": "mm",
          "_m": "m", "_s": "s", "_rad": "rad", "_deg": "deg", "_px": "px", "_hz": "Hz"}


def print_table(suite: str, rows: list[Row], width: int = TABLE_WIDTH) -> None:
    """One table per run of consecutive rows that share their metrics, each at most ``width``
    columns wide: metric columns beyond that go to a further table with the same row names; text
    fields (notes) are printed under the table, one line per row."""
    groups: list[list[Row]] = []
    for row in rows:
        if groups and set(groups[-1][0]) == set(row):
            groups[-1].append(row)
        else:
            groups.append([row])
    for group in groups:
        _print_group(suite, group, width)


def header(metric: str) -> str:
    """A metric's column header: its words, the unit on a line of its own (``median_ms`` ->
    "median\\nms", ``max_speed_m_s`` -> "max speed\\nm/s"); other names as words."""
    for unit, shown in _UNITS.items():
        if metric.endswith(unit) and len(metric) > len(unit):
            return f"{metric[: -len(unit)].replace('_', ' ')}\n{shown}"
    return metric.replace("_", " ")


def _print_group(suite: str, rows: list[Row], width: int) -> None:
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    metrics: list[str] = []
    for row in rows:
        metrics += [k for k in row if k != "name" and k not in metrics]
    texts = [m for m in metrics if any(isinstance(r.get(m), str) for r in rows)]
    numbers = [m for m in metrics if m not in texts]
    per_table = max(1, (width - _NAME_WIDTH - 4) // _CELL_WIDTH)
    console = Console(width=width, highlight=False)
    chunks = [numbers[i : i + per_table] for i in range(0, len(numbers), per_table)]
    for k, chunk in enumerate(chunks):
        part = f" ({k + 1}/{len(chunks)})" if len(chunks) > 1 else ""
        table = Table(title=Text(f"cmdragons bench {suite}{part}"), title_justify="left")
        table.add_column("name", max_width=_NAME_WIDTH, overflow="fold")
        for m in chunk:
            table.add_column(Text(header(m)), justify="right", overflow="fold")
        for row in rows:
            table.add_row(Text(row["name"].replace("_", " ")), *(Text(_fmt(row.get(m))) for m in chunk))
        console.print(table)
    for row in rows:
        for m in texts:
            if row.get(m):
                console.print(Text(f"{row['name']}: {m}: {row[m]}"), soft_wrap=False)


def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.3g}" if abs(v) < 1000 else f"{v:.0f}"
    return str(v)


def write_json(path: str | Path, suite: str, rows: list[Row]) -> None:
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(json.dumps({"suite": suite, "rows": rows}, indent=2) + "\n", encoding="utf-8")
