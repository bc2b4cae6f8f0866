"""`cmdragons bench grid` on a folder of Moving AI files a user brings: every row there, the search
exact against the scenarios' optima, E*'s paths within their bounds."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from cmdragons.cli import main
from cmdragons.planning.grid import octile_path


def write_map(folder: Path, name: str, free: np.ndarray, pairs: list[tuple[tuple[int, int], tuple[int, int]]]) -> None:
    h, w = free.shape
    rows = ["".join("." if f else "@" for f in row) for row in free]
    (folder / f"{name}.map").write_text(f"type octile\nheight {h}\nwidth {w}\nmap\n" + "\n".join(rows) + "\n")
    cost = np.where(free, 1.0, np.inf)
    lines = ["version 1"]
    for (sx, sy), (gx, gy) in pairs:
        best = octile_path(cost, (sy, sx), (gy, gx), astar=False).length
        lines.append(f"0\t{name}.map\t{w}\t{h}\t{sx}\t{sy}\t{gx}\t{gy}\t{best:.8f}")
    (folder / f"{name}.map.scen").write_text("\n".join(lines) + "\n")


def test_the_grid_bench_runs_on_a_users_maps(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(4)
    free = rng.random((40, 60)) > 0.15
    cells = np.argwhere(free)
    pairs = [((int(a[1]), int(a[0])), (int(b[1]), int(b[0])))
             for a, b in (cells[rng.integers(len(cells), size=2)] for _ in range(12))]
    write_map(tmp_path, "small", free, pairs)
    out = tmp_path / "rows.json"
    assert main(["bench", "grid", "--quick", "--maps", str(tmp_path), "--json", str(out)]) == 0
    import json

    rows = {r["name"]: r for r in json.loads(out.read_text())["rows"]}
    assert rows["dijkstra8/small"]["max_error"] < 1e-6 and rows["astar8/small"]["max_error"] < 1e-6
    e = rows["estar/small"]
    assert e["no_path"] == 0 and e["to_straight_line_min"] >= 1.0 - 1e-9 and e["ratio_max"] <= 1.0 + 1e-3
    assert rows["estar_repair/small"]["max_diff_to_full"] <= 1e-9
    assert {"estar8_full/small", "estar4_full/small", "nf1/small", "estar_vs_dstar/40x40"} <= set(rows)
    assert math.isfinite(rows["nf1/small"]["median_ms"])
