"""Moving AI grid benchmark files (Sturtevant 2012): ``.map`` grids and ``.map.scen`` scenarios.

A ``.map`` has a four-line header (``type octile``, ``height H``, ``width W``, ``map``) and H rows of
W characters: ``.`` and ``G`` passable, anything else (``@``, ``O``, ``T``, ``S``, ``W``) not. A scenario
line (after ``version 1``) holds bucket, map name, width, height, start x, start y, goal x, goal y
and the optimal 8-connected length (straight 1, diagonal sqrt 2, no cut corners).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

__all__ = ["MapError", "Scenario", "read_map", "read_scenarios"]

PASSABLE = frozenset(".G")


class MapError(ValueError):
    """A map or scenario file that cannot be read, naming the file and line."""


@dataclass(frozen=True)
class Scenario:
    bucket: int
    start: tuple[int, int]  # (x, y): column, row
    goal: tuple[int, int]
    optimal: float  # cell lengths


def read_map(path: str | Path) -> NDArray[np.bool_]:
    """The map's free cells, shape (height, width), row 0 first."""
    p = Path(path)
    try:
        lines = p.read_text(encoding="ascii").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise MapError(f"{p}: cannot read: {exc}") from None
    try:
        header = dict(line.split(maxsplit=1) for line in lines[:3])
        h, w = int(header["height"]), int(header["width"])
    except (ValueError, KeyError):
        raise MapError(f"{p}: expected the header 'type octile', 'height H', 'width W', 'map'") from None
    if len(lines) < 4 or lines[3].strip() != "map":
        raise MapError(f"{p}: line 4 must be 'map'")
    rows = lines[4 : 4 + h]
    if len(rows) != h or any(len(r) < w for r in rows):
        raise MapError(f"{p}: expected {h} rows of {w} characters")
    return np.array([[ch in PASSABLE for ch in r[:w]] for r in rows], dtype=bool)


def read_scenarios(path: str | Path) -> list[Scenario]:
    p = Path(path)
    out = []
    try:
        lines = p.read_text(encoding="ascii").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise MapError(f"{p}: cannot read: {exc}") from None
    for k, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        parts = line.split("\t") if "\t" in line else line.split()
        try:
            out.append(Scenario(int(parts[0]), (int(parts[4]), int(parts[5])), (int(parts[6]), int(parts[7])),
                                float(parts[8])))
        except (ValueError, IndexError):
            raise MapError(f"{p}:{k}: expected 9 fields: bucket map width height sx sy gx gy length") from None
    return out
